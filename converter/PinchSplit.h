// The documented exception of shared walls (docs/theory.md, "Shared walls", "Pinches"): where a
// label's region R touches itself at a vertex or along an edge of the complex (a pinch), its
// triangles are not a 2-manifold there. The region's boundary is made one by giving each sheet
// that meets there its own copy of the vertex: around an edge with 2k > 2 triangles of the label,
// the triangles are paired across the k sectors of R between them (by angle around the edge);
// around a vertex, the triangles joined through paired edges form one fan each, and every fan
// but the first gets a new copy of the vertex, at the same point. Nothing moves; the wall
// triangles stay shared (the same points, the same surfels). A pinched edge whose sheets are
// joined around both its ends (the region wraps round and touches itself along the edge) is not
// separated by any copy of a vertex; there the region is taken as joined along the edge instead
// (its triangles paired across the complement's sectors), which parts the sheets at both ends,
// and the copies of both ends separate the edge's triangles into two edges at the same points
// (joinedEdges; docs/theory.md §12, "The exception"). An edge still of more than two triangles
// after that stays, counted (unsplitEdges).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace surftrack {

struct PinchSplit {
  /// The triangles over the split vertices: vertex v < the input's count is itself, vertex
  /// count + j is a copy of copyOf[j].
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::uint32_t> copyOf;
  std::size_t pinchedEdges = 0;  ///< edges of more than 2 triangles
  /// Pinched edges whose sheets are joined around both of their ends, so that no vertex copy
  /// separates them with the region's pairing: taken as joined along the edge instead.
  std::size_t joinedEdges = 0;
  /// Edges still of more than 2 triangles after the split (joined ones included).
  std::size_t unsplitEdges = 0;
};

/// Splits the pinches of a closed oriented triangle 2-cycle (every directed edge matched by as
/// many reverse ones) whose vertex v lies at points[v]; triangles are oriented outward of the
/// region (right-hand rule). Throws std::logic_error if an edge's triangles do not alternate in
/// orientation around it.
PinchSplit splitPinches(const std::vector<std::array<double, 3>>& points,
                        const std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace surftrack
