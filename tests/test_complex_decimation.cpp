// Decimation of the complex of shared walls (LabelOptions::decimate; docs/theory.md §12,
// "Decimating the complex") against computations that do not use it, on random label images
// (fixed seeds) and on the cube patterns of tests/LabelPatterns.h blown up to blocks of voxels
// (large flat walls, where the collapses have room), with and without smoothing first:
//  - every triangle of a label has a reversed twin in another label at bit-identical points,
//    or lies on the background's or the outside's wall (its vertices' surfels touch it);
//  - every grid edge has one point in every label that has it, the point it had before the
//    decimation (a halfedge collapse moves no vertex);
//  - each label stays closed and oriented (a 2-manifold where it has no unsplit pinched edge),
//    with the Euler characteristic and components it had (counted by hand, ClosedManifold.h);
//  - no label intersects itself (CGAL, where it has no pinch) and no two triangles of the whole
//    complex meet other than in what they share (CGAL on the soup of the complex);
//  - each label within max error of its undecimated self both ways (CGAL's sampled distance);
//  - the figures: triangles before and after, volumes as the meshes give them;
//  - with a reduction alone on the blown-up patterns, the labels' triangles within 5 % of the
//    target (the total over the patterns).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "CaseSubset.h"
#include "CgalMeshChecks.h"
#include "ClosedManifold.h"
#include "LabelPatterns.h"
#include "Labels.h"
#include "MeshChecks.h"
#include "Refine.h"
#include "WallPoints.h"

