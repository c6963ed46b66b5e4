// Throughput of the scanning method (method 1 of Figure 9): scanIsoSurface on the sphere of the
// Figure 9 protocol (docs/figure9.md, 'Protocol'), single thread, median of several runs, for
// each side q and noise level.
//
//   bench_scanning [--runs N] [--q 128,256,512] [--noise 0,0.01,0.05] [--pair 26-6] [--no-generic]
//                  [--cpu-time]
//
// Times are wall-clock times, or with --cpu-time the CPU time of the thread (user + system),
// which is steadier on a machine shared with other jobs.
//
// Columns: surfels and triangles of the whole iso-surface, its number of components (the
// kappa-lambda-boundaries), the median time of the fast (dense threshold) path and its
// throughput in voxels/s (q^3 / time), the same for the generic operator() path and for a classic
// table-driven marching cubes (one cube at a time, 8 gray reads, on a pre-padded copy; same
// table, same mesh), and method 1b: the scan plus the extraction of the protocol seed's component.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <ctime>
#include <string>
#include <vector>

#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "ScanIsoSurface.h"
#include "BenchSupport.h"
#include "Phantoms.h"

using namespace surftrack;

namespace {

struct Options {
  int runs = 5;
  std::vector<int> sides{128, 256, 512};
  std::vector<double> noises{0.0, 0.01, 0.05};
  AdjacencyPair pair = AdjacencyPair::k26_6;
  bool generic = true;
  bool cpuTime = false;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "missing value after %s\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--runs") o.runs = std::max(1, std::atoi(value().c_str()));
    else if (a == "--q") o.sides = bench::parseList<int>(value(), "size");
    else if (a == "--noise") o.noises = bench::parseList<double>(value(), "noise level");
    else if (a == "--pair") o.pair = parseAdjacencyPair(value());
    else if (a == "--no-generic") o.generic = false;
    else if (a == "--cpu-time") o.cpuTime = true;
    else {
      std::fprintf(stderr,
                   "usage: bench_scanning [--runs N] [--q 128,256,512] [--noise 0,0.01,0.05] "
                   "[--pair 26-6] [--no-generic] [--cpu-time]\n");
      std::exit(2);
    }
  }
  return o;
}

/// Classic table-driven marching cubes, for comparison: reads the 8 gray values of every cube of
/// a zero-padded copy of the image (made untimed; 4 new reads per cube, the other 4 are those of
/// the previous cube), skips the 0x00 / 0xFF cubes, and shares vertices through per-slab edge
/// arrays filled on first use. Same mesh as scanIsoSurface up to the vertex numbering.
class ClassicMarchingCubes {
 public:
  ClassicMarchingCubes(const DenseImage<std::uint8_t>& gray, std::uint8_t threshold)
      : d_(gray.dims()), px_(d_.nx + 2), py_(d_.ny + 2), pz_(d_.nz + 2), t_(threshold),
        padded_(std::size_t(px_) * py_ * pz_, 0) {
    for (int z = 0; z < d_.nz; ++z)
      for (int y = 0; y < d_.ny; ++y)
        std::copy_n(&gray.at(0, y, z), d_.nx, &padded_[index(1, y + 1, z + 1)]);
  }

