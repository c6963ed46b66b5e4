// Levels of detail on an octree grid (refine/LevelsOfDetail.h, docs/theory.md section 10,
// "Levels of detail on a grid"), checked on random images, raw and smoothed surfaces, with a
// fine grid (planes every 2 or 3 voxels) and the writer's own choice (gridFor):
//  - every level a closed oriented manifold (the same check as the converter's) with the
//    surface's Euler characteristic and components, embedded (CGAL, exact predicates);
//  - level 0 the same surface: its area and enclosed volume;
//  - every triangle of level k inside one closed cell of level max(k - 1, 0), by brute force;
//  - no crack: on every plane of level k - 1's grid, the edges where the surface crosses from
//    one side to the other are the same in levels 0 .. k (as point pairs, exactly).
#include <gtest/gtest.h>
#include <surftrack/Extract.h>
#include <surftrack/Refine.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "CaseSubset.h"
#include "CgalMeshChecks.h"
#include "Image.h"
#include "LevelsOfDetail.h"
#include "SurfaceMesh.h"

namespace surftrack {
namespace {

namespace ck = checks;
using refine::GridMesh;

Surface extractAll(const DenseImage<std::uint8_t>& image) {
  ExtractOptions o;
  o.selection = Selection::label(1);
  o.seed = SeedRule::all();
  o.threads = 1;
  return extract(VolumeView::of(image.data().data(), image.dims(), image.geometry()), o);
}

/// (Euler characteristic, components), counted here.
std::pair<long long, std::size_t> topologyOf(const GridMesh& m) {
  std::vector<std::size_t> parent(m.vertices.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
      parent[find(a)] = find(b);
    }
  std::set<std::size_t> roots;
  for (std::size_t v = 0; v < parent.size(); ++v) roots.insert(find(v));
  return {(long long)m.vertices.size() - (long long)edges.size() + (long long)m.triangles.size(), roots.size()};
}

double areaOf(const GridMesh& m) {
  double a = 0;
  for (const auto& t : m.triangles) {
    const auto &p = m.vertices[t[0]], &q = m.vertices[t[1]], &r = m.vertices[t[2]];
    const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    a += std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / 2;
  }
  return a;
}

double volumeOf(const GridMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) {
    const auto &p = m.vertices[t[0]], &q = m.vertices[t[1]], &r = m.vertices[t[2]];
    v += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) + p[2] * (q[0] * r[1] - q[1] * r[0])) / 6;
  }
  return v;
}

/// Whether every triangle lies in one closed cell of level g: along each axis its coordinates,
/// in cells, within [n, n + 1] for one integer n.
bool cutOn(const GridMesh& m, const OctreeGrid& grid, int g) {
  for (const auto& t : m.triangles)
    for (int a = 0; a < 3; ++a) {
      double lo = 1e300, hi = -1e300;
      for (std::uint32_t v : t) {
        const double u = (m.vertices[v][a] - grid.origin[a]) / (grid.chunk[a] * std::ldexp(1.0, g));
        lo = std::min(lo, u), hi = std::max(hi, u);
      }
      if (std::floor(lo) + 1 < hi) return false;
    }
  return true;
}

using Key = std::tuple<int, double, std::array<double, 3>, std::array<double, 3>>;  // axis, plane, ends

/// The crossing edges on the planes of level g: edges in a plane whose two triangles lie on
/// opposite sides of it (a triangle's side: its third vertex's), keyed by their points.
std::set<Key> crossings(const GridMesh& m, const OctreeGrid& grid, int g) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> opposite;  // edge -> third vertices
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      opposite[{std::min(a, b), std::max(a, b)}].push_back(t[(k + 2) % 3]);
    }
  std::set<Key> out;
  for (const auto& [e, thirds] : opposite) {
    const auto &p = m.vertices[e.first], &q = m.vertices[e.second];
    for (int a = 0; a < 3; ++a) {
      if (p[a] != q[a] || !grid.onPlane(a, p[a], g) || thirds.size() != 2) continue;
      const double s0 = m.vertices[thirds[0]][a] - p[a], s1 = m.vertices[thirds[1]][a] - p[a];
      if ((s0 > 0) != (s1 > 0) || (s0 < 0) != (s1 < 0)) out.insert({a, p[a], std::min(p, q), std::max(p, q)});
    }
  }
  return out;
}

