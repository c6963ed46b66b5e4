// Several kappa-lambda-boundaries of one binary image, each tracked once (paper §4.3, §5.2),
// from seeds that a scan found (LabelSeeds.h): the x-surfels of the image, of which every
// boundary holds at least one. A tracked boundary marks the x-surfels it holds, so a seed on a
// boundary already tracked is skipped; the cost is that of tracking each boundary wanted once,
// plus a binary search per x-surfel tracked.
#pragma once

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "AdjacencyPair.h"
#include "SurfaceGraph.h"
#include "TrackComponent.h"

namespace surftrack {

/// Tracks the boundary of each seed xSurfels[i], i in `wanted` in that order, unless a boundary
/// tracked before holds it, and passes its surface graph to onBoundary(SurfaceGraph&&).
/// \param xSurfels the keys, in increasing order, of all surfels of `image` whose normal is +x
///        or -x (LabelSeeds::surfels)
/// \throw std::logic_error if a tracked boundary holds an x-surfel missing from xSurfels (the
///        seeds do not belong to this image)
template <class BinaryImage, class OnBoundary>
void trackBoundaries(const BinaryImage& image, const std::vector<std::uint64_t>& xSurfels,
                     const std::vector<std::size_t>& wanted, AdjacencyPair pair, OnBoundary&& onBoundary) {
  std::vector<bool> tracked(xSurfels.size(), false);
  for (std::size_t i : wanted) {
    if (tracked[i]) continue;
    SurfaceGraph graph = trackComponent(image, Surfel::fromKey(xSurfels[i]), pair);
    for (const Surfel& s : graph.surfels) {
      if (axisOf(s.n) != 0) continue;
      const auto at = std::lower_bound(xSurfels.begin(), xSurfels.end(), s.key());
      if (at == xSurfels.end() || *at != s.key()) {
        std::ostringstream msg;
        msg << "trackBoundaries: the boundary tracked from " << Surfel::fromKey(xSurfels[i]) << " holds "
            << s << ", which the scan did not find";
        throw std::logic_error(msg.str());
      }
      tracked[std::size_t(at - xSurfels.begin())] = true;
    }
    onBoundary(std::move(graph));
  }
}

}  // namespace surftrack
