// Independent checks of a triangle mesh for the refine tests and tools: the combinatorics by
// counting (ClosedManifold.h), the geometry with CGAL (self-intersection, point-in-mesh,
// distances), never with the code under test.
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "ClosedManifold.h"

namespace surftrack::checks {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Points = std::vector<std::array<double, 3>>;
using Triangles = std::vector<std::array<std::uint32_t, 3>>;

inline CgalMesh cgalMesh(const Points& points, const Triangles& triangles) {
  CgalMesh m;
  std::vector<CgalMesh::Vertex_index> v;
  v.reserve(points.size());
  for (const auto& p : points) v.push_back(m.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  for (const auto& t : triangles) m.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return m;
}

/// The pairs of triangles that intersect other than in shared vertices and edges (CGAL,
/// exact predicates).
inline std::size_t selfIntersections(const CgalMesh& m) {
  std::vector<std::pair<CgalMesh::Face_index, CgalMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(m, std::back_inserter(pairs));
  return pairs.size();
}

/// Points spread over the triangles: vertices, edge midpoints, centroids and the points of
/// barycentric coordinates (4, 1, 1) / 6 and its rotations.
inline std::vector<Kernel::Point_3> samplePoints(const Points& points, const Triangles& triangles) {
  std::vector<Kernel::Point_3> out;
  auto mix = [&](const std::array<std::uint32_t, 3>& t, double a, double b, double c) {
    const auto &p = points[t[0]], &q = points[t[1]], &r = points[t[2]];
    out.emplace_back(a * p[0] + b * q[0] + c * r[0], a * p[1] + b * q[1] + c * r[1], a * p[2] + b * q[2] + c * r[2]);
  };
  for (const auto& t : triangles) {
    mix(t, 1, 0, 0);
    mix(t, 0.5, 0.5, 0);
    mix(t, 0, 0.5, 0.5);
    mix(t, 0.5, 0, 0.5);
    mix(t, 1.0 / 3, 1.0 / 3, 1.0 / 3);
    mix(t, 4.0 / 6, 1.0 / 6, 1.0 / 6);
    mix(t, 1.0 / 6, 4.0 / 6, 1.0 / 6);
    mix(t, 1.0 / 6, 1.0 / 6, 4.0 / 6);
  }
  return out;
}

/// The largest distance from the samples of (pa, ta) to mesh b (CGAL's AABB tree).
inline double sampledDistance(const Points& pa, const Triangles& ta, const CgalMesh& b) {
  return CGAL::Polygon_mesh_processing::max_distance_to_triangle_mesh<CGAL::Sequential_tag>(samplePoints(pa, ta), b);
}

}  // namespace surftrack::checks
