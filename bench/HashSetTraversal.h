// The baseline bench_tracking measures the tracker against: a straightforward hash-set
// depth-first traversal of beta-adjacencies. It reads the image voxel by voxel through the
// reference betaNeighbours (Definition 38) and keeps the visited surfels in an open-addressing
// hash set keyed by Surfel::key(). It only visits: it builds no graph, so it does less than
// trackComponent and the speed ratio between the two is, if anything, in the baseline's favour.
// Timing both in one run is what makes the ratio comparable across machines, whose absolute
// speeds here drift by ±30 % (docs/performance.md).
#pragma once

#include <cstdint>
#include <vector>

#include "AdjacencyPair.h"
#include "BetaAdjacency.h"
#include "Hash.h"
#include "Surfel.h"

namespace surftrack::bench {

/// The number of surfels of the kappa-lambda-boundary that contains `seed`.
template <class BinaryImage>
std::size_t hashSetTraversal(const BinaryImage& image, const Surfel& seed, AdjacencyPair pair) {
  constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  std::vector<std::uint64_t> slots(1024, kEmpty);
  std::size_t size = 0;
  auto insert = [&](std::uint64_t key) {
    const std::size_t mask = slots.size() - 1;
    for (std::size_t i = mix64(key) & mask;; i = (i + 1) & mask) {
      if (slots[i] == key) return false;
      if (slots[i] == kEmpty) {
        slots[i] = key;
        ++size;
        return true;
      }
    }
  };
  auto growIfHalfFull = [&] {
    if (2 * (size + kMaxBetaNeighbours) <= slots.size()) return;
    std::vector<std::uint64_t> old(2 * slots.size(), kEmpty);
    old.swap(slots);
    size = 0;
    for (std::uint64_t key : old)
      if (key != kEmpty) insert(key);
  };

  insert(seed.key());
  std::vector<Surfel> stack{seed};
  Surfel neighbours[kMaxBetaNeighbours];
  while (!stack.empty()) {
    const Surfel s = stack.back();
    stack.pop_back();
    growIfHalfFull();
    const int count = betaNeighbours(image, s, pair, neighbours);
    for (int i = 0; i < count; ++i)
      if (insert(neighbours[i].key())) stack.push_back(neighbours[i]);
  }
  return size;
}

}  // namespace surftrack::bench