void checkLevels(const Surface& s, const OctreeGrid& grid, const std::string& what) {
  const GridMesh mesh{s.vertices, s.triangles};
  const auto [euler, components] = topologyOf(mesh);
  const std::vector<GridMesh> levels = refine::levelsOfDetail(mesh, grid, {});
  ASSERT_EQ(levels.size(), std::size_t(grid.lods)) << what;
  for (int k = 0; k < grid.lods; ++k) {
    const GridMesh& l = levels[std::size_t(k)];
    const std::string at = what + " level " + std::to_string(k);
    EXPECT_NO_THROW(requireClosedOrientedManifold(l.vertices.size(), l.triangles)) << at;
    EXPECT_EQ(topologyOf(l), std::make_pair(euler, components)) << at;
    EXPECT_EQ(ck::selfIntersections(l.vertices, l.triangles), 0u) << at;
    EXPECT_TRUE(cutOn(l, grid, std::max(k - 1, 0))) << at;
    EXPECT_GT(volumeOf(l), 0) << at;
    if (k > 0)  // levels 0 .. k meet on the same curves on level k - 1's planes
      for (int j = 0; j < k; ++j)
        EXPECT_EQ(crossings(levels[std::size_t(j)], grid, k - 1), crossings(l, grid, k - 1)) << at << " vs " << j;
  }
  // The same surface, but for the vertices snapped onto planes (by at most a 16-bit step of a
  // cell, GridCut.h): within that layer.
  const double snap = 3 * std::max({grid.chunk[0], grid.chunk[1], grid.chunk[2]}) / 65535;
  EXPECT_NEAR(areaOf(levels[0]), areaOf(mesh), 1e-9 * areaOf(mesh) + snap * std::sqrt(areaOf(mesh))) << what;
  EXPECT_NEAR(volumeOf(levels[0]), volumeOf(mesh), snap * areaOf(mesh)) << what;
}

TEST(LevelsOfDetail, RandomImagesRawAndSmoothed) {
  std::mt19937_64 rng(20261203);
  for (int trial = 0; trial < 10; ++trial) {
    std::uniform_int_distribution<int> side(5, 9);
    const Dims dims{side(rng), side(rng), side(rng)};
    const double density = std::uniform_real_distribution<double>(0.3, 0.7)(rng);
    DenseImage<std::uint8_t> image(dims);
    for (auto& v : image.data()) v = std::uniform_real_distribution<double>(0, 1)(rng) < density;
    if (std::count(image.data().begin(), image.data().end(), 1) == 0) continue;
    if (!surftrack::testing::caseChecked(trial)) continue;  // after the draws: the same images
    Surface s = extractAll(image);
    for (int smoothed = 0; smoothed < 2; ++smoothed) {
      if (smoothed) smooth(s, {});
      const std::string what = "trial " + std::to_string(trial) + (smoothed ? " smoothed" : " raw");
      OctreeGrid fine;  // planes every 2 or 3 voxels, a quarter voxel off the lattice
      fine.lods = 3;
      for (int a = 0; a < 3; ++a) fine.origin[a] = -1.25, fine.chunk[a] = 2 + trial % 2;
      checkLevels(s, fine, what + " fine grid");
      checkLevels(s, refine::gridFor(s.vertices, 3), what + " gridFor");
      if (HasFailure()) return;
    }
  }
}

TEST(LevelsOfDetail, GridForHoldsTheMeshInItsTopCell) {
  const std::vector<std::array<double, 3>> v = {{-3.5, 0, 100.5}, {40, 2, 101}, {7, 9.5, 130}};
  for (int lods = 1; lods <= 5; ++lods) {
    const OctreeGrid g = refine::gridFor(v, lods);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(double(float(g.origin[a])), g.origin[a]);
      EXPECT_EQ(double(float(g.chunk[a])), g.chunk[a]);
      EXPECT_GE(g.chunk[a], 8);
      for (const auto& p : v) {
        const double u = g.cells(a, p[a], lods - 1);
        EXPECT_GT(u, 0) << lods;
        EXPECT_LT(u, 1) << lods;
        EXPECT_NE(std::fmod(p[a] - g.origin[a], 0.5), 0) << "a vertex on the lattice lies on a plane";
      }
    }
  }
}

}  // namespace
}  // namespace surftrack
