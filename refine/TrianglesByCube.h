// The triangles of a continuous analog grouped by their digital 3-cube (docs/theory.md,
// section 8: every triangle has one), for the fold check of the constrained smoothing: a radix
// sort of the cubes' minimum corners, which costs a few passes over the triangles where a hash
// map of millions of cubes costs a cache miss and an allocation per cube.
#pragma once

#include <span>

#include "CompressedLists.h"
#include "Voxel.h"

namespace surftrack::refine {

/// The triangles of each cube: triangle f is in the list of cube[f], the minimum corner of its
/// cube; each list is in increasing order, and the cubes are numbered in the order of their
/// first triangles, so the result depends on the triangles' order alone.
Lists groupTrianglesByCube(std::span<const Voxel> cube);

}  // namespace surftrack::refine
