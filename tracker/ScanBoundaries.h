// The scanning counterpart of tracking: enumerate every boundary surfel of the image (an
// O(volume) scan) and split them into beta-components with a union-find (Boost's disjoint sets)
// over the same adjacency. By Proposition 39 the components are exactly the
// kappa-lambda-boundaries.
#pragma once

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <boost/pending/disjoint_sets.hpp>

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

  // Boost's disjoint sets, as in converter/MeshComponents.h (the project's one union-find). The
  // ranks and parents are iterator property maps, not pointers: where Boost's CSR graph is
  // included (SurfaceGraph.h), its boost::detail::get hides the boost::get of pointers.
  std::vector<std::uint32_t> rank(count), parent(count);
  const boost::typed_identity_property_map<std::uint32_t> index;
  boost::disjoint_sets sets(boost::make_iterator_property_map(rank.begin(), index),
                            boost::make_iterator_property_map(parent.begin(), index));
  for (std::uint32_t i = 0; i < count; ++i) sets.make_set(i);
  Surfel neighbours[kMaxBetaNeighbours];
  for (std::size_t i = 0; i < count; ++i) {
    const int k = betaNeighbours(image, result.surfels[i], pair, neighbours);
    for (int j = 0; j < k; ++j) sets.union_set(std::uint32_t(i), indexOf.at(neighbours[j]));
  }
  // Number components by their smallest surfel index; `rank` is reused for the numbers.
  constexpr std::uint32_t kUnnumbered = ~std::uint32_t(0);
  std::fill(rank.begin(), rank.end(), kUnnumbered);
  result.component.assign(count, 0);
  for (std::uint32_t i = 0; i < count; ++i) {
    std::uint32_t& number = rank[sets.find_set(i)];
    if (number == kUnnumbered) number = std::uint32_t(result.componentCount++);
    result.component[i] = number;
  }
  return result;
}

}  // namespace surftrack
