// Conversion throughput: from a tracked surface graph to the indexed triangle list
// (extractLoops, paper §5.2) — from the image bricks the graph keeps, and for comparison from
// the image itself, which binarises it again — then, separately, the iso-value mapping of the vertices and the
// construction of the OpenMesh half-edge mesh, on the noisy spheres of the Figure 9 protocol
// (docs/figure9.md, 'Protocol').
// Medians of several runs, one thread.
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

int main(int argc, char** argv) {
  try {
    std::vector<int> sizes{128, 256, 512};
    int reps = 5;
    AdjacencyPair pair = AdjacencyPair::k26_6;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++i];
      };
      if (a == "--sizes") {
        sizes = bench::parseList<int>(value(), "size");
      } else if (a == "--reps") {
        reps = std::stoi(value());
      } else if (a == "--pair") {
        pair = parseAdjacencyPair(value());
      } else {
        throw std::invalid_argument("unknown option " + a);
      }
    }
    std::printf("conversion, pair %s, median of %d runs, one thread (ms; M triangles/s)\n",
                toString(pair).c_str(), reps);
    std::printf("%-18s %10s %10s %10s %8s %12s %8s %10s %10s %8s\n", "case", "triangles", "track",
                "loops", "M tri/s", "loops(image)", "M tri/s", "mapping", "openmesh", "M tri/s");
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
        const double build = bench::medianSeconds(reps, [&] { toSurfaceMesh(mesh, points); });
        const double tri = double(mesh.triangles.size());
        std::printf("q=%-4d p=%-2d%%       %10zu %10.1f %10.1f %8.2f %12.1f %8.2f %10.1f %10.1f %8.2f\n",
                    q, int(noise * 100), mesh.triangles.size(), 1e3 * track, 1e3 * loops,
                    tri / loops / 1e6, 1e3 * checked, tri / checked / 1e6, 1e3 * map, 1e3 * build,
                    tri / build / 1e6);
        std::fflush(stdout);
      }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_conversion: error: " << e.what() << "\n";
    return 1;
  }
}
