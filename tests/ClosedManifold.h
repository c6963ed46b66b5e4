// Combinatorial checks of an indexed triangle mesh, by counting, for the tests and the
// mesh_check tool (no GoogleTest here): a closed, consistently oriented 2-manifold, its Euler
// characteristic and its connected components (Boost's disjoint sets, the project's one
// union-find), never from the engine's own code.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <boost/pending/disjoint_sets.hpp>
#include <boost/property_map/property_map.hpp>

namespace surftrack::checks {

/// The combinatorial figures of a triangle mesh, counted from its triangles alone.
struct Topology {
  bool closedOriented = false;    ///< every directed edge once, and its reverse once
  bool manifoldVertices = false;  ///< the triangles around every used vertex form one fan
  long long euler = 0;            ///< V - E + F over the used vertices
  std::size_t components = 0;     ///< connected components of the triangles
  std::string problem;            ///< what failed, for the test's message
};

/// Counts the Euler characteristic and the components, then checks, in this order (the first
/// failure is the `problem`):
///  - every triangle has 3 distinct vertices in range, no triangle is repeated;
///  - every directed edge is used once and its reverse once;
///  - the star of every used vertex is one disc: its triangles (v, a, b) chain a -> b into one
///    cycle.
inline Topology topologyOf(std::size_t vertexCount, const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  Topology out;
  auto fail = [&](const std::string& what) {
    out.problem = what;
    return out;
  };
  std::vector<std::array<std::uint32_t, 3>> sortedTriangles;
  std::vector<std::uint64_t> directed;                // (a << 32) | b for every triangle edge a -> b
  std::vector<std::array<std::uint32_t, 3>> corners;  // (v, a, b) for every triangle (v, a, b)
  std::vector<char> used(vertexCount, 0);
  for (const auto& t : triangles) {
    for (std::uint32_t v : t)
      if (v >= vertexCount) return fail("vertex index out of range");
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      return fail("degenerate triangle " + std::to_string(t[0]) + "," + std::to_string(t[1]) + "," +
                  std::to_string(t[2]));
    std::array<std::uint32_t, 3> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    sortedTriangles.push_back(sorted);
    for (int j = 0; j < 3; ++j) {
      directed.push_back((std::uint64_t(t[j]) << 32) | t[(j + 1) % 3]);
      corners.push_back({t[j], t[(j + 1) % 3], t[(j + 2) % 3]});
      used[t[j]] = 1;
    }
  }
  // Components: vertices joined by the triangles' edges.
  std::vector<std::uint32_t> rank(vertexCount), parent(vertexCount);
  const boost::typed_identity_property_map<std::uint32_t> index;
  boost::disjoint_sets sets(boost::make_iterator_property_map(rank.begin(), index),
                            boost::make_iterator_property_map(parent.begin(), index));
  for (std::uint32_t v = 0; v < vertexCount; ++v) sets.make_set(v);
  for (const auto& t : triangles) {
    sets.union_set(t[0], t[1]);
    sets.union_set(t[0], t[2]);
  }
  long long vertices = 0;
  for (std::uint32_t v = 0; v < vertexCount; ++v)
    if (used[v]) {
      ++vertices;
      if (sets.find_set(v) == v) ++out.components;
    }
  std::vector<std::uint64_t> edges = directed;  // each edge once, as (min << 32) | max
  for (std::uint64_t& e : edges) e = std::min(e, (e << 32) | (e >> 32));
  std::sort(edges.begin(), edges.end());
  const auto distinct = std::unique(edges.begin(), edges.end()) - edges.begin();
  out.euler = vertices - (long long)distinct + (long long)triangles.size();
  std::sort(sortedTriangles.begin(), sortedTriangles.end());
  if (std::adjacent_find(sortedTriangles.begin(), sortedTriangles.end()) != sortedTriangles.end())
    return fail("repeated triangle");
  std::sort(directed.begin(), directed.end());
  if (auto it = std::adjacent_find(directed.begin(), directed.end()); it != directed.end())
    return fail("directed edge " + std::to_string(*it >> 32) + "->" + std::to_string(*it & 0xFFFFFFFFu) +
                " used twice");
  for (std::uint64_t key : directed)
    if (!std::binary_search(directed.begin(), directed.end(), (key << 32) | (key >> 32)))
      return fail("edge " + std::to_string(key >> 32) + "->" + std::to_string(key & 0xFFFFFFFFu) +
                  " has one triangle only (or a misoriented one)");
  out.closedOriented = true;
  // Star of v: its corners (v, a, b) sorted by a; a -> b must be one cycle through all of them.
  std::sort(corners.begin(), corners.end());
  for (std::size_t begin = 0; begin < corners.size();) {
    const std::uint32_t v = corners[begin][0];
    std::size_t end = begin;
    while (end < corners.size() && corners[end][0] == v) ++end;
    const auto first = corners.begin() + std::ptrdiff_t(begin), last = corners.begin() + std::ptrdiff_t(end);
    std::uint32_t a = (*first)[1];
    std::size_t steps = 0;
    do {
      const auto it = std::lower_bound(first, last, std::array<std::uint32_t, 3>{v, a, 0});
      if (it == last || (*it)[1] != a) return fail("star of vertex " + std::to_string(v) + " is open");
      a = (*it)[2];
    } while (++steps <= end - begin && a != (*first)[1]);
    if (steps != end - begin) return fail("star of vertex " + std::to_string(v) + " is not one disc");
    begin = end;
  }
  out.manifoldVertices = true;
  return out;
}

}  // namespace surftrack::checks
