// The cut of a closed mesh on the planes of an octree grid's level 0 (docs/theory.md, section
// 10, "Levels of detail on a grid"): every triangle crossed by a plane is split there, the new vertices on the crossed edges
// shared by both triangles of the edge, so the result is the same surface (closed, oriented,
// the same components and genus) with every triangle inside one cell of level 0 (and so of
// every level), as Neuroglancer's multi-resolution format wants its fragments.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "OctreeGrid.h"

namespace surftrack::refine {

struct GridMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// `mesh` cut on the planes of `grid`'s level 0, along x, then y, then z. A new vertex lies
/// exactly on its plane (its coordinate is the plane's); the old vertices keep their indices
/// and, but for the snap, their points; the new ones follow them. A triangle lying in a plane
/// is kept whole. Before the cut along axis a, a vertex within `snap[a]` of a plane along it
/// (an old one, or one an earlier axis made, whose coordinate is interpolated) is moved onto
/// it: no new vertex then lies within that distance of an old one along the axis (no needle
/// triangles), and quantizing with steps of snap[a] keeps them apart.
GridMesh cutOnGrid(const GridMesh& mesh, const OctreeGrid& grid, const std::array<double, 3>& snap = {});

}  // namespace surftrack::refine
