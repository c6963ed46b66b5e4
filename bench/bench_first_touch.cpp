// What writing fresh memory costs on this machine, with 4 KiB pages and with 2 MiB pages
// (transparent huge pages, "madvise" mode). The tracker writes tens of bytes per surfel into
// new arrays; on the project's virtual machines the first write to a page costs more than the
// tracking itself, which is why lib/HugePages.h exists. Reports GB/s of a first memset over a
// fresh mapping, and of a second one over the same (now resident) memory, for comparison.
#include <sys/mman.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "BenchSupport.h"

int main(int argc, char** argv) try {
  std::size_t mib = 256;
  int runs = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--mib" && i + 1 < argc) mib = std::stoul(argv[++i]);
    else if (a == "--runs" && i + 1 < argc) runs = std::stoi(argv[++i]);
    else throw std::invalid_argument("usage: bench_first_touch [--mib N] [--runs N]");
  }
  const std::size_t bytes = mib << 20;
  std::printf("first write of %zu MiB fresh anonymous memory, median of %d runs\n", mib, runs);
  std::printf("%-10s %14s %12s %14s\n", "pages", "first GB/s", "ns/byte", "second GB/s");
  for (const bool huge : {false, true}) {
    std::vector<double> first, second;
    for (int r = 0; r < runs; ++r) {
      void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED) throw std::runtime_error("mmap failed");
      if (huge) madvise(p, bytes, MADV_HUGEPAGE);
      double t = surftrack::bench::wallSeconds();
      std::memset(p, 1, bytes);
      first.push_back(surftrack::bench::wallSeconds() - t);
      t = surftrack::bench::wallSeconds();
      std::memset(p, 2, bytes);
      second.push_back(surftrack::bench::wallSeconds() - t);
      munmap(p, bytes);
    }
    const double f = surftrack::bench::median(first), s = surftrack::bench::median(second);
    std::printf("%-10s %14.2f %12.3f %14.2f\n", huge ? "2 MiB" : "4 KiB", bytes / f / 1e9,
                f * 1e9 / double(bytes), bytes / s / 1e9);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_first_touch: error: %s\n", e.what());
  return 2;
}
