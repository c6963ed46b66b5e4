// The conforming complex of a label map, one digital 3-cube at a time (docs/theory.md,
// "Shared walls"): the labels are put in a priority order (the background lowest), and for each
// level t the voxels of priority >= t form a binary image B_t whose continuous analog V_t is the
// (26,6) one of Definition 9. V_t shrinks as t grows (the local convex volume is monotone in the
// 1-voxels), so the regions R_t = V_t \ V_{t+1} partition space, and every wall is a piece of
// some boundary of V_t: one triangle, used by the two labels it separates, with opposite
// orientations. In a cube, V_t is the convex hull Conv(B_t u A(B_t)) (every corner is
// 26-adjacent to every other), whose faces are the (26,6) table's polygons; each plane holding
// faces of several levels is triangulated once, along all of their traces (NestedWalls.cpp).
// For (6,26) V_t is the closure of the complement of the (26,6) analog of the complement: the
// same on the reversed priorities, turned over.
#pragma once

#include <array>
#include <cstdint>

#include "AdjacencyPair.h"

namespace surftrack {

/// One wall triangle of a cube: three cube edges (DigitalCube.h), oriented so that
/// (b - a) x (c - a) points from the region of priority `inside` to that of `outside`
/// (inside > outside; priorities are the cube's local ranks). The walls of a cube meet only in
/// the vertices and edges they share.
struct WallTriangle {
  std::array<std::uint8_t, 3> edges{};
  std::uint8_t inside = 0, outside = 0;
};

/// Every wall triangle of one cube. At most 6 triangles per level (CubeTriangulation) and 7
/// levels (at most 14 occur: tests/test_shared_walls.cpp).
struct CubeWalls {
  static constexpr int kMaxTriangles = 42;
  int count = 0;
  std::array<WallTriangle, kMaxTriangles> triangles{};
};

/// The walls of a cube whose corner i has local rank rank[i] (the ranks present are 0..k-1,
/// k <= 8, in priority order; a rank is a label), every level's analog that of `pair`, 26-6 or
/// 6-26 (one convex hull per cube and level, or its complement's). Throws std::logic_error if
/// its own invariants fail (never: tests/test_shared_walls.cpp runs every pattern).
CubeWalls cubeWalls(const std::array<std::uint8_t, 8>& rank, AdjacencyPair pair = AdjacencyPair::k26_6);

}  // namespace surftrack
