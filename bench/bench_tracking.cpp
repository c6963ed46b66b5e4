// Tracking throughput: surfels per second of trackComponent, single thread, on the noisy
// spheres of the Figure 9 protocol (docs/figure9.md, 'Protocol'), and on an implicit ball of
// radius 900 in a 4096^3 domain that can be neither stored nor scanned. Memory is the tracker's
// own peak: each case runs in a child process that reports its peak resident size minus its size
// just before tracking (so the stored image does not count). Each case also times, in the same
// run, the baseline, a hash-set depth-first traversal (HashSetTraversal.h), and prints the
// speed ratio: absolute speeds drift between runs on a VM, the ratio much less.
//
// With --breakdown, two parts of the tracker's work are also timed on their own, each in the
// same kind of child process: binarising the bricks the surface passes through (the tracker's
// BinaryBrickCache, in the order it created them), and writing fresh output arrays of the graph's
// size (surfels, row starts, arcs: the floor any tracker writing this graph pays).
//
//   bench_tracking [--sizes 64,128,...] [--quick] [--reps N] [--pair 26-6] [--no-baseline]
//                  [--breakdown]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "BenchSupport.h"
#include "FindSeed.h"
#include "HashSetTraversal.h"
#include "Phantoms.h"
#include "TrackComponent.h"

using namespace surftrack;

namespace {

long residentKiB() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

struct Measurement {
  std::size_t surfels = 0;
  double wallSeconds = 0, cpuSeconds = 0;  // medians
  long peakKiB = 0;                        // tracker's peak memory
};

// Runs `track` `reps` times in a child process; the child sends back its figures on a pipe.
template <class Track>
Measurement measure(int reps, const Track& track) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const long before = residentKiB();
    std::vector<double> wall, cpu;
    std::size_t surfels = 0;
    for (int r = 0; r < reps; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = bench::threadCpuSeconds();
      surfels = track();
      cpu.push_back(bench::threadCpuSeconds() - c0);
      wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    Measurement m{surfels, bench::median(wall), bench::median(cpu), usage.ru_maxrss - before};
    if (write(fds[1], &m, sizeof m) != sizeof m) _exit(1);
    _exit(0);
  }
  close(fds[1]);
  Measurement m{};
  const bool ok = read(fds[0], &m, sizeof m) == sizeof m;
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!ok || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("measurement child failed");
  return m;
}

// One table row; `baseline` (a measurement of hashSetTraversal) is left out when it has no time.
void printRow(const std::string& name, const Measurement& m, const Measurement& baseline) {
  std::printf("%-28s %12zu %10.1f %10.1f %9.2f %9.2f %10.1f %8.0f", name.c_str(), m.surfels,
              1e3 * m.wallSeconds, 1e3 * m.cpuSeconds, m.surfels / m.wallSeconds / 1e6,
              m.surfels / m.cpuSeconds / 1e6, m.peakKiB / 1024.0,
              m.surfels ? 1024.0 * m.peakKiB / double(m.surfels) : 0.0);
  if (baseline.cpuSeconds > 0) {
    if (baseline.surfels != m.surfels) throw std::runtime_error(name + ": the baseline found another surface");
    std::printf(" %9.2f %6.1fx", baseline.surfels / baseline.cpuSeconds / 1e6, baseline.cpuSeconds / m.cpuSeconds);
  }
  std::printf("\n");
  std::fflush(stdout);
}

// The --breakdown parts for the graph `g` tracked in `image`: binarising its bricks, and
// writing output arrays of its size. Printed on one line below the case's row.
template <class BinaryImage>
void printBreakdown(int runs, const BinaryImage& image, const SurfaceGraph& g, const Measurement& whole) {
  const Measurement bricks = measure(runs, [&] {
    BinaryBrickCache<BinaryImage> cache(image);
    for (std::uint32_t b = 0; b < g.bricks.size(); ++b) {
      const Voxel o = g.bricks.brickOrigin(b);
      cache.brickIndex(o.x >> 3, o.y >> 3, o.z >> 3);
    }
    return g.surfelCount();
  });
  const Measurement output = measure(runs, [&] {
    const std::size_t n = g.surfelCount(), arcs = boost::num_edges(g.graph);
    std::vector<Surfel> surfels;
    std::vector<std::uint32_t> rowStart, targets;
    resizeHugePages(surfels, n);
    resizeHugePages(rowStart, n + 1);
    resizeHugePages(targets, arcs);
    for (std::size_t v = 0; v < n; ++v) surfels[v] = Surfel{Voxel{int(v), 0, 0}, 0}, rowStart[v] = std::uint32_t(v);
    for (std::size_t a = 0; a < arcs; ++a) targets[a] = std::uint32_t(a);
    return n;
  });
  const double rest = whole.cpuSeconds - bricks.cpuSeconds - output.cpuSeconds;
  std::printf("    breakdown (cpu ms): binarise %zu bricks %.1f, write output %.1f, the rest %.1f "
              "(%.0f ns/surfel)\n",
              g.bricks.size(), 1e3 * bricks.cpuSeconds, 1e3 * output.cpuSeconds, 1e3 * rest,
              1e9 * rest / double(g.surfelCount()));
  std::fflush(stdout);
}

