// Topology and extent of an output mesh: counts, connected components, Euler characteristic
// V - E + F and genus g = (2 - chi) / 2 per component, closedness, bounding box.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "SurfaceMesh.h"

namespace surftrack::cli {

struct ComponentStats {
  std::size_t vertices = 0, edges = 0, triangles = 0;
  long long euler = 0;
  double area = 0, volume = 0;  ///< physical; the volume enclosed (negative: a cavity)
  /// (2 - chi) / 2: an integer for a closed orientable surface.
  double genus() const { return (2.0 - double(euler)) / 2.0; }
};

struct MeshStats {
  std::size_t vertices = 0, edges = 0, triangles = 0;
  long long euler = 0;
  /// Sorted by decreasing vertex count.
  std::vector<ComponentStats> components;
  bool closed = false;    ///< no boundary edge
  bool manifold = false;  ///< every vertex has a single fan of triangles
  std::array<double, 3> min{}, max{};  ///< bounding box of the vertices (physical)
};

MeshStats computeMeshStats(const SurfaceMesh& mesh);

}  // namespace surftrack::cli
