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
#include "SurfelIndexMap.h"

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
/// Vertex 0 is the seed; vertices are numbered in breadth-first order.
template <class BinaryImage>
SurfaceGraph trackComponent(const BinaryImage& image, const Surfel& seed, AdjacencyPair pair,
                            const TrackingProgress& progress = {}) {
  requireTrackableSeed(image, seed);
  SurfaceGraph result;
  result.pair = pair;
  std::vector<Surfel>& surfels = result.surfels;
  std::vector<std::uint32_t> rowStart{0};
  std::vector<std::uint32_t> targets;
  SurfelIndexMap index;
  surfels.push_back(seed);
  index.insert(seed, 0);
  BinaryBrickCache<BinaryImage> cache(image);
  const BetaNeighbourTable beta(pair);
  Surfel neighbours[kMaxBetaNeighbours];
  // The queue is `surfels` itself: vertex v is expanded at step v, so the arcs come out
  // grouped by source, ready for the CSR graph.
  for (std::size_t v = 0; v < surfels.size(); ++v) {
    const Surfel t = surfels[v];
    const int count = beta.neighbours(cache.neighbourhood(t.inside()).bits, t, neighbours);
    for (int k = 0; k < count; ++k) {
      auto [w, isNew] = index.insert(neighbours[k], std::uint32_t(surfels.size()));
      if (isNew) surfels.push_back(neighbours[k]);
      targets.push_back(w);
    }
    rowStart.push_back(std::uint32_t(targets.size()));
    if (progress && (v & 0xFFFFF) == 0xFFFFF) progress(surfels.size());
  }
  result.graph = makeSurfelGraph(std::move(rowStart), std::move(targets));
  return result;
}

}  // namespace surftrack
