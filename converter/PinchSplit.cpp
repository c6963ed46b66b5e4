// Pinches of a region's boundary split into sheets (PinchSplit.h).
#include "PinchSplit.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "UnionFind.h"

namespace surftrack {
namespace {

using P = std::array<double, 3>;
P sub(const P& a, const P& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
P cross(const P& a, const P& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const P& a, const P& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

struct Side {
  std::uint32_t lo, hi, triangle;
  std::uint8_t corner;  // the side runs from corner to corner + 1 of its triangle
};

/// The vertices' sheets under one pairing of each edge's triangles, and the copies they give:
/// `joined` (sorted lo << 32 | hi) lists the pinched edges whose triangles are paired across the
/// complement's sectors instead of the region's (the region taken as joined along the edge).
void pairAndCopy(const std::vector<std::array<double, 3>>& points, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                 const std::vector<Side>& sides, const std::vector<std::uint64_t>& joined, PinchSplit& out) {
  UnionFind sheets(3 * triangles.size());  // corners 3t + j; two joined are one sheet at their vertex
  out.pinchedEdges = 0;
  auto runsLowToHigh = [&](const Side& s) { return triangles[s.triangle][s.corner] == s.lo; };
  auto pair = [&](const Side& x, const Side& y) {  // the two triangles bound one sector
    const std::uint32_t tx = x.triangle, ty = y.triangle;
    for (std::uint32_t v : {x.lo, x.hi}) {
      const auto cx = std::uint32_t(std::find(triangles[tx].begin(), triangles[tx].end(), v) - triangles[tx].begin());
      const auto cy = std::uint32_t(std::find(triangles[ty].begin(), triangles[ty].end(), v) - triangles[ty].begin());
      sheets.join(3 * tx + cx, 3 * ty + cy);
    }
  };
  std::vector<std::pair<double, std::size_t>> around;
  for (std::size_t b = 0; b < sides.size();) {
    std::size_t e = b;
    while (e < sides.size() && sides[e].lo == sides[b].lo && sides[e].hi == sides[b].hi) ++e;
    const std::size_t n = e - b;
    if (n == 2 && runsLowToHigh(sides[b]) != runsLowToHigh(sides[b + 1])) {
      pair(sides[b], sides[b + 1]);
    } else {
      std::size_t forward = 0;
      for (std::size_t i = b; i < e; ++i) forward += runsLowToHigh(sides[i]);
      if (2 * forward != n) throw std::logic_error("splitPinches: an edge's triangles are not matched in orientation");
      ++out.pinchedEdges;
      // Angles around d = hi - lo, counter-clockwise (right-hand rule about d).
      const P& a = points[sides[b].lo];
      const P d = sub(points[sides[b].hi], a);
      P e1 = std::abs(d[0]) < std::abs(d[1]) ? (std::abs(d[0]) < std::abs(d[2]) ? P{1, 0, 0} : P{0, 0, 1})
                                             : (std::abs(d[1]) < std::abs(d[2]) ? P{0, 1, 0} : P{0, 0, 1});
      e1 = cross(cross(d, e1), d);  // orthogonal to d
      const P e2 = cross(d, e1);
      around.clear();
      for (std::size_t i = b; i < e; ++i) {
        const auto& t = triangles[sides[i].triangle];
        const P u = sub(points[t[(sides[i].corner + 2) % 3]], a);
        around.push_back({std::atan2(dot(u, e2), dot(u, e1)), i});
      }
      std::sort(around.begin(), around.end());
      // A triangle whose side runs hi -> lo has its outward normal turned clockwise: the region
      // lies counter-clockwise of it, up to the next triangle, which must run lo -> hi. Joined,
      // the complement's sector counter-clockwise of each lo -> hi triangle is bounded instead.
      const bool join = std::binary_search(joined.begin(), joined.end(), std::uint64_t(sides[b].lo) << 32 | sides[b].hi);
      for (std::size_t k = 0; k < n; ++k) {
        const Side& x = sides[around[k].second];
        if (runsLowToHigh(x) != join) continue;
        const Side& y = sides[around[(k + 1) % n].second];
        if (runsLowToHigh(y) == join) throw std::logic_error("splitPinches: the triangles around an edge do not alternate");
        pair(x, y);
      }
    }
    b = e;
  }
  // Each vertex's sheets: the first keeps the vertex, the others get copies.
  out.triangles = triangles;
  out.copyOf.clear();
  std::vector<std::uint32_t> copy(3 * triangles.size(), ~0u);  // root corner -> vertex
  std::vector<char> taken(points.size(), 0);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (std::uint32_t j = 0; j < 3; ++j) {
      const std::uint32_t root = sheets.find(3 * t + j), v = triangles[t][j];
      if (copy[root] == ~0u) {
        if (!taken[v]) {
          taken[v] = 1;
          copy[root] = v;
        } else {
          copy[root] = std::uint32_t(points.size() + out.copyOf.size());
          out.copyOf.push_back(v);
        }
      }
      out.triangles[t][j] = copy[root];
    }
}

/// The edges of more than two triangles of `out`, named by their original vertices (sorted
/// lo << 32 | hi, each once); `count` gets how many edges of `out` they are.
std::vector<std::uint64_t> crowdedEdges(std::size_t vertexCount, const PinchSplit& out, std::size_t& count) {
  auto original = [&](std::uint32_t v) -> std::uint64_t { return v < vertexCount ? v : out.copyOf[v - vertexCount]; };
  std::vector<std::pair<std::uint64_t, std::uint64_t>> edges;  // (split edge, original edge)
  for (const auto& t : out.triangles)
    for (int j = 0; j < 3; ++j) {
      const std::uint64_t a = t[std::size_t(j)], b = t[std::size_t((j + 1) % 3)];
      const std::uint64_t oa = original(t[std::size_t(j)]), ob = original(t[std::size_t((j + 1) % 3)]);
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), std::min(oa, ob) << 32 | std::max(oa, ob)});
    }
  std::sort(edges.begin(), edges.end());
  std::vector<std::uint64_t> crowded;
  count = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t e = i;
    while (e < edges.size() && edges[e].first == edges[i].first) ++e;
    if (e - i > 2) crowded.push_back(edges[i].second), ++count;
    i = e;
  }
  std::sort(crowded.begin(), crowded.end());
  crowded.erase(std::unique(crowded.begin(), crowded.end()), crowded.end());
  return crowded;
}

}  // namespace

