// What decimate() costs against what OpenMesh's Decimater costs without its guards (docs/
// performance.md, "Smoothing and decimation"): the same closed mesh (a PLY file, e.g. the
// smoothed sphere bench_refine writes) reduced to the same triangle count by
//  - "openmesh": OpenMesh's DecimaterT with the quadric module alone (OpenMesh's own collapse
//    legality, is_collapse_ok, and no guard of this project's);
//  - "link": this project's CheckedDecimaterT (refine/CheckedDecimater.h) with the quadric, the
//    normal-flip module and the link condition (refine/TopologyGuard.h), no embedding guard and
//    no distance bound: what keeping the topology alone costs;
//  - "safe": refine::decimateSafely, every guard of docs/theory.md section 10, as decimate()
//    runs it (without the front door's copies).
// Each is run --reps times on a fresh copy of the mesh; prints one JSON object with the median
// CPU seconds of this thread and the triangles left.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include "BenchSupport.h"
#include "CheckedDecimater.h"
#include "SurfaceMesh.h"
#include "TopologyGuard.h"
#include "TopologySafeDecimation.h"

using namespace surftrack;

namespace {

const char* kUsage =
    "usage: bench_decimation_floor --input MESH.ply [--reduce F] [--max-error E] [--reps N]\n"
    "                              [--only openmesh|link|safe]\n"
    "  Decimates the closed mesh MESH to (1 - F) of its triangles (default F 0.9) three ways:\n"
    "  OpenMesh's DecimaterT with the quadric module alone, the checked decimater with the\n"
    "  quadric, normal-flip and link-condition modules, and decimateSafely within E (default\n"
    "  0.5, the mesh's units), which adds the embedding and distance guards; median CPU\n"
    "  seconds of N runs (default 3) each, as one JSON object; --only runs one of them (profiling).\n";

void prepare(SurfaceMesh& m) {
  m.request_vertex_status();
  m.request_edge_status();
  m.request_halfedge_status();
  m.request_face_status();
  m.request_face_normals();
  m.update_face_normals();
}

std::size_t openMeshQuadric(SurfaceMesh& m, std::size_t target) {
  prepare(m);
  OpenMesh::Decimater::DecimaterT<SurfaceMesh> d(m);
  OpenMesh::Decimater::ModQuadricT<SurfaceMesh>::Handle quadric;
  d.add(quadric);
  d.module(quadric).unset_max_err();
  d.initialize();
  d.decimate_to_faces(0, target);
  m.garbage_collection();
  return m.n_faces();
}

std::size_t linkOnly(SurfaceMesh& m, std::size_t target) {
  prepare(m);
  refine::CheckedDecimaterT<SurfaceMesh> d(m);
  OpenMesh::Decimater::ModQuadricT<SurfaceMesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<SurfaceMesh>::Handle flipping;
  refine::ModTopologyGuardT<SurfaceMesh>::Handle guard;
  d.add(quadric);
  d.add(flipping);
  d.add(guard);
  d.module(quadric).unset_max_err();
  d.module(flipping).set_max_normal_deviation(refine::DecimationParameters{}.maxNormalDeviation);
  d.initialize();
  auto& q = d.module(quadric);
  d.decimateToFaces(target, [&](const auto& ci) { return q.collapse_priority(ci); });
  m.garbage_collection();
  return m.n_faces();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string input, only;
    double reduce = 0.9, maxError = 0.5;
    int reps = 3;
    for (bench::Arguments args(argc, argv); args.next();) {
      if (args.isHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (args.is("--input")) {
        input = args.value();
      } else if (args.is("--reduce")) {
        reduce = std::stod(args.value());
      } else if (args.is("--max-error")) {
        maxError = std::stod(args.value());
      } else if (args.is("--only")) {
        only = args.value();
        if (only != "openmesh" && only != "link" && only != "safe")
          throw std::invalid_argument("--only takes openmesh, link or safe");
      } else if (args.is("--reps")) {
        reps = std::stoi(args.value());
      } else {
        args.unknown();
      }
    }
    if (input.empty()) throw std::invalid_argument("--input MESH.ply is required (see --help)");
    if (reps < 1) throw std::invalid_argument("--reps must be at least 1");
    SurfaceMesh original;
    if (!OpenMesh::IO::read_mesh(original, input)) throw std::runtime_error("cannot read " + input);
    const std::size_t target = std::size_t(std::llround((1 - reduce) * double(original.n_faces())));
    refine::DecimationParameters p;
    p.maxError = maxError;
    p.targetReduction = reduce;
    std::string out = "{\"triangles\": " + std::to_string(original.n_faces()) +
                      ", \"target\": " + std::to_string(target);
    auto run = [&](const std::string& name, auto&& decimate) {
      if (!only.empty() && name != only) return;
      std::vector<double> cpu;
      std::size_t left = 0;
      for (int r = 0; r < reps; ++r) {
        SurfaceMesh m = original;
        const double c0 = bench::threadCpuSeconds();
        left = decimate(m);
        cpu.push_back(bench::threadCpuSeconds() - c0);
      }
      char buf[160];
      std::snprintf(buf, sizeof buf, ",\n \"%s\": {\"cpu\": %.4f, \"triangles\": %zu}", name.c_str(), bench::median(cpu), left);
      out += buf;
    };
    run("openmesh", [&](SurfaceMesh& m) { return openMeshQuadric(m, target); });
    run("link", [&](SurfaceMesh& m) { return linkOnly(m, target); });
    run("safe", [&](SurfaceMesh& m) { return refine::decimateSafely(m, p).trianglesAfter; });
    std::cout << out << "}\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_decimation_floor: " << e.what() << "\n";
    return 1;
  }
}
