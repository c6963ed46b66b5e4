#include "MeshComponents.h"

#include <boost/pending/disjoint_sets.hpp>

namespace surftrack {
namespace {

/// The sets of `count` elements after `joinAll(sets)`, numbered 0, 1, ... in the order of their
/// smallest element; `number` receives the number of sets.
template <class JoinAll>
std::vector<std::uint32_t> numberedSets(std::size_t count, JoinAll joinAll, std::size_t& number) {
  std::vector<std::uint32_t> rank(count), parent(count);
  boost::disjoint_sets<std::uint32_t*, std::uint32_t*> sets(rank.data(), parent.data());
  for (std::uint32_t v = 0; v < count; ++v) sets.make_set(v);
  joinAll(sets);
  // A set's number is given at its first (smallest) element; `rank` is reused for it.
  constexpr std::uint32_t kUnnumbered = ~std::uint32_t(0);
  std::fill(rank.begin(), rank.end(), kUnnumbered);
  std::vector<std::uint32_t> label(count);
  number = 0;
  for (std::uint32_t v = 0; v < count; ++v) {
    std::uint32_t& n = rank[sets.find_set(v)];
    if (n == kUnnumbered) n = std::uint32_t(number++);
    label[v] = n;
  }
  return label;
}

}  // namespace

std::vector<std::uint32_t> triangleComponents(std::size_t vertexCount,
                                              const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                              std::size_t& count) {
  return numberedSets(
      vertexCount,
      [&](auto& sets) {
        for (const auto& t : triangles) {
          sets.union_set(t[0], t[1]);
          sets.union_set(t[0], t[2]);
        }
      },
      count);
}

std::vector<std::uint32_t> joinedComponents(std::size_t elementCount,
                                            const std::vector<std::array<std::uint32_t, 2>>& joins,
                                            std::size_t& count) {
  return numberedSets(
      elementCount,
      [&](auto& sets) {
        for (const auto& j : joins) sets.union_set(j[0], j[1]);
      },
      count);
}

}  // namespace surftrack
