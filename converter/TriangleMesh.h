// The common output of the loop-extraction converter (method 2) and of the scanning method
// (method 1): an indexed triangle mesh whose vertices are boundary surfels (paper §5.2).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "Surfel.h"

namespace surftrack {

struct TriangleMesh {
  std::vector<Surfel> surfels;  ///< vertex v is the surfel surfels[v]
  /// Triangles as vertex indices, oriented so that the normal (right-hand rule) points from
  /// the 1-voxels to the 0-voxels.
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

}  // namespace surftrack
