// Independent checks of a triangle mesh for the refine tests and tools: the combinatorics by
// hand (directed edges, Euler characteristic, components by union-find), the geometry with CGAL
// (self-intersection, point-in-mesh, distances), never with the code under test.
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cstdint>
#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace surftrack::checks {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Points = std::vector<std::array<double, 3>>;
using Triangles = std::vector<std::array<std::uint32_t, 3>>;

/// The combinatorial figures of a triangle mesh, counted from its triangles alone.
struct Topology {
  bool closedOriented = false;  ///< every directed edge once, and its reverse once
  bool manifoldVertices = false;  ///< the triangles around every used vertex form one fan
  long long euler = 0;          ///< V - E + F over the used vertices
  std::size_t components = 0;   ///< connected components of the triangles
  std::string problem;          ///< what failed, for the test's message
};

inline Topology topologyOf(std::size_t vertexCount, const Triangles& triangles) {
  Topology out;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  out.closedOriented = true;
  for (const auto& [e, n] : directed)
    if (n != 1 || !directed.count({e.second, e.first}) || directed.at({e.second, e.first}) != 1) {
      out.closedOriented = false;
      out.problem = "directed edge " + std::to_string(e.first) + "->" + std::to_string(e.second) + " unmatched";
      break;
    }
  // Fans: around vertex v, the map "next" from each triangle's edge v->a to a->b... links of v
  // form one cycle iff following a -> b (triangle (v, a, b)) from any a returns after all.
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> link(vertexCount);
  std::vector<char> used(vertexCount, 0);
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      link[t[k]].push_back({t[(k + 1) % 3], t[(k + 2) % 3]});
      used[t[k]] = 1;
    }
  out.manifoldVertices = out.closedOriented;
  for (std::size_t v = 0; v < vertexCount && out.manifoldVertices; ++v) {
    if (!used[v]) continue;
    std::map<std::uint32_t, std::uint32_t> next;
    for (auto [a, b] : link[v]) next[a] = b;
    std::uint32_t a = link[v][0].first;
    std::size_t steps = 0;
    do {
      a = next.at(a);
      ++steps;
    } while (a != link[v][0].first && steps <= link[v].size());
    if (steps != link[v].size()) {
      out.manifoldVertices = false;
      out.problem = "vertex " + std::to_string(v) + " has more than one fan";
    }
  }
  std::vector<std::uint32_t> parent(vertexCount);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& t : triangles) {
    parent[find(t[1])] = find(t[0]);
    parent[find(t[2])] = find(t[0]);
  }
  long long vertices = 0;
  for (std::size_t v = 0; v < vertexCount; ++v)
    if (used[v]) {
      ++vertices;
      if (find(std::uint32_t(v)) == v) ++out.components;
    }
  out.euler = vertices - (long long)(directed.size() / 2) + (long long)triangles.size();
  return out;
}

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
