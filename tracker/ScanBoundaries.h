// The scanning counterpart of tracking: enumerate every boundary surfel of the image (an
// O(volume) scan) and split them into beta-components with a union-find over the same
// adjacency. By Proposition 39 the components are exactly the kappa-lambda-boundaries.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <vector>

#include "AdjacencyPair.h"
#include "BetaAdjacency.h"
#include "Image.h"

namespace surftrack {

/// All boundary surfels of an image, each with the index of its beta-component.
struct BoundaryPartition {
  std::vector<Surfel> surfels;
  std::vector<std::uint32_t> component;  ///< component[i] of surfels[i], in [0, componentCount)
  std::size_t componentCount = 0;

  /// The surfels of each component, in the order of `surfels`.
  std::vector<std::vector<Surfel>> components() const {
    std::vector<std::vector<Surfel>> out(componentCount);
    for (std::size_t i = 0; i < surfels.size(); ++i) out[component[i]].push_back(surfels[i]);
    return out;
  }
};

/// Every boundary surfel of the image: c in the domain padded by one voxel, d a 6-neighbour.
template <class BinaryImage>
std::vector<Surfel> allBoundarySurfels(const BinaryImage& image) {
  const Dims& dims = image.dims();
  std::vector<Surfel> out;
  for (int z = -1; z <= dims.nz; ++z)
    for (int y = -1; y <= dims.ny; ++y)
      for (int x = -1; x <= dims.nx; ++x) {
        if (!image(x, y, z)) continue;
        for (Direction n = 0; n < 6; ++n) {
          const Surfel s{Voxel{x, y, z}, n};
          if (!image(s.outside())) out.push_back(s);
        }
      }
  return out;
}

template <class BinaryImage>
BoundaryPartition scanBoundaries(const BinaryImage& image, AdjacencyPair pair) {
  BoundaryPartition result;
  result.surfels = allBoundarySurfels(image);
  const std::size_t count = result.surfels.size();
  std::unordered_map<Surfel, std::uint32_t> indexOf;
  indexOf.reserve(count);
  for (std::size_t i = 0; i < count; ++i) indexOf.emplace(result.surfels[i], std::uint32_t(i));

  std::vector<std::uint32_t> parent(count);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  Surfel neighbours[kMaxBetaNeighbours];
  for (std::size_t i = 0; i < count; ++i) {
    const int k = betaNeighbours(image, result.surfels[i], pair, neighbours);
    for (int j = 0; j < k; ++j) {
      const std::uint32_t a = find(std::uint32_t(i)), b = find(indexOf.at(neighbours[j]));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  // Number components by their smallest surfel index.
  result.component.assign(count, 0);
  std::vector<std::uint32_t> label(count, ~0u);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t r = find(std::uint32_t(i));
    if (label[r] == ~0u) label[r] = std::uint32_t(result.componentCount++);
    result.component[i] = label[r];
  }
  return result;
}

}  // namespace surftrack
