// The loops of §5.2 read off the configuration tables. In a digital 3-cube, the surfels of one
// patch form a loop whose consecutive surfels are joined by a beta-arc lying on a cube face;
// the patch's triangles are oriented, so the triangle edges used once are that loop, in order.
// Knowing the order, the converter walks a loop by following, from each surfel, the one out-arc
// that leads to the next cube edge: no search, and no need to look at a surfel to know where it
// is. Derived once per pair from the tables (themselves computed from Definition 9).
#pragma once

#include <array>
#include <cstdint>

#include "AdjacencyPair.h"
#include "ConfigurationTable.h"
#include "DigitalCube.h"

namespace surftrack {

/// The surfel on a cut edge of a cube, relative to the cube's min corner m.
struct EdgeSurfel {
  Voxel inside;      ///< its 1-voxel minus m
  Direction n = 0;   ///< its normal
  std::uint8_t cubeSlot = 0;  ///< which of the surfel's 4 cubes this is (cube::cubesOf order)
  /// Index among the surfel's out-arcs (SurfaceGraph.h order) of the edge neighbour across
  /// direction e, for each of the 6 directions (only the 4 orthogonal to n are meaningful).
  std::array<std::uint8_t, 6> arcOf{};
};

/// The loop of one patch: its cube edges in order (triangle orientation), and for each the
/// out-arc of its surfel that leads to the next one. length 0: not a loop (the strict-26 tube).
/// The patch's triangles are restated in loop positions, so that a walk that records the vertex
/// at each position can emit them without looking up cube edges again.
struct CubeLoop {
  static constexpr std::uint8_t kNotInLoop = 0xFF;

  std::uint8_t length = 0;
  std::array<std::uint8_t, cube::kEdges> edge{};
  std::array<std::uint8_t, cube::kEdges> arc{};
  std::array<std::uint8_t, cube::kEdges> cubeSlot{};    ///< EdgeSurfel::cubeSlot at each position
  std::array<std::uint8_t, cube::kEdges> positionOf{};  ///< of each cube edge, or kNotInLoop
  std::uint8_t triangleCount = 0;
  std::array<std::array<std::uint8_t, 3>, CubeTriangulation::kMaxTriangles> triangles{};
};

using EdgeSurfels = std::array<std::array<EdgeSurfel, cube::kEdges>, 256>;
using CubeLoops = std::array<std::array<CubeLoop, CubeTriangulation::kMaxPatches>, 256>;

/// edgeSurfels()[config][k]: the surfel on cut edge k of a cube with configuration `config`.
const EdgeSurfels& edgeSurfels();

/// cubeLoops(pair)[config][p]: the loop of patch p of configuration `config` for `pair`.
const CubeLoops& cubeLoops(AdjacencyPair pair);

}  // namespace surftrack
