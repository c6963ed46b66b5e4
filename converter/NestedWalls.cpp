// The walls of one cube from the nested analogs (NestedWalls.h).
//
// Level t's table entry triangulates each planar face of its hull by a fan (§6). A face of a
// higher level may lie in the same plane as a larger face of a lower level (V_t+1 touching the
// boundary of V_t along a polygon); then the lower level's fan does not contain the higher one's
// triangles, and the walls must be cut along the smaller face. So the walls are made per
// oriented plane: the levels with a face in the plane are an interval [a, b] (the faces shrink
// as t grows, since V_t+1 lies inside V_t and the plane supports both), the faces are nested
// convex polygons F_a ⊇ ... ⊇ F_b whose vertices are midpoints, F_b is a wall between b and
// a - 1, and each pocket of F_t minus F_t+1 (cut off by an edge of F_t+1 that is not one of F_t)
// a wall between t and a - 1; each is a fan from its vertex of smallest edge index.
#include "NestedWalls.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "ConfigurationTable.h"
#include "DigitalCube.h"

namespace surftrack {
namespace {

using P = std::array<int, 3>;

P doubledMidpoint(int edge) {
  const Voxel a = cube::cornerOffset(cube::edgeLowCorner(edge)), b = cube::cornerOffset(cube::edgeHighCorner(edge));
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
P minus(const P& a, const P& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
P cross(const P& a, const P& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
int dot(const P& a, const P& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// An oriented plane: its primitive outward normal and offset.
using Plane = std::array<int, 4>;

Plane planeOf(const std::array<std::uint8_t, 3>& t) {
  const P a = doubledMidpoint(t[0]);
  P n = cross(minus(doubledMidpoint(t[1]), a), minus(doubledMidpoint(t[2]), a));
  const int g = std::gcd(std::gcd(std::abs(n[0]), std::abs(n[1])), std::abs(n[2]));
  if (g == 0) throw std::logic_error("cubeWalls: a degenerate table triangle");
  for (int& x : n) x /= g;
  return {n[0], n[1], n[2], dot(n, a)};
}

/// The edges of a convex polygon of the plane, counter-clockwise about its normal.
std::vector<std::uint8_t> counterClockwise(std::vector<std::uint8_t> edges, const Plane& plane) {
  const P n{plane[0], plane[1], plane[2]};
  P sum{0, 0, 0};
  for (auto e : edges)
    for (int i = 0; i < 3; ++i) sum[std::size_t(i)] += doubledMidpoint(e)[std::size_t(i)];
  // Angles about the centroid (scaled by the count to stay in integers), in a basis of the plane.
  const int k = int(edges.size());
  P e1 = minus(P{doubledMidpoint(edges[0])[0] * k, doubledMidpoint(edges[0])[1] * k, doubledMidpoint(edges[0])[2] * k}, sum);
  const P e2 = cross(n, e1);
  auto angle = [&](std::uint8_t e) {
    const P p = doubledMidpoint(e);
    const P d = minus(P{p[0] * k, p[1] * k, p[2] * k}, sum);
    return std::atan2(double(dot(d, e2)), double(dot(d, e1)));
  };
  std::sort(edges.begin(), edges.end(), [&](std::uint8_t a, std::uint8_t b) { return angle(a) < angle(b); });
  return edges;
}

/// A fan of a convex polygon (counter-clockwise) from its vertex of smallest edge index; the
/// labels are assigned afterwards.
void appendFan(std::vector<std::uint8_t> polygon, std::vector<std::array<std::uint8_t, 3>>& out) {
  std::rotate(polygon.begin(), std::min_element(polygon.begin(), polygon.end()), polygon.end());
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) out.push_back({polygon[0], polygon[i], polygon[i + 1]});
}

/// The vertices of q from u round to v (counter-clockwise), both included.
std::vector<std::uint8_t> arc(const std::vector<std::uint8_t>& q, std::uint8_t u, std::uint8_t v) {
  auto it = std::find(q.begin(), q.end(), u);
  std::vector<std::uint8_t> out{u};
  while (*it != v) {
    if (++it == q.end()) it = q.begin();
    out.push_back(*it);
  }
  return out;
}

/// Triangulates the convex polygon q (counter-clockwise, its vertices on the plane at level
/// t - 1) so that the edges of conv(W_t) are edges of the triangulation, recursively: W_t's
/// polygon and the pockets around it, or the two sides of W_t's segment.
void triangulate(const std::vector<std::uint8_t>& q, int t, const std::vector<std::vector<char>>& cutAt,
                 std::vector<std::array<std::uint8_t, 3>>& out) {
  std::vector<std::uint8_t> s;
  if (t < int(cutAt.size()))
    for (auto v : q)
      if (cutAt[std::size_t(t)][v]) s.push_back(v);
  if (s.size() >= 3) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      const std::vector<std::uint8_t> pocket = arc(q, s[i], s[(i + 1) % s.size()]);
      if (pocket.size() >= 3) appendFan(pocket, out);
    }
    triangulate(s, t + 1, cutAt, out);
  } else if (s.size() == 2) {
    for (const auto& side : {arc(q, s[0], s[1]), arc(q, s[1], s[0])})
      if (side.size() >= 3) appendFan(side, out);
  } else {
    appendFan(q, out);
  }
}

/// kappa in {18, 26}: the faces of V_t shrink as t grows.
CubeWalls shrinkingWalls(const std::array<std::uint8_t, 8>& rank, int levels, AdjacencyPair pair) {
  // Oriented plane -> the lowest level with a face in it, and that face's vertices.
  std::map<Plane, std::pair<int, std::vector<std::uint8_t>>> faces;
  std::vector<std::vector<char>> cutAt(std::size_t(levels), std::vector<char>(12, 0));  // edge cut at level t
  for (int t = 1; t < levels; ++t) {
    std::uint8_t config = 0;  // B_t: the corners of priority >= t
    for (int i = 0; i < 8; ++i)
      if (rank[std::size_t(i)] >= t) config = std::uint8_t(config | 1u << i);
    for (int e = 0; e < 12; ++e) cutAt[std::size_t(t)][std::size_t(e)] = cube::edgeIsCut(e, config);
    for (const auto& tri : configurationTable(pair, config).allTriangles()) {
      auto [it, added] = faces.try_emplace(planeOf(tri), t, std::vector<std::uint8_t>{});
      if (it->second.first != t) continue;  // a higher level's face in a lower one's plane
      for (auto e : tri)
        if (std::find(it->second.second.begin(), it->second.second.end(), e) == it->second.second.end())
          it->second.second.push_back(e);
    }
  }
  CubeWalls out;
  std::vector<std::array<std::uint8_t, 3>> triangles;
  for (const auto& [plane, lowest] : faces) {
    const auto& [a, vertices] = lowest;
    triangles.clear();
    triangulate(counterClockwise(vertices, plane), a + 1, cutAt, triangles);
    for (const auto& tri : triangles) {
      // Behind the triangle: the highest level whose analog has it on its boundary, i.e. cuts
      // its three edges; in front: the level below the plane's lowest.
      int inside = a;
      while (inside + 1 < levels && cutAt[std::size_t(inside + 1)][tri[0]] && cutAt[std::size_t(inside + 1)][tri[1]] &&
             cutAt[std::size_t(inside + 1)][tri[2]])
        ++inside;
      if (out.count == CubeWalls::kMaxTriangles) throw std::logic_error("cubeWalls: too many walls");
      out.triangles[std::size_t(out.count++)] = {tri, std::uint8_t(inside), std::uint8_t(a - 1)};
    }
  }
  return out;
}

}  // namespace

CubeWalls cubeWalls(const std::array<std::uint8_t, 8>& rank, AdjacencyPair pair) {
  int levels = 0;  // k: the ranks present are 0..k-1
  for (std::uint8_t r : rank) levels = std::max(levels, int(r) + 1);
  if (kappa(pair) != 6) return shrinkingWalls(rank, levels, pair);
  // kappa = 6 (Definition 28): V_t is the closure of the complement of the lambda-analog of
  // the complement, whose levels are those of the reversed priorities: the walls of the
  // reversed ranks with (lambda, 6), each turned over, inside and outside exchanged.
  std::array<std::uint8_t, 8> reversed;
  for (int i = 0; i < 8; ++i) reversed[std::size_t(i)] = std::uint8_t(levels - 1 - rank[std::size_t(i)]);
  CubeWalls out = shrinkingWalls(reversed, levels, lambda(pair) == 18 ? AdjacencyPair::k18_6 : AdjacencyPair::k26_6);
  for (int w = 0; w < out.count; ++w) {
    WallTriangle& t = out.triangles[std::size_t(w)];
    std::swap(t.edges[1], t.edges[2]);
    const auto inside = std::uint8_t(levels - 1 - t.outside), outside = std::uint8_t(levels - 1 - t.inside);
    t.inside = inside;
    t.outside = outside;
  }
  return out;
}

}  // namespace surftrack
