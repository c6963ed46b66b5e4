// Independent checks of a triangle mesh for the refine tests and tools: the combinatorics by
// counting (ClosedManifold.h), the geometry with CGAL (self-intersection, point-in-mesh,
// distances, orientation), never with the code under test. CGAL stays inside
// CgalMeshChecks.cpp, compiled once into surftrack_cgal_checks (tests/CMakeLists.txt): in the
// sanitized build it is an oracle, not code under test, and is compiled without the sanitizers.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "ClosedManifold.h"

namespace surftrack::checks {

using Point = std::array<double, 3>;
using Points = std::vector<Point>;
using Triangles = std::vector<std::array<std::uint32_t, 3>>;

/// The pairs of triangles that intersect other than in shared vertices and edges (CGAL,
/// exact predicates).
std::size_t selfIntersections(const Points& points, const Triangles& triangles);

/// The pairs of triangles of a soup (any number of triangles on an edge, as a label map's
/// complex) that meet other than in the vertices they share by index: a repeated triangle; two
/// on a shared edge, coplanar, on the same side of it; two with a shared vertex whose opposite
/// edge meets the other one; two with nothing shared that meet (CGAL, exact predicates).
/// Brute force over the pairs whose boxes meet: for small complexes.
std::size_t soupIntersections(const Points& points, const Triangles& triangles);

/// The largest distance from samples of mesh a to mesh b (CGAL's AABB tree): vertices, edge
/// midpoints, centroids and the points of barycentric coordinates (4, 1, 1) / 6 and its
/// rotations of every triangle of a.
double sampledDistance(const Points& pa, const Triangles& ta, const Points& pb, const Triangles& tb);

/// Where a point is with respect to a closed mesh (CGAL's ray-parity Side_of_triangle_mesh).
enum class Side { Inside, Outside, Boundary };

class SideOfMesh {
 public:
  SideOfMesh(const Points& points, const Triangles& triangles);
  ~SideOfMesh();
  Side operator()(const Point& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The sign of the orientation of (p, q, r, s), exactly (CGAL's orientation predicate): +1
/// when s is on the positive side of the plane of p, q, r, -1 on the negative, 0 on it.
int orientation(const Point& p, const Point& q, const Point& r, const Point& s);

}  // namespace surftrack::checks
