// The cut of a mesh on a grid's planes (GridCut.h).
#include "GridCut.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace surftrack::refine {

namespace {

/// One axis: every triangle split on the planes strictly inside its span. Each edge crossed
/// gets its new vertices once (keyed by its two ends), in order of increasing plane, so that
/// the two triangles of an edge share them and the mesh stays conforming.
void cutAlong(GridMesh& m, const OctreeGrid& grid, int axis, double snap) {
  // The snap, for the vertices of the earlier passes too: theirs interpolate this coordinate,
  // and one a rounding error off a plane would be cut into needles.
  for (auto& p : m.vertices) {
    const double u = grid.cells(axis, p[std::size_t(axis)], 0), n = std::round(u);
    if (u != n && std::abs(u - n) * grid.chunk[std::size_t(axis)] <= snap)
      p[std::size_t(axis)] = grid.plane(axis, std::int64_t(n), 0);
  }
  std::vector<double> u(m.vertices.size());
  for (std::size_t v = 0; v < u.size(); ++v) u[v] = grid.cells(axis, m.vertices[v][axis], 0);
  std::unordered_map<std::uint64_t, std::uint32_t> firstCut;  // edge (low, high) -> its first new vertex
  auto edgeCuts = [&](std::uint32_t a, std::uint32_t b, std::vector<std::uint32_t>& out) {
    // The new vertices on edge a -> b, in order from a to b.
    const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
    const double ul = u[lo], uh = u[hi];
    const double first = std::floor(std::min(ul, uh)) + 1, last = std::ceil(std::max(ul, uh)) - 1;
    if (first > last) return;
    const std::uint64_t key = (std::uint64_t(lo) << 32) | hi;
    auto it = firstCut.find(key);
    if (it == firstCut.end()) {
      const std::uint32_t start = std::uint32_t(m.vertices.size());
      for (double n = first; n <= last; ++n) {  // by increasing plane
        const double t = grid.plane(axis, std::int64_t(n), 0);
        const auto p = m.vertices[lo], q = m.vertices[hi];
        const double s = (t - p[axis]) / (q[axis] - p[axis]);
        std::array<double, 3> x{};
        for (int k = 0; k < 3; ++k) x[k] = p[k] + s * (q[k] - p[k]);
        x[axis] = t;  // exactly on the plane
        m.vertices.push_back(x);
        u.push_back(n);
      }
      it = firstCut.emplace(key, start).first;
    }
    const std::uint32_t count = std::uint32_t(last - first + 1);
    const bool increasing = u[a] < u[b];
    for (std::uint32_t i = 0; i < count; ++i) out.push_back(it->second + (increasing ? i : count - 1 - i));
  };

  std::vector<std::array<std::uint32_t, 3>> out;
  out.reserve(m.triangles.size());
  std::vector<std::uint32_t> polygon, piece;
  const std::vector<std::array<std::uint32_t, 3>> triangles = std::move(m.triangles);
  for (const auto& t : triangles) {
    const double lo = std::min({u[t[0]], u[t[1]], u[t[2]]}), hi = std::max({u[t[0]], u[t[1]], u[t[2]]});
    const double first = std::floor(lo) + 1, last = std::ceil(hi) - 1;
    if (first > last) {  // no plane strictly inside: the triangle stays whole
      out.push_back(t);
      continue;
    }
    polygon.clear();  // the triangle's boundary with its new vertices, in its own orientation
    for (int k = 0; k < 3; ++k) {
      polygon.push_back(t[k]);
      edgeCuts(t[k], t[(k + 1) % 3], polygon);
    }
    // Each slab [n, n + 1] between the triangle's planes holds the convex polygon of the
    // boundary vertices in it, in the same cyclic order: a fan keeps its orientation.
    for (double n = first - 1; n <= last; ++n) {
      piece.clear();
      bool inside = false;  // a vertex strictly inside the slab (not only on its planes)
      for (std::uint32_t v : polygon)
        if (u[v] >= n && u[v] <= n + 1) {
          piece.push_back(v);
          inside = inside || (u[v] > n && u[v] < n + 1);
        }
      if (piece.size() < 3) continue;
      if (!inside) {  // only vertices on the two planes: a piece of area unless all on one plane
        bool onLow = true, onHigh = true;
        for (std::uint32_t v : piece) onLow = onLow && u[v] == n, onHigh = onHigh && u[v] == n + 1;
        if (onLow || onHigh) continue;
      }
      for (std::size_t k = 1; k + 1 < piece.size(); ++k) out.push_back({piece[0], piece[k], piece[k + 1]});
    }
  }
  m.triangles = std::move(out);
}

}  // namespace

GridMesh cutOnGrid(const GridMesh& mesh, const OctreeGrid& grid, const std::array<double, 3>& snap) {
  GridMesh m = mesh;
  for (int axis = 0; axis < 3; ++axis) cutAlong(m, grid, axis, snap[std::size_t(axis)]);
  return m;
}

}  // namespace surftrack::refine
