// Topology and extent of an output mesh, for the summary: counts, the figures of each connected
// component (Euler characteristic V - E + F, genus (2 - chi) / 2, area, enclosed volume — the
// engine's own, Extract.h's ComponentFigures), closedness, bounding box.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "Extract.h"

namespace surftrack::cli {

struct MeshStats {
  std::size_t vertices = 0, edges = 0, triangles = 0;
  long long euler = 0;
  /// Sorted by decreasing surfel (vertex) count.
  std::vector<ComponentFigures> components;
  bool closed = false;    ///< no boundary edge
  bool manifold = false;  ///< every vertex has a single fan of triangles
  std::array<double, 3> min{}, max{};  ///< bounding box of the vertices (physical)
};

/// The figures of `surface`, whose triangles requireClosedOrientedManifold (SurfaceMesh.h) has
/// accepted: a closed, consistently oriented 2-manifold, so both flags are true and every edge
/// is in two triangles (E = 3F / 2); the components' figures are the engine's.
MeshStats meshStats(const Surface& surface);

}  // namespace surftrack::cli