namespace surftrack {
namespace {

using testing::caseChecked;
using P3 = std::array<double, 3>;
using testing::Bits;
using testing::bitsOf;
using testing::directed;
using testing::DirectedTriangle;
using testing::gridEdge;

/// The whole complex as a soup: the points by their bits, each wall triangle once (as the first
/// label that has it gives it), with its wall: the indices of the labels that have it (one for
/// a wall on the background or the outside).
void complexSoup(const std::vector<LabelSurface>& surfaces, checks::Points& points, checks::Triangles& triangles,
                 std::vector<std::vector<int>>* walls = nullptr) {
  std::map<Bits, std::uint32_t> index;
  std::map<std::array<std::uint32_t, 3>, std::size_t> seen;
  for (std::size_t l = 0; l < surfaces.size(); ++l)
    for (const auto& t : surfaces[l].surface.triangles) {
      std::array<std::uint32_t, 3> x;
      for (int k = 0; k < 3; ++k) {
        const P3& p = surfaces[l].surface.vertices[t[std::size_t(k)]];
        const auto [it, added] = index.try_emplace(bitsOf(p), std::uint32_t(points.size()));
        if (added) points.push_back(p);
        x[std::size_t(k)] = it->second;
      }
      std::array<std::uint32_t, 3> key = x;
      std::sort(key.begin(), key.end());
      const auto [it, added] = seen.try_emplace(key, triangles.size());
      if (added) {
        triangles.push_back(x);
        if (walls) walls->push_back({int(l)});
      } else if (walls) {
        (*walls)[it->second].push_back(int(l));
      }
    }
}

/// For each wall of the soup, its triangles and the fewest triangles collapses of its free
/// vertices can leave (each removes one vertex and two triangles): a vertex is free when all its
/// triangles are of one wall and chain into one closed disc around it.
std::map<std::vector<int>, std::array<std::size_t, 2>> wallFloors(const checks::Triangles& triangles,
                                                                   const std::vector<std::vector<int>>& walls) {
  std::map<std::uint32_t, std::vector<std::size_t>> at;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::uint32_t v : triangles[t]) at[v].push_back(t);
  std::map<std::vector<int>, std::array<std::size_t, 2>> out;
  for (std::size_t t = 0; t < triangles.size(); ++t) ++out[walls[t]][0];
  for (auto& [w, f] : out) f[1] = f[0];
  for (const auto& [v, ts] : at) {
    bool one = true;
    std::map<std::uint32_t, std::uint32_t> next;  // around v: each triangle's corner after v -> the one before
    for (std::size_t t : ts) {
      one = one && walls[t] == walls[ts[0]];
      const auto& x = triangles[t];
      const int k = int(std::find(x.begin(), x.end(), v) - x.begin());
      one = one && next.emplace(x[std::size_t((k + 1) % 3)], x[std::size_t((k + 2) % 3)]).second;
    }
    if (!one || next.size() < 3) continue;
    std::uint32_t a = next.begin()->first;
    std::size_t steps = 0;
    do {
      const auto it = next.find(a);
      if (it == next.end()) break;
      a = it->second;
      ++steps;
    } while (a != next.begin()->first && steps <= next.size());
    if (a == next.begin()->first && steps == next.size()) out[walls[ts[0]]][1] -= 2;
  }
  return out;
}

struct Stats {
  std::size_t images = 0, labels = 0, before = 0, after = 0, target = 0;
  std::size_t complexBefore = 0, complexAfter = 0, reachable = 0;  // the complex's triangles
};

/// One image decimated (after smoothing if `iterations`), checked against its undecimated
/// labels. priorityOf: 0 for the background and the outside.
template <class PriorityOf>
void checkDecimation(const std::vector<std::uint16_t>& data, Dims dims, bool withBackground, AdjacencyPair pair,
                     int iterations, const DecimateOptions& decimate, PriorityOf&& priorityOf, const std::string& what,
                     Stats& stats, const ImageGeometry& geometry = {}) {
  LabelOptions options;
  options.walls = LabelWalls::Shared;
  options.pair = pair;
  options.threads = 1;
  options.background = withBackground ? 0 : 65535;
  if (iterations) {
    SmoothOptions smooth;
    smooth.iterations = iterations;
    smooth.threads = 1;
    options.smooth = smooth;
  }
  const VolumeView view = VolumeView::of(data.data(), dims, geometry);
  const std::vector<LabelSurface> before = extractLabels(view, options);
  options.decimate = decimate;
  const std::vector<LabelSurface> after = extractLabels(view, options);
  ASSERT_EQ(before.size(), after.size()) << what;
  ++stats.images;

  // One point per grid edge, in every label, as before.
  std::map<std::array<int, 4>, Bits> pointOf;
  for (const LabelSurface& l : before)
    for (std::size_t v = 0; v < l.surface.vertices.size(); ++v)
      pointOf.emplace(gridEdge(l.surface.surfels[v]), bitsOf(l.surface.vertices[v]));
  for (const LabelSurface& l : after)
    for (std::size_t v = 0; v < l.surface.vertices.size(); ++v) {
      const auto at = pointOf.find(gridEdge(l.surface.surfels[v]));
      ASSERT_TRUE(at != pointOf.end()) << what << ": a vertex on a grid edge no label had";
      EXPECT_EQ(at->second, bitsOf(l.surface.vertices[v])) << what << ": a vertex moved or not shared";
    }

  // Twins at bit-identical points, or a wall of the background or the outside.
  std::map<DirectedTriangle, std::vector<int>> all;
  std::map<DirectedTriangle, std::array<Surfel, 3>> surfelsOf;
  for (std::size_t l = 0; l < after.size(); ++l) {
    const Surface& s = after[l].surface;
    for (const auto& t : s.triangles) {
      const DirectedTriangle d = directed(bitsOf(s.vertices[t[0]]), bitsOf(s.vertices[t[1]]), bitsOf(s.vertices[t[2]]));
      all[d].push_back(int(l));
      surfelsOf[d] = {s.surfels[t[0]], s.surfels[t[1]], s.surfels[t[2]]};
    }
  }
  for (const auto& [t, owners] : all) {
    ASSERT_EQ(owners.size(), 1u) << what << ": a triangle twice in one orientation";
    const auto twin = all.find(directed(t[0], t[2], t[1]));
    if (twin != all.end()) {
      EXPECT_NE(twin->second[0], owners[0]) << what << ": a label's triangle and its reverse";
    } else {
      for (const Surfel& s : surfelsOf[t])
        EXPECT_TRUE(priorityOf(s.inside()) == 0 || priorityOf(s.outside()) == 0)
            << what << ": a wall without its twin, not on the background";
    }
  }

  for (std::size_t l = 0; l < after.size(); ++l) {
    const Surface &s0 = before[l].surface, &s = after[l].surface;
    const std::string at = what + " label " + after[l].label.text();
    ASSERT_TRUE(after[l].decimate.has_value()) << at;
    const DecimateReport& r = *after[l].decimate;
    EXPECT_EQ(r.trianglesBefore, s0.triangles.size()) << at;
    EXPECT_EQ(r.trianglesAfter, s.triangles.size()) << at;
    EXPECT_LE(s.triangles.size(), s0.triangles.size()) << at;
    EXPECT_EQ(after[l].pinchCopies, before[l].pinchCopies) << at;
    TriangleMesh mesh;
    mesh.triangles = s.triangles;
    EXPECT_NEAR(testing::signedVolume(mesh, s.vertices), r.volumeAfter, 1e-9 * std::max(1.0, std::abs(r.volumeAfter))) << at;
    mesh.triangles = s0.triangles;
    EXPECT_NEAR(testing::signedVolume(mesh, s0.vertices), r.volumeBefore, 1e-9 * std::max(1.0, std::abs(r.volumeBefore))) << at;
    // Closed, oriented; the topology it had, counted by hand.
    const checks::Topology t0 = checks::topologyOf(s0.vertices.size(), s0.triangles);
    const checks::Topology t1 = checks::topologyOf(s.vertices.size(), s.triangles);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : s.triangles)
      for (int j = 0; j < 3; ++j) ++uses[{t[std::size_t(j)], t[std::size_t((j + 1) % 3)]}];
    for (const auto& [e, n] : uses) {
      const auto back = uses.find({e.second, e.first});
      ASSERT_TRUE(back != uses.end() && back->second == n) << at << ": not closed";
    }
    EXPECT_EQ(t1.euler, t0.euler) << at;
    EXPECT_EQ(t1.components, t0.components) << at;
    EXPECT_EQ(s.components.size(), s0.components.size()) << at;
    if (after[l].unsplitEdges == 0) {
      EXPECT_TRUE(t1.manifoldVertices) << at << ": " << t1.problem;
    }
    if (after[l].unsplitEdges == 0 && after[l].pinchCopies == 0) {
      EXPECT_EQ(checks::selfIntersections(s.vertices, s.triangles), 0u) << at;
    }
    if (decimate.maxError) {
      const double e = *decimate.maxError * (1 + 1e-9);
      EXPECT_LE(checks::sampledDistance(s.vertices, s.triangles, s0.vertices, s0.triangles), e) << at;
      EXPECT_LE(checks::sampledDistance(s0.vertices, s0.triangles, s.vertices, s.triangles), e) << at;
    }
    ++stats.labels;
    stats.before += r.trianglesBefore;
    stats.after += r.trianglesAfter;
    stats.target += r.targetTriangles;
  }
  // No two triangles of the complex meet but in what they share.
  checks::Points points;
  checks::Triangles triangles;
  complexSoup(after, points, triangles);
  EXPECT_EQ(checks::soupIntersections(points, triangles), 0u) << what << ": walls meet";
  // The triangles the reduction could reach: each wall's target, or its floor when higher.
  checks::Points points0;
  checks::Triangles triangles0;
  std::vector<std::vector<int>> walls0;
  complexSoup(before, points0, triangles0, &walls0);
  stats.complexBefore += triangles0.size();
  stats.complexAfter += triangles.size();
  for (const auto& [w, f] : wallFloors(triangles0, walls0)) {
    const std::size_t target = decimate.reduction ? std::size_t(std::llround((1 - *decimate.reduction) * double(f[0]))) : 0;
    stats.reachable += std::max(target, f[1]);
  }
}

