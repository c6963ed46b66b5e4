// Lists of indices stored back to back (compressed sparse rows), for the smoothing's per-cube
// and per-vertex lists (docs/theory.md, section 8): one allocation for all the lists, items
// read in order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "HugePages.h"

namespace surftrack::refine {

/// The items of list i are items[start[i] .. start[i + 1]).
struct Lists {
  std::vector<std::uint32_t> start, items;
  std::span<const std::uint32_t> operator[](std::size_t i) const {
    return {items.data() + start[i], items.data() + start[i + 1]};
  }
  std::size_t size() const { return start.empty() ? 0 : start.size() - 1; }
};

/// The lists of the items k with owner[k] = i, for i < count, each in increasing order (a
/// counting sort; the items on huge pages, lib/HugePages.h, for large inputs).
/// \pre every owner[k] < count.
inline Lists invert(std::span<const std::uint32_t> owner, std::size_t count) {
  Lists out;
  out.start.assign(count + 1, 0);
  for (std::uint32_t o : owner) ++out.start[o + 1];
  for (std::size_t i = 0; i < count; ++i) out.start[i + 1] += out.start[i];
  out.items = hugePageVector<std::uint32_t>(owner.size());
  std::vector<std::uint32_t> next(out.start.begin(), out.start.end() - 1);
  for (std::size_t k = 0; k < owner.size(); ++k) out.items[next[owner[k]]++] = std::uint32_t(k);
  return out;
}

}  // namespace surftrack::refine
