#include "MeshComponents.h"

#include <boost/pending/disjoint_sets.hpp>

namespace surftrack {

std::vector<std::uint32_t> triangleComponents(std::size_t vertexCount,
                                              const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                              std::size_t& count) {
  std::vector<std::uint32_t> rank(vertexCount), parent(vertexCount);
  boost::disjoint_sets<std::uint32_t*, std::uint32_t*> sets(rank.data(), parent.data());
  for (std::uint32_t v = 0; v < vertexCount; ++v) sets.make_set(v);
  for (const auto& t : triangles) {
    sets.union_set(t[0], t[1]);
    sets.union_set(t[0], t[2]);
  }
  // A set's number is given at its first (smallest) vertex; `rank` is reused for it.
  constexpr std::uint32_t kUnnumbered = ~std::uint32_t(0);
  std::fill(rank.begin(), rank.end(), kUnnumbered);
  std::vector<std::uint32_t> label(vertexCount);
  count = 0;
  for (std::uint32_t v = 0; v < vertexCount; ++v) {
    std::uint32_t& number = rank[sets.find_set(v)];
    if (number == kUnnumbered) number = std::uint32_t(count++);
    label[v] = number;
  }
  return label;
}

}  // namespace surftrack