PinchSplit splitPinches(const std::vector<std::array<double, 3>>& points,
                        const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  // Every triangle side as (low vertex, high vertex, triangle, corner of its first vertex),
  // sorted by (lo, hi, triangle) so that the sides of one edge are together: placed by lo
  // (count, prefix sum, fill, in triangle order), then each vertex's few sorted by hi.
  std::vector<std::uint32_t> start(points.size() + 1, 0);
  for (const auto& t : triangles)
    for (std::uint8_t j = 0; j < 3; ++j) ++start[std::size_t(std::min(t[j], t[(j + 1) % 3])) + 1];
  for (std::size_t v = 0; v < points.size(); ++v) start[v + 1] += start[v];
  std::vector<Side> sides(3 * triangles.size());
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      for (std::uint8_t j = 0; j < 3; ++j) {
        const std::uint32_t a = triangles[t][j], b = triangles[t][(j + 1) % 3];
        sides[next[std::min(a, b)]++] = {std::min(a, b), std::max(a, b), t, j};
      }
  }
  for (std::size_t v = 0; v < points.size(); ++v) {
    const auto first = sides.begin() + start[v], last = sides.begin() + start[v + 1];
    if (last - first > 32) {  // (a vertex of the digital surfaces has a few dozen sides at most)
      std::sort(first, last, [](const Side& x, const Side& y) { return x.hi != y.hi ? x.hi < y.hi : x.triangle < y.triangle; });
      continue;
    }
    for (auto i = first + 1; i < last; ++i)  // insertion: stable, equal hi stay in triangle order
      for (auto k = i; k > first && k->hi < (k - 1)->hi; --k) std::iter_swap(k, k - 1);
  }
  PinchSplit out;
  pairAndCopy(points, triangles, sides, {}, out);
  if (out.pinchedEdges == 0) return out;  // (copies never crowd an edge)
  std::size_t crowded = 0;
  std::vector<std::uint64_t> joined = crowdedEdges(points.size(), out, crowded);
  if (!joined.empty()) {
    // The region wraps round and touches itself along these edges: taken as joined there, the
    // sheets at each end part, and copies of both ends separate them (PinchSplit.h).
    pairAndCopy(points, triangles, sides, joined, out);
    out.joinedEdges = joined.size();
    crowdedEdges(points.size(), out, out.unsplitEdges);
  }
  return out;
}

}  // namespace surftrack
