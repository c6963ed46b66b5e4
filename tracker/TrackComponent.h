// Digital surface tracking (paper §4.3, §5.2): from one seed surfel, a breadth-first traversal
// of beta^{kappa lambda}-adjacencies visits exactly the kappa-lambda-boundary that contains the
// seed (Proposition 39) and records its surface graph. The work and memory are proportional to
// the number of surfels: nothing here is sized by the image volume, so it runs on implicit
// images far too large to store.
#pragma once

#include <cstdint>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "AdjacencyPair.h"
#include "BetaAdjacency.h"
#include "BetaNeighbourTable.h"
#include "BinaryBrickCache.h"
#include "Image.h"
#include "SurfaceGraph.h"
#include "BrickSurfelSet.h"

namespace surftrack {

/// Called now and then during long traversals with the number of surfels found so far.
using TrackingProgress = std::function<void(std::size_t surfelsFound)>;

/// Throws std::invalid_argument unless the domain fits the surfel key and the seed lies on it.
template <class BinaryImage>
void requireTrackableSeed(const BinaryImage& image, const Surfel& seed) {
  const Dims& dims = image.dims();
  for (int a = 0; a < 3; ++a)
    if (dims[a] <= 0 || dims[a] >= Surfel::kCoordinateLimit - 2)
      throw std::invalid_argument("image dimensions must be in [1, " +
                                  std::to_string(Surfel::kCoordinateLimit - 3) + "]");
  for (Voxel v : {seed.inside(), seed.outside()})
    for (int a = 0; a < 3; ++a)
      if (v[a] < -1 || v[a] > dims[a]) {
        std::ostringstream msg;
        msg << "seed " << seed << " lies outside the image domain [0," << dims.nx << ")x[0,"
            << dims.ny << ")x[0," << dims.nz << ")";
        throw std::invalid_argument(msg.str());
      }
  requireBoundarySurfel(image, seed);
}

/// The surface graph G(Sigma, beta) of the kappa-lambda-boundary Sigma containing `seed`.
/// Vertices are numbered by position (brick by brick), not in traversal order.
template <class BinaryImage>
SurfaceGraph trackComponent(const BinaryImage& image, const Surfel& seed, AdjacencyPair pair,
                            const TrackingProgress& progress = {}) {
  requireTrackableSeed(image, seed);
  BinaryBrickCache<BinaryImage> cache(image);
  const BetaNeighbourTable beta(pair);
  BrickSurfelSet visited;
  struct Place {
    std::uint32_t brick;
    int bit;
  };
  // Where surfel s is marked; `near` is a voxel whose brick `nearBrick` is known (a
  // neighbour's 1-voxel is within ±1 of the current one, most often in the same brick).
  auto placeOf = [&cache](const Surfel& s, Voxel near, std::uint32_t nearBrick) {
    const Voxel c = s.inside();
    const bool sameBrick = (((c.x ^ near.x) | (c.y ^ near.y) | (c.z ^ near.z)) >> 3) == 0;
    return Place{sameBrick ? nearBrick : cache.brickOf(c),
                 BrickSurfelSet::bitOf(Voxel{c.x & 7, c.y & 7, c.z & 7}, s.n)};
  };
  Surfel neighbours[kMaxBetaNeighbours];

  // 1. Breadth-first traversal of beta-arcs from the seed: marks the surfels of Sigma.
  {
    std::vector<Surfel> queue{seed};
    const Place p = placeOf(seed, seed.inside(), cache.brickOf(seed.inside()));
    visited.insert(p.brick, p.bit);
    for (std::size_t i = 0; i < queue.size(); ++i) {
      const Surfel t = queue[i];
      const std::uint32_t brick = cache.brickOf(t.inside());
      const int count = beta.neighbours(cache.neighbourhood(brick, t.inside()).bits, t, neighbours);
      for (int k = 0; k < count; ++k) {
        const Place q = placeOf(neighbours[k], t.inside(), brick);
        if (visited.insert(q.brick, q.bit)) queue.push_back(neighbours[k]);
      }
      if (progress && (i & 0xFFFFF) == 0xFFFFF) progress(queue.size());
    }
  }

  // 2. Number the surfels brick by brick, so that each arc finds its target's index in O(1).
  SurfaceGraph result;
  result.pair = pair;
  result.surfels.resize(visited.number());
  {
    std::size_t v = 0;
    visited.forEach([&](std::uint32_t brick, int bit) {
      const Voxel o = cache.brickOrigin(brick);
      const int voxel = bit & 511;
      result.surfels[v++] = Surfel{o + Voxel{voxel & 7, (voxel >> 3) & 7, voxel >> 6},
                                   Direction(bit >> 9)};
    });
  }

  // 3. The arcs, in compressed sparse row form.
  std::vector<std::uint32_t> rowStart;
  std::vector<std::uint32_t> targets;
  rowStart.reserve(result.surfels.size() + 1);
  targets.reserve(4 * result.surfels.size() + 64);
  rowStart.push_back(0);
  for (const Surfel& t : result.surfels) {
    const std::uint32_t brick = cache.brickOf(t.inside());
    const int count = beta.neighbours(cache.neighbourhood(brick, t.inside()).bits, t, neighbours);
    for (int k = 0; k < count; ++k) {
      const Place q = placeOf(neighbours[k], t.inside(), brick);
      targets.push_back(visited.index(q.brick, q.bit));
    }
    rowStart.push_back(std::uint32_t(targets.size()));
  }
  result.graph = makeSurfelGraph(std::move(rowStart), std::move(targets));
  return result;
}

}  // namespace surftrack