/// The priority of each voxel as the engine ranks them: 0 for the background and the outside,
/// then 1 + the label's rank.
auto priorities(const std::vector<std::uint16_t>& data, Dims dims, bool withBackground) {
  std::vector<std::uint16_t> values(data);
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  if (withBackground && values[0] == 0) values.erase(values.begin());
  return [data, values, dims, withBackground](Voxel v) -> int {
    if (!dims.contains(v)) return 0;
    const std::uint16_t x = data[std::size_t(v.x) + std::size_t(dims.nx) * (std::size_t(v.y) + std::size_t(dims.ny) * std::size_t(v.z))];
    if (withBackground && x == 0) return 0;
    return int(std::lower_bound(values.begin(), values.end(), x) - values.begin()) + 1;
  };
}

TEST(ComplexDecimation, RandomLabelImages) {
  std::mt19937_64 rng(5151);
  Stats stats;
  for (int image = 0; image < 1000; ++image) {
    std::uniform_int_distribution<int> side(2, 5);
    const Dims dims{side(rng), side(rng), side(rng)};
    const int count = std::uniform_int_distribution<int>(2, image % 4 == 0 ? 40 : 6)(rng);
    const bool withBackground = image % 2 == 0;
    std::vector<std::uint16_t> data;
    do data = testing::randomLabels(rng, dims, count, withBackground);  // (a label at least)
    while (std::all_of(data.begin(), data.end(), [&](std::uint16_t x) { return withBackground && x == 0; }));
    if (!caseChecked(std::uint64_t(image))) continue;
    DecimateOptions decimate;
    if (image % 3 != 1) decimate.maxError = 0.3 + 0.1 * (image % 4);
    if (image % 3 != 0) decimate.reduction = 0.5 + 0.1 * (image % 4);
    const AdjacencyPair pair = image % 3 == 2 ? AdjacencyPair::k6_26 : AdjacencyPair::k26_6;
    checkDecimation(data, dims, withBackground, pair, image % 2 ? 0 : 1 + image % 20, decimate,
                    priorities(data, dims, withBackground), "image " + std::to_string(image), stats);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(stats.images, testing::subsetMinimum(1000));
  EXPECT_LT(stats.after, stats.before);
  std::cout << "[ study ] " << stats.images << " random images, " << stats.labels << " labels: triangles "
            << stats.before << " -> " << stats.after << "\n";
}

TEST(ComplexDecimation, BlownUpCubePatterns) {
  // Patterns of one digital 3-cube (tests/LabelPatterns.h), each corner a block of k^3 voxels:
  // flat walls meeting on junction lines and pinches, the outside the background.
  const std::vector<testing::Ranks> patterns = testing::allPriorityPatterns();
  const int k = 4;
  const Dims dims{2 * k, 2 * k, 2 * k};
  Stats reduced, bounded;
  std::size_t checked = 0;
  for (std::size_t c = 7; c < patterns.size(); c += 39989) {
    if (!caseChecked(c / 39989)) continue;
    ++checked;
    std::vector<std::uint16_t> data(std::size_t(dims.nx) * std::size_t(dims.ny) * std::size_t(dims.nz));
    for (int z = 0, i = 0; z < dims.nz; ++z)
      for (int y = 0; y < dims.ny; ++y)
        for (int x = 0; x < dims.nx; ++x, ++i)
          data[std::size_t(i)] = std::uint16_t(patterns[c][std::size_t((x / k) + 2 * (y / k) + 4 * (z / k))] + 1);
    const AdjacencyPair pair = c % 2 ? AdjacencyPair::k6_26 : AdjacencyPair::k26_6;
    DecimateOptions a;
    a.reduction = 0.8;
    checkDecimation(data, dims, false, pair, 0, a, priorities(data, dims, false), "pattern " + std::to_string(c) + " reduce",
                    reduced);
    if (::testing::Test::HasFatalFailure()) return;
    DecimateOptions b;
    b.maxError = 0.3;
    // Half of them in a mirrored frame (the axes x and z swapped, as the binding gives a numpy
    // array's): the walls in physical space, the normals turned.
    ImageGeometry g;
    if (c % 2) g.direction = {{{0, 0, 1}, {0, 1, 0}, {1, 0, 0}}};
    checkDecimation(data, dims, false, pair, c % 3 ? 10 : 0, b, priorities(data, dims, false),
                    "pattern " + std::to_string(c) + " max error", bounded, g);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(checked, testing::subsetMinimum(14));
  std::cout << "[ study ] " << checked << " blown-up cube patterns, reduce 0.8: triangles " << reduced.before << " -> "
            << reduced.after << " (labels' target " << reduced.target << "); the complex " << reduced.complexBefore
            << " -> " << reduced.complexAfter << " (" << reduced.reachable
            << " if each wall reached its target or lost every free vertex, the junction lines kept); max error 0.3: "
            << bounded.before << " -> " << bounded.after << "\n";
  // The target of the labels' triangles within 5 %: the walls decimated, then the junction lines
  // and the walls again (docs/theory.md §12, "Decimating the complex").
  EXPECT_LE(double(reduced.after), 1.05 * double(reduced.target));
  EXPECT_GE(double(reduced.after), 0.95 * double(reduced.target));
}

TEST(ComplexDecimation, LabelsOnTheBackgroundReachTheTarget) {
  // Labels that touch only the background (two balls and a torus): each is one closed wall with
  // no junction, so the reduction is limited by the guards alone, as decimate()'s on one surface.
  const int n = 30;
  std::vector<std::uint16_t> data(std::size_t(n) * n * n, 0);
  for (int z = 0, i = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, ++i) {
        if (std::hypot(x - 7.3, y - 7.6, z - 7.2) <= 5.4) data[std::size_t(i)] = 3;
        if (std::hypot(x - 21.4, y - 8.1, z - 20.3) <= 6.7) data[std::size_t(i)] = 9;
        if (std::hypot(std::hypot(x - 15.2, y - 21.1) - 6.3, z - 9.4) <= 2.6) data[std::size_t(i)] = 5;
      }
  const auto priorityOf = priorities(data, {n, n, n}, true);
  Stats stats;
  DecimateOptions d;
  d.reduction = 0.9;
  checkDecimation(data, {n, n, n}, true, AdjacencyPair::k26_6, 0, d, priorityOf, "balls and torus", stats);
  std::cout << "[ study ] three labels on the background, reduce 0.9: triangles " << stats.before << " -> "
            << stats.after << " (target " << stats.target << ")\n";
  EXPECT_LE(double(stats.after), 1.05 * double(stats.target));
}

TEST(ComplexDecimation, Refusals) {
  const std::vector<std::uint8_t> data{1, 2, 0, 1, 2, 2, 0, 1};
  const VolumeView view = VolumeView::of(data.data(), {2, 2, 2});
  LabelOptions options;
  options.decimate = DecimateOptions{};
  options.decimate->maxError = 0.5;
  EXPECT_THROW(extractLabels(view, options), InvalidInput);  // independent walls
  options.walls = LabelWalls::Shared;
  options.decimate->maxError.reset();  // neither a max error nor a reduction
  EXPECT_THROW(extractLabels(view, options), InvalidInput);
  options.decimate->reduction = 1.5;
  EXPECT_THROW(extractLabels(view, options), InvalidInput);
  options.decimate->reduction = 0.5;
  options.decimate->maxError = -1;
  EXPECT_THROW(extractLabels(view, options), InvalidInput);
  options.decimate->maxError = 0.5;
  EXPECT_EQ(extractLabels(view, options).size(), 2u);
}

}  // namespace
}  // namespace surftrack