  TriangleMesh run(AdjacencyPair pair) const {
    TriangleMesh mesh;
    const std::size_t plane = std::size_t(px_) * py_;
    // Vertex ids of the edges of one slab: x- and y-edges of its two planes, z-edges between.
    std::vector<std::uint32_t> xLo(plane, ~0u), xHi(plane, ~0u), yLo(plane, ~0u), yHi(plane, ~0u), zs(plane);
    const std::size_t dy = px_, dz = plane;
    for (int z = 0; z + 1 < pz_; ++z) {
      std::fill(xHi.begin(), xHi.end(), ~0u);
      std::fill(yHi.begin(), yHi.end(), ~0u);
      std::fill(zs.begin(), zs.end(), ~0u);
      for (int y = 0; y + 1 < py_; ++y) {
        // The 4 corners of column x (bits 0, 2, 4, 6 of a configuration), reused by cube x - 1.
        const std::uint8_t* row = &padded_[index(0, y, z)];
        const std::uint8_t t = t_;
        auto column = [&](int x) {
          const std::uint8_t* c = row + x;
          return unsigned(c[0] > t) | unsigned(c[dy] > t) << 2 | unsigned(c[dz] > t) << 4 |
                 unsigned(c[dz + dy] > t) << 6;
        };
        unsigned next = column(0);
        for (int x = 0; x + 1 < px_; ++x) {
          const unsigned low = next;
          next = column(x + 1);
          const unsigned config = low | next << 1;
          if (config == 0 || config == 255) continue;
          const std::size_t at = std::size_t(y) * px_ + x;
          std::uint32_t* slot[12] = {&xLo[at], &xLo[at + px_], &xHi[at], &xHi[at + px_],
                                     &yLo[at], &yLo[at + 1],   &yHi[at], &yHi[at + 1],
                                     &zs[at],  &zs[at + 1],    &zs[at + px_], &zs[at + px_ + 1]};
          const Voxel m{x - 1, y - 1, z - 1};
          for (const auto& tri : configurationTable(pair, std::uint8_t(config)).allTriangles()) {
            std::array<std::uint32_t, 3> out;
            for (int k = 0; k < 3; ++k) {
              std::uint32_t& id = *slot[tri[k]];
              if (id == ~0u) {
                id = std::uint32_t(mesh.surfels.size());
                mesh.surfels.push_back(cube::surfelOnEdge(m, tri[k], std::uint8_t(config)));
              }
              out[k] = id;
            }
            mesh.triangles.push_back(out);
          }
        }
      }
      std::swap(xLo, xHi);
      std::swap(yLo, yHi);
    }
    return mesh;
  }

 private:
  std::size_t index(int x, int y, int z) const { return (std::size_t(z) * py_ + y) * px_ + x; }
  Dims d_;
  int px_, py_, pz_;
  std::uint8_t t_;
  std::vector<std::uint8_t> padded_;
};

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  const auto clock = o.cpuTime ? bench::threadCpuSeconds : bench::wallSeconds;
  std::printf("scanning method (method 1), pair %s, median %s of %d runs, one thread\n",
              toString(o.pair).c_str(), o.cpuTime ? "thread CPU time" : "wall time", o.runs);
  std::printf("%5s %6s %10s %10s %7s | %9s %12s | %9s %12s | %9s %12s | %9s\n", "q", "noise",
              "surfels", "triangles", "comps", "scan ms", "voxels/s", "gen. ms", "gen. vox/s",
              "MC ms", "MC vox/s", "1b ms");
  for (int q : o.sides)
    for (double noise : o.noises) {
      const NoisyPhantom sphere = makeNoisySphere(q, noise);
      const auto image = sphere.binary();
      const Surfel seed = protocolSeed(sphere);
      const double voxels = double(q) * q * q;

      std::size_t surfels = 0, triangles = 0, components = 0;
      {
        const TriangleMesh mesh = scanIsoSurface(image, o.pair, 1);
        surfels = mesh.surfels.size();
        triangles = mesh.triangles.size();
        meshComponents(mesh, components);
      }
      const double scan = bench::medianSeconds(o.runs, [&] { return scanIsoSurface(image, o.pair, 1); }, clock);
      const double generic = o.generic ? bench::medianSeconds(o.runs, [&] {
        return scanIsoSurfaceGeneric(image, o.pair, 1);
      }, clock) : 0.0;
      const ClassicMarchingCubes classic(sphere.image, std::uint8_t(kPhantomIsoValue));
      {
        const TriangleMesh check = classic.run(o.pair);
        if (check.triangles.size() != triangles || check.surfels.size() != surfels)
          std::fprintf(stderr, "classic marching cubes gives another mesh!\n");
      }
      const double mc = bench::medianSeconds(o.runs, [&] { return classic.run(o.pair); }, clock);
      const double oneB = bench::medianSeconds(o.runs, [&] {
        return extractComponent(scanIsoSurface(image, o.pair, 1), seed);
      }, clock);
      std::printf("%5d %5.0f%% %10zu %10zu %7zu | %9.2f %12.4g | %9.2f %12.4g | %9.2f %12.4g | %9.2f\n",
                  q, 100 * noise, surfels, triangles, components, 1e3 * scan, voxels / scan,
                  1e3 * generic, o.generic ? voxels / generic : 0.0, 1e3 * mc, voxels / mc, 1e3 * oneB);
      std::fflush(stdout);
    }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_scanning: error: %s\n", e.what());
  return 2;
}
