// Large arrays written once, front to back (volumes, the surface graph, meshes), are backed by
// 2 MiB pages where Linux offers them (transparent huge pages in "madvise" mode). First-touch
// page faults on 4 KiB pages cost as much as the tracker's own work on virtual machines, and
// every row of a volume read brick by brick would otherwise be a TLB miss.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
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

}  // namespace surftrack
