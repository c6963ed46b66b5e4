// Area-weighted vertex normals of a triangle mesh, for the front door's vertexNormals
// (docs/api.md). The smoothing's step sums them around each vertex's ring as it walks it
// (docs/theory.md, section 8), with the Laplacian in the same walk.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "TriangleIntersection.h"

namespace surftrack::refine {

/// Sets sums[v] to the sum of the normals (b - a) x (c - a) of the triangles (a, b, c) around v
/// (each twice its triangle's area: area-weighted, not normalised). sums gets points.size()
/// entries.
inline void sumTriangleNormals(const std::vector<Point3>& points,
                               const std::vector<std::array<std::uint32_t, 3>>& triangles,
                               std::vector<Point3>& sums) {
  sums.assign(points.size(), Point3{0, 0, 0});
  for (const auto& t : triangles) {
    const Point3 n = triangleNormal({points[t[0]], points[t[1]], points[t[2]]});
    for (std::uint32_t v : t)
      for (int k = 0; k < 3; ++k) sums[v][k] += n[k];
  }
}

}  // namespace surftrack::refine
