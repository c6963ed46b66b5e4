// Topology-safe decimation of a conforming complex of shared walls (docs/theory.md §12,
// "Decimating the complex"): the triangles of a label map's complex, each wall once, between
// two regions. The complex is cut into its walls (the triangles between one ordered pair of
// regions); a vertex of more than one wall (a junction line), or where some region's triangles
// are not one closed disc around it (a pinch), is locked. Each wall, a surface with boundary
// whose border vertices are all locked, is decimated once, one after the other, by
// decimateSafely's engine (CheckedDecimater.h with the quadric, the normal-flip guard, the link
// condition, the embedding guard and the distance bound, TopologySafeDecimation.h), with two
// more demands: the link condition and the embedding hold in the whole complex
// (ComplexLinkGuard.h, EmbeddingGuard.h's obstacles), and only free vertices go. Then the
// vertices inside junction lines go along them, in every wall at once (JunctionLines.h), and
// the walls again. A halfedge collapse moves no vertex, and a wall's decimated triangles replace
// its own: written to both regions (reversed for one), the walls stay shared triangle for
// triangle, the junction lines are the same in every wall along them, and every region's
// surface keeps its topology.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "TopologySafeDecimation.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

struct ComplexDecimationReport {
  std::size_t trianglesBefore = 0, trianglesAfter = 0;
  std::size_t targetTriangles = 0;  ///< the walls' targets summed (0: no target)
  std::size_t walls = 0;            ///< walls of the complex
  std::size_t lockedVertices = 0;   ///< vertices on junction lines or pinches
  std::size_t junctionCollapses = 0;  ///< vertices gone from inside junction lines (JunctionLines.h)
};

/// Decimates the complex of `triangles` over `points` (physical) in place: triangle t lies on
/// the wall between regions sides[t][0] and sides[t][1] (an ordered pair: the triangles of one
/// wall are oriented alike); on return removed[t] says whether triangle t is gone, and
/// triangles[t] holds a survivor's vertices (a removed vertex replaced by the one it went into;
/// the orientation kept). The walls are decimated in rounds, each wall a part of the way to its
/// target in each, then the junction lines (see ComplexDecimation.cpp). parameters.grid is not
/// used; a reduction applies to each wall and each region (the reduction of its triangles), as far
/// as the guards allow, and last a region still above its target takes up to 4 % of theirs from
/// its neighbours (DecimatedComplex::balancing): a region ends at most 4 % of its target and one
/// collapse below it. A `background` region (a label map's, whose surface is not made) has no
/// target of its own: its walls go as far as their other region's allows.
/// \throw std::invalid_argument for parameters out of range (decimateSafely's), sizes that
///        differ or a vertex index out of range; Cancelled when parameters.cancel is raised.
ComplexDecimationReport decimateComplex(const std::vector<Point3>& points,
                                        std::vector<std::array<std::uint32_t, 3>>& triangles,
                                        const std::vector<std::array<std::uint32_t, 2>>& sides,
                                        std::vector<char>& removed, const DecimationParameters& parameters,
                                        std::optional<std::uint32_t> background = std::nullopt);

}  // namespace surftrack::refine
