// Conversion throughput: from a tracked surface graph to the indexed triangle list
// (extractLoops, paper §5.2) — from the image bricks the graph keeps, and for comparison from
// the image itself, which binarises it again — then, separately, the iso-value mapping of the
// vertices and the construction of the OpenMesh half-edge mesh, both ways: toSurfaceMesh (built
// directly from the oriented triangles) and toSurfaceMeshByAddFace (the add_face reference), on
// the noisy spheres of the Figure 9 protocol (docs/figure9.md, 'Protocol').
// Medians of several runs, one thread; each result is destroyed outside the timing.
//
//   bench_conversion [--sizes 64,128,...] [--reps N] [--pair 26-6]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "BenchSupport.h"
#include "BoundaryMapping.h"
#include "LoopExtraction.h"
#include "Phantoms.h"
#include "SurfaceMesh.h"
#include "TrackComponent.h"

using namespace surftrack;

namespace {

const char* const kUsage =
    "usage: bench_conversion [--sizes 64,128,...] [--reps N] [--pair 26-6]\n"
    "\n"
    "Conversion throughput on the noisy spheres of the Figure 9 protocol (noise 0, 1, 5 %),\n"
    "one thread, median of N runs: tracking, extractLoops from the graph's bricks and from\n"
    "the image, the iso-value mapping of the vertices, and the OpenMesh half-edge mesh built\n"
    "with add_face (toSurfaceMeshByAddFace) and directly (toSurfaceMesh; also on the thread's\n"
    "CPU clock). Results are destroyed outside the timing.\n"
    "\n"
    "  --sizes LIST  sphere image sides (default 128,256,512)\n"
    "  --reps N      runs per measurement (default 5)\n"
    "  --pair P      adjacency pair: 26-6, 18-6, 6-18 or 6-26 (default 26-6)\n"
    "  --help        this text\n";

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<int> sizes{128, 256, 512};
    int reps = 5;
    AdjacencyPair pair = AdjacencyPair::k26_6;
    for (bench::Arguments args(argc, argv); args.next();) {
      if (args.isHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (args.is("--sizes")) {
        sizes = bench::parseList<int>(args.value(), "size");
      } else if (args.is("--reps")) {
        reps = std::stoi(args.value());
      } else if (args.is("--pair")) {
        pair = parseAdjacencyPair(args.value());
      } else {
        args.unknown();
      }
    }
    std::printf("conversion, pair %s, median of %d runs, one thread (ms; M triangles/s)\n",
                toString(pair).c_str(), reps);
    std::printf("%-18s %10s %10s %10s %8s %12s %8s %10s %10s %8s %10s %8s %10s %8s %7s\n", "case",
                "triangles", "track", "loops", "M tri/s", "loops(image)", "M tri/s", "mapping",
                "add_face", "M tri/s", "direct", "M tri/s", "direct cpu", "M tri/s", "speedup");
    for (int q : sizes)
      for (double noise : {0.0, 0.01, 0.05}) {
        const NoisyPhantom sphere = makeNoisySphere(q, noise);
        const auto image = sphere.binary();
        const Surfel seed = protocolSeed(sphere);
        SurfaceGraph graph;
        const double track = bench::medianSeconds(reps, [&] { graph = trackComponent(image, seed, pair); });
        TriangleMesh mesh;
        // From the bricks the graph keeps (what the CLI and Figure 9 use), then from the image.
        const double loops = bench::medianSeconds(reps, [&] { return extractLoops(graph); });
        const double checked = bench::medianSeconds(reps, [&] { return extractLoops(image, graph); });
        mesh = extractLoops(graph);
        if (extractLoops(image, graph).triangles != mesh.triangles)
          throw std::logic_error("the two extractLoops overloads disagree");
        const IsoValueMapping<std::uint8_t> mapping(sphere.image, kPhantomIsoValue);
        std::vector<std::array<double, 3>> points;
        const double map = bench::medianSeconds(reps, [&] { points = mapVertices(mesh, mapping, {}); });
        // The OpenMesh half-edge mesh, by add_face (the reference) and built directly.
        const double byAddFace =
            bench::medianSeconds(reps, [&] { return toSurfaceMeshByAddFace(mesh, points); });
        const double direct = bench::medianSeconds(reps, [&] { return toSurfaceMesh(mesh, points); });
        // The same on this thread's CPU clock, which a loaded machine inflates less.
        const double directCpu = bench::medianSeconds(
            reps, [&] { return toSurfaceMesh(mesh, points); }, bench::threadCpuSeconds);
        {
          const SurfaceMesh a = toSurfaceMesh(mesh, points), b = toSurfaceMeshByAddFace(mesh, points);
          if (a.n_vertices() != b.n_vertices() || a.n_edges() != b.n_edges() || a.n_faces() != b.n_faces())
            throw std::logic_error("the two OpenMesh constructions disagree");
        }
        const double tri = double(mesh.triangles.size());
        std::printf("q=%-4d p=%-2d%%       %10zu %10.1f %10.1f %8.2f %12.1f %8.2f %10.1f %10.1f %8.2f "
                    "%10.1f %8.2f %10.1f %8.2f %6.1fx\n",
                    q, int(noise * 100), mesh.triangles.size(), 1e3 * track, 1e3 * loops,
                    tri / loops / 1e6, 1e3 * checked, tri / checked / 1e6, 1e3 * map, 1e3 * byAddFace,
                    tri / byAddFace / 1e6, 1e3 * direct, tri / direct / 1e6, 1e3 * directCpu,
                    tri / directCpu / 1e6, byAddFace / direct);
        std::fflush(stdout);
      }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_conversion: error: " << e.what() << "\n";
    return 1;
  }
}
