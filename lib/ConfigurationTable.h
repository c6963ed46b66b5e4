// The configuration tables of paper §5.1: for each adjacency pair (kappa, lambda) and each of
// the 256 configurations of a digital 3-cube (conventions of DigitalCube.h), the triangles of
// the continuous analog with the midpoint boundary mapping, i.e. the faces of the C^3-local
// volume of Definition 9 whose vertices are all boundary vertices (Figure 2 (c)). A vertex is a
// cube edge index: a boundary surfel lies on exactly one cube edge.
//
// The tables are never typed in: lib/LocalConvexVolume.cpp computes them from Definition 9
// and tools/generate_configuration_tables.cpp writes them, at build time, to the generated
// ConfigurationTables.inc compiled into ConfigurationTable.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "AdjacencyPair.h"

namespace surftrack {

/// The triangles of one configuration of one pair, grouped by patch.
///  - Each triangle (a, b, c) is oriented so that (b - a) x (c - a) points from the 1-voxels to
///    the 0-voxels (outward of the local volume of the 1-voxels).
///  - A patch is a connected component of the triangles under sharing a triangle edge: a loop
///    of surfels (§5.2) triangulated, or, in a strict 26-configuration, the 6-triangle "tube"
///    (A_i, A_j, B_k), (B_i, B_j, A_k). Every cut edge belongs to exactly one patch.
///  - Triangle edges joining two cube edges of a common cube face are the beta-arcs of rules
///    (i)-(iii) of Definition 38 inside the cube, each used by one triangle; the other
///    ("inner") edges are used by two triangles in opposite directions.
struct CubeTriangulation {
  static constexpr int kMaxTriangles = 6;   // over all 4 x 256 configurations (checked by the generator)
  static constexpr int kMaxPatches = 4;     // four isolated corners of a checkerboard cube

  std::uint8_t triangleCount = 0;
  std::uint8_t patchCount = 0;
  /// Cube-edge indices; triangles of patch p are [patchBegin[p], patchBegin[p + 1]).
  std::array<std::array<std::uint8_t, 3>, kMaxTriangles> triangles{};
  std::array<std::uint8_t, kMaxPatches + 1> patchBegin{};
  /// The patch of the surfel on each cube edge, -1 for an edge that carries no surfel.
  std::array<std::int8_t, 12> patchOfEdge{};

  std::span<const std::array<std::uint8_t, 3>> allTriangles() const {
    return {triangles.data(), triangleCount};
  }
  std::span<const std::array<std::uint8_t, 3>> patchTriangles(int p) const {
    return {triangles.data() + patchBegin[p], std::size_t(patchBegin[p + 1] - patchBegin[p])};
  }
};

/// The precomputed table entry of `config` (bit i = value of corner i) for `pair`.
const CubeTriangulation& configurationTable(AdjacencyPair pair, std::uint8_t config);

/// All 256 entries of `pair`, indexed by configuration.
std::span<const CubeTriangulation, 256> configurationTables(AdjacencyPair pair);

}  // namespace surftrack