const char* const kUsage =
    "usage: bench_tracking [--sizes 64,128,...] [--quick] [--reps N] [--pair 26-6] [--no-baseline]\n"
    "                      [--breakdown]\n"
    "\n"
    "trackComponent throughput, one thread, on the noisy spheres of the Figure 9 protocol\n"
    "(noise 0, 1, 5 %) and on an implicit ball of radius 900 in a 4096^3 domain; each case in\n"
    "a child process that reports the tracker's own peak memory.\n"
    "\n"
    "  --sizes LIST   sphere image sides (default 64,128,256,512,1024)\n"
    "  --quick        sides 64,128,256, 3 runs, no implicit ball\n"
    "  --reps N       runs per measurement (default 5; at most 3 from side 512 on)\n"
    "  --pair P       adjacency pair: 26-6, 18-6, 6-18 or 6-26 (default 26-6)\n"
    "  --no-baseline  skip the hash-set traversal baseline and the speed ratio\n"
    "  --breakdown    also time brick binarisation and writing the output arrays\n"
    "  --help         this text\n";

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<int> sizes{64, 128, 256, 512, 1024};
    int reps = 5;
    AdjacencyPair pair = AdjacencyPair::k26_6;
    bool implicitBall = true, baseline = true, breakdown = false;
    for (bench::Arguments args(argc, argv); args.next();) {
      if (args.isHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (args.is("--sizes")) sizes = bench::parseList<int>(args.value(), "size");
      else if (args.is("--quick")) sizes = {64, 128, 256}, reps = 3, implicitBall = false;
      else if (args.is("--reps")) reps = std::stoi(args.value());
      else if (args.is("--pair")) pair = parseAdjacencyPair(args.value());
      else if (args.is("--no-baseline")) baseline = false;
      else if (args.is("--breakdown")) breakdown = true;
      else args.unknown();
    }
    std::printf("trackComponent throughput, pair %s, median of %d runs, one thread\n",
                toString(pair).c_str(), reps);
    std::printf("%-28s %12s %10s %10s %9s %9s %10s %8s%s\n", "case", "surfels", "wall ms",
                "cpu ms", "M/s wall", "M/s cpu", "peak MiB", "B/surfel",
                baseline ? "  hash-set M/s cpu  ratio" : "");
    for (int q : sizes)
      for (double noise : {0.0, 0.01, 0.05}) {
        const NoisyPhantom sphere = makeNoisySphere(q, noise);
        const auto image = sphere.binary();
        const Surfel seed = protocolSeed(sphere);
        const int runs = q >= 512 ? std::min(reps, 3) : reps;
        const Measurement m = measure(runs, [&] { return trackComponent(image, seed, pair).surfelCount(); });
        const Measurement b = baseline ? measure(runs, [&] { return bench::hashSetTraversal(image, seed, pair); })
                                       : Measurement{};
        printRow("sphere q=" + std::to_string(q) + " p=" + std::to_string(int(noise * 100)) + "%", m, b);
        if (breakdown) printBreakdown(runs, image, trackComponent(image, seed, pair), m);
      }
    if (implicitBall) {
      const int c = 2048;
      const ImplicitImage ball({4096, 4096, 4096}, Ball::ofRadius({c, c, c}, 900));
      const Surfel seed = *seedAlongRay(ball, Voxel{c, c, c}, 0);
      const int runs = std::min(reps, 3);
      const Measurement m = measure(runs, [&] { return trackComponent(ball, seed, pair).surfelCount(); });
      const Measurement b = baseline ? measure(runs, [&] { return bench::hashSetTraversal(ball, seed, pair); })
                                     : Measurement{};
      printRow("implicit ball R=900 in 4096^3", m, b);
      if (breakdown) printBreakdown(runs, ball, trackComponent(ball, seed, pair), m);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_tracking: error: " << e.what() << "\n";
    return 1;
  }
}
