// The triangles of a continuous analog grouped by their digital 3-cube (docs/theory.md,
// section 8: every triangle has one), for the fold check of the constrained smoothing: a radix
// sort of the cubes' minimum corners, which costs a few passes over the triangles where a hash
// map of millions of cubes costs a cache miss and an allocation per cube.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "Voxel.h"

namespace surftrack::refine {

/// Compressed lists: the items of list i are items[start[i] .. start[i + 1]).
struct Lists {
  std::vector<std::uint32_t> start, items;
  std::span<const std::uint32_t> operator[](std::size_t i) const {
    return {items.data() + start[i], items.data() + start[i + 1]};
  }
  std::size_t size() const { return start.empty() ? 0 : start.size() - 1; }
};

struct TrianglesByCube {
  std::vector<std::uint32_t> cubeOfTriangle;  ///< triangle -> its cube's index
  Lists trianglesOfCube;                      ///< cube -> its triangles, in increasing order
};

/// Groups triangle f by cube[f], the minimum corner of its cube. Cubes are numbered in the
/// order of their first triangles, so the result depends on the triangles' order alone.
TrianglesByCube groupTrianglesByCube(std::span<const Voxel> cube);

}  // namespace surftrack::refine
