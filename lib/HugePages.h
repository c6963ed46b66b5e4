// Large arrays written once, front to back (volumes, the surface graph, meshes), are backed by
// 2 MiB pages where Linux offers them (transparent huge pages in "madvise" mode). First-touch
// page faults on 4 KiB pages cost as much as the tracker's own work on virtual machines, and
// every row of a volume read brick by brick would otherwise be a TLB miss.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace surftrack {

/// Asks for huge pages on the whole 2 MiB pages inside [data, data + bytes). Effective only
/// before the memory is first written; harmless where unsupported.
inline void adviseHugePages(void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t(1) << 21;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data, (void)bytes;
#endif
}

/// v.reserve(n) on fresh memory advised for huge pages (the elements are moved over).
template <class T>
void reserveHugePages(std::vector<T>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  std::vector<T> bigger;
  bigger.reserve(n);
  adviseHugePages(bigger.data(), n * sizeof(T));
  bigger.insert(bigger.end(), std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
  v.swap(bigger);
}

/// v.resize(n), growing geometrically onto huge-page-advised memory.
template <class T>
void resizeHugePages(std::vector<T>& v, std::size_t n) {
  if (n > v.capacity()) reserveHugePages(v, std::max(n, 2 * v.capacity()));
  v.resize(n);
}

/// A vector of n value-initialised elements on huge-page-advised memory.
template <class T>
std::vector<T> hugePageVector(std::size_t n) {
  std::vector<T> v;
  resizeHugePages(v, n);
  return v;
}

/// An uninitialised array of n trivial values, on fresh memory, for results written once
/// (in parallel: the page faults then fall on the threads that write). From 1 MiB on, the
/// memory is whole 2 MiB pages (aligned, the size rounded up) advised for huge pages: written
/// once at random, it would otherwise cost a page fault per 4 KiB, the first and last 2 MiB of
/// an unaligned block included (docs/performance.md, 'Fresh memory on this machine'). Its
/// memory is std::malloc's: release() hands it to an owner that calls std::free (a numpy
/// array's capsule, python/src/MarchingCubes.cpp).
struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <class T>
using FreshArray = std::unique_ptr<T[], FreeDeleter>;

template <class T>
FreshArray<T> freshArray(std::size_t n) {
  static_assert(std::is_trivially_default_constructible_v<T> && std::is_trivially_destructible_v<T>);
  constexpr std::size_t kHuge = std::size_t(1) << 21;
  const std::size_t bytes = std::max<std::size_t>(n, 1) * sizeof(T);
  void* p = nullptr;
  if (bytes >= kHuge / 2) {
    const std::size_t rounded = (bytes + kHuge - 1) & ~(kHuge - 1);
    p = std::aligned_alloc(kHuge, rounded);
    if (p) adviseHugePages(p, rounded);
  } else {
    p = std::malloc(bytes);
  }
  if (!p) throw std::bad_alloc();
  return FreshArray<T>(static_cast<T*>(p));
}

}  // namespace surftrack
