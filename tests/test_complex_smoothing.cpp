// Smoothing of the complex of shared walls (LabelOptions::smooth; docs/theory.md §12, "Smoothing
// the complex") against computations that do not use it, before and after smoothing:
//  - random label images (2 to 40 labels, noise or blobs, fixed seeds) and single cubes of
//    every kind of priority pattern (a subset of tests/test_shared_walls.cpp's 545,835): every
//    triangle of a label has a reversed twin in another label at bit-identical coordinates (or
//    lies over the domain's border when the background is absent), as many as before; every
//    grid edge has one point in every label that has it; every vertex lies on its surfel's
//    segment at t in [epsilon, 1 - epsilon]; each label keeps its triangles, stays closed and
//    oriented, with the Euler characteristic and components it had (counted by hand), and
//    without self-intersection (CGAL) where it is a 2-manifold with no pinch copies; voxel
//    centres lie inside their own label only and random points inside at most one label
//    (winding numbers);
//  - the binary sphere: the RMS distance to the analytic sphere falls at least 3x and the
//    enclosed volume stays within 1 % of the ball's, and the complex's smoothing is the single
//    surface's smoothing (smooth()) there, the complex being that one surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <map>
#include <numbers>
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

struct Counts {
  std::size_t twins = 0, borders = 0;
};

/// Twins at bit-identical points: each triangle of a label reversed in exactly one other label
/// or, without it, over the domain's border when the background is absent.
void checkTwins(const std::vector<LabelSurface>& surfaces, Dims dims, bool withBackground,
                const std::map<Bits, std::array<int, 4>>& edgeAt, Counts& counts, const std::string& what) {
  std::map<DirectedTriangle, std::vector<int>> all;
  for (std::size_t l = 0; l < surfaces.size(); ++l) {
    const Surface& s = surfaces[l].surface;
    for (const auto& t : s.triangles)
      all[directed(bitsOf(s.vertices[t[0]]), bitsOf(s.vertices[t[1]]), bitsOf(s.vertices[t[2]]))].push_back(int(l));
  }
  for (const auto& [t, owners] : all) {
    EXPECT_EQ(owners.size(), 1u) << what << ": a triangle twice in one orientation";
    const auto twin = all.find(directed(t[0], t[2], t[1]));
    if (twin != all.end()) {
      EXPECT_NE(twin->second[0], owners[0]) << what << ": a label's triangle and its reverse";
      ++counts.twins;
    } else {
      ++counts.borders;
      // Without the background only the outside is priority 0: each vertex of such a wall is
      // on a grid edge leaving the domain.
      if (!withBackground)
        for (const Bits& p : t) {
          const std::array<int, 4> e = edgeAt.at(p);
          Voxel hi{e[0], e[1], e[2]};
          hi[e[3]] += 1;
          EXPECT_TRUE(!dims.contains(Voxel{e[0], e[1], e[2]}) || !dims.contains(hi))
              << what << ": a wall without its twin inside the domain";
        }
    }
  }
}

/// Checks the labels of one image (identity geometry) and returns its twin counts.
/// priorityOf: 0 background or outside, 1 + label index.
template <class PriorityOf>
Counts checkComplex(const std::vector<LabelSurface>& surfaces, Dims dims, bool withBackground, PriorityOf&& priorityOf,
                    double epsilon, std::mt19937_64& rng, const std::string& what) {
  Counts counts;
  // One point per grid edge in every label; on the segment, at t in [epsilon, 1 - epsilon].
  std::map<std::array<int, 4>, Bits> pointOf;
  for (const LabelSurface& l : surfaces) {
    const Surface& s = l.surface;
    for (std::size_t v = 0; v < s.vertices.size(); ++v) {
      const auto [it, added] = pointOf.try_emplace(gridEdge(s.surfels[v]), bitsOf(s.vertices[v]));
      EXPECT_EQ(it->second, bitsOf(s.vertices[v])) << what << ": a grid edge at two points";
      const Voxel c = s.surfels[v].inside(), d = s.surfels[v].outside();
      const int axis = gridEdge(s.surfels[v])[3];
      for (int a = 0; a < 3; ++a)
        if (a != axis) EXPECT_EQ(s.vertices[v][std::size_t(a)], double(c[a])) << what << ": off the segment's line";
      const double t = (s.vertices[v][std::size_t(axis)] - c[axis]) / double(d[axis] - c[axis]);
      EXPECT_GE(t, epsilon - 1e-12) << what;
      EXPECT_LE(t, 1 - epsilon + 1e-12) << what;
    }
  }
  std::map<Bits, std::array<int, 4>> edgeAt;
  for (const auto& [e, p] : pointOf) {
    const auto [it, added] = edgeAt.emplace(p, e);
    EXPECT_TRUE(added) << what << ": two grid edges at one point";
  }
  checkTwins(surfaces, dims, withBackground, edgeAt, counts, what);
  // Inside exactly one label or the background, by winding numbers.
  std::vector<TriangleMesh> meshes(surfaces.size());
  for (std::size_t l = 0; l < surfaces.size(); ++l) meshes[l].triangles = surfaces[l].surface.triangles;
  auto check = [&](const testing::Point& q, int expected) {
    int inside = 0, sum = 0;
    for (std::size_t l = 0; l < surfaces.size(); ++l) {
      const double w = testing::windingNumber(meshes[l], surfaces[l].surface.vertices, q);
      ASSERT_NEAR(w, std::round(w), 1e-6) << what;
      ASSERT_TRUE(std::round(w) == 0 || std::round(w) == 1) << what << ": winding " << w;
      if (std::round(w) == 1) inside = int(l) + 1;
      sum += int(std::round(w));
    }
    ASSERT_LE(sum, 1) << what << ": a point inside two labels";
    if (expected >= 0) ASSERT_EQ(inside, expected) << what;
  };
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x) check({double(x), double(y), double(z)}, priorityOf(Voxel{x, y, z}));
  std::uniform_real_distribution<double> unit(0, 1);
  for (int k = 0; k < 12; ++k)
    check({-0.9 + unit(rng) * (dims.nx + 0.8), -0.9 + unit(rng) * (dims.ny + 0.8), -0.9 + unit(rng) * (dims.nz + 0.8)}, -1);
  return counts;
}

/// The labels of one image, before and after smoothing, against each other and the checks above.
void checkImage(const std::vector<std::uint16_t>& data, Dims dims, bool withBackground, AdjacencyPair pair,
                int iterations, std::mt19937_64& rng, const std::string& what, std::size_t& labelsSeen) {
  LabelOptions options;
  options.walls = LabelWalls::Shared;
  options.pair = pair;
  options.threads = 1;
  options.background = withBackground ? 0 : 65535;  // absent: only the outside is background
  const VolumeView view = VolumeView::of(data.data(), dims);
  const std::vector<LabelSurface> before = extractLabels(view, options);
  SmoothOptions smooth;
  smooth.iterations = iterations;
  smooth.threads = 1;
  options.smooth = smooth;
  const std::vector<LabelSurface> after = extractLabels(view, options);
  ASSERT_EQ(before.size(), after.size()) << what;
  std::vector<std::uint16_t> values(data);
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  if (withBackground && values[0] == 0) values.erase(values.begin());
  auto priorityOf = [&](Voxel v) -> int {
    if (!dims.contains(v)) return 0;
    const std::uint16_t x = data[std::size_t(v.x) + std::size_t(dims.nx) * (std::size_t(v.y) + std::size_t(dims.ny) * std::size_t(v.z))];
    if (withBackground && x == 0) return 0;
    return int(std::lower_bound(values.begin(), values.end(), x) - values.begin()) + 1;
  };
  // No wall lies in a face plane of its cube (docs/theory.md §12, "Smoothing the complex": the
  // two cubes of a face then see the same trace segments on it): in doubled coordinates the
  // face planes are the even ones, where a vertex's own axis is odd.
  for (const LabelSurface& l : before)
    for (const auto& t : l.surface.triangles)
      for (int axis = 0; axis < 3; ++axis) {
        std::array<long long, 3> k;
        for (int j = 0; j < 3; ++j) k[std::size_t(j)] = std::llround(2 * l.surface.vertices[t[std::size_t(j)]][std::size_t(axis)]);
        ASSERT_FALSE(k[0] == k[1] && k[1] == k[2] && k[0] % 2 == 0) << what << ": a wall in a cube's face plane";
      }
  const Counts a = checkComplex(before, dims, withBackground, priorityOf, 0.5, rng, what + " before");
  const Counts b = checkComplex(after, dims, withBackground, priorityOf, smooth.epsilon, rng, what + " after");
  EXPECT_EQ(a.twins, b.twins) << what;
  EXPECT_EQ(a.borders, b.borders) << what;
  for (std::size_t l = 0; l < after.size(); ++l) {
    const Surface &s0 = before[l].surface, &s = after[l].surface;
    ASSERT_EQ(s.triangles, s0.triangles) << what;
    ASSERT_EQ(s.surfels.size(), s0.surfels.size()) << what;
    ASSERT_TRUE(after[l].smooth.has_value()) << what;
    EXPECT_EQ(after[l].smooth->unguardedCubes, 0u) << what << ": a cube of the complex not embedded at the midpoints";
    // Closed, oriented; the same Euler characteristic and components, counted by hand.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : s.triangles)
      for (int j = 0; j < 3; ++j) ++uses[{t[std::size_t(j)], t[std::size_t((j + 1) % 3)]}];
    for (const auto& [e, n] : uses) {
      const auto back = uses.find({e.second, e.first});
      ASSERT_TRUE(back != uses.end() && back->second == n) << what << ": not closed";
    }
    const checks::Topology t0 = checks::topologyOf(s0.vertices.size(), s0.triangles);
    const checks::Topology t1 = checks::topologyOf(s.vertices.size(), s.triangles);
    EXPECT_EQ(t1.euler, t0.euler) << what;
    EXPECT_EQ(t1.components, t0.components) << what;
    EXPECT_EQ(s.components.size(), s0.components.size()) << what;
    if (after[l].unsplitEdges == 0) EXPECT_TRUE(t1.manifoldVertices) << what << ": " << t1.problem;
    // The moves stay on the segments: at most a voxel.
    double moved = 0;
    for (std::size_t v = 0; v < s.vertices.size(); ++v)
      moved = std::max(moved, std::sqrt(std::pow(s.vertices[v][0] - s0.vertices[v][0], 2) +
                                        std::pow(s.vertices[v][1] - s0.vertices[v][1], 2) +
                                        std::pow(s.vertices[v][2] - s0.vertices[v][2], 2)));
    EXPECT_EQ(moved, after[l].smooth->maxDisplacement) << what;
    EXPECT_LT(moved, 0.5) << what;
    // No self-intersection (CGAL) where the label is a 2-manifold without two vertices at a point.
    if (after[l].unsplitEdges == 0 && after[l].pinchCopies == 0)
      EXPECT_EQ(checks::selfIntersections(s.vertices, s.triangles), 0u) << what << " label " << l;
    ++labelsSeen;
  }
}

TEST(ComplexSmoothing, RandomLabelImages) {
  std::mt19937_64 rng(4242);
  std::size_t images = 0, labels = 0;
  for (int image = 0; image < 300; ++image) {
    std::uniform_int_distribution<int> side(2, 5);
    const Dims dims{side(rng), side(rng), side(rng)};
    const int count = std::uniform_int_distribution<int>(2, 40)(rng);
    const bool withBackground = image % 2 == 0;
    const std::vector<std::uint16_t> data = testing::randomLabels(rng, dims, count, withBackground);
    if (!caseChecked(std::uint64_t(image))) continue;
    ++images;
    const AdjacencyPair pair = image % 3 == 2 ? AdjacencyPair::k6_26 : AdjacencyPair::k26_6;
    checkImage(data, dims, withBackground, pair, 1 + image % 20, rng, "image " + std::to_string(image), labels);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(images, testing::subsetMinimum(300));
  std::cout << "[ study ] " << images << " random images, " << labels << " labels smoothed\n";
}

TEST(ComplexSmoothing, PatternsOfOneCube) {
  // One pattern in 389 of tests/test_shared_walls.cpp's (every kind of cube, spread over them),
  // as a 2 x 2 x 2 image of labels rank + 1 (the outside is the background).
  const std::vector<testing::Ranks> patterns = testing::allPriorityPatterns();
  std::mt19937_64 rng(7);
  std::size_t checked = 0, labels = 0;
  for (std::size_t c = 0; c < patterns.size(); c += 389) {
    if (!caseChecked(c / 389)) continue;
    std::vector<std::uint16_t> data(8);
    for (int i = 0; i < 8; ++i) data[std::size_t(i)] = std::uint16_t(patterns[c][std::size_t(i)] + 1);
    ++checked;
    checkImage(data, {2, 2, 2}, false, c % 2 ? AdjacencyPair::k6_26 : AdjacencyPair::k26_6, 10, rng,
               "pattern " + std::to_string(c), labels);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(checked, testing::subsetMinimum(1400));
  std::cout << "[ study ] " << checked << " cube patterns, " << labels << " labels smoothed\n";
}

TEST(ComplexSmoothing, BinarySphere) {
  const int n = 28;
  const double r = 11.3, c = 13.6;  // off the grid's symmetries
  std::vector<std::uint8_t> data(std::size_t(n) * n * n);
  for (int z = 0, i = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, ++i) data[std::size_t(i)] = std::hypot(x - c, y - c, z - c) <= r;
  LabelOptions options;
  options.walls = LabelWalls::Shared;
  const VolumeView view = VolumeView::of(data.data(), {n, n, n});
  LabelSurface plain = extractLabels(view, options).at(0);
  SmoothOptions fifty;  // the labels' default (kLabelSmoothIterations): lambda 0.7, mu -0.73
  fifty.iterations = kLabelSmoothIterations;
  options.smooth = fifty;
  const LabelSurface smoothed = extractLabels(view, options).at(0);
  auto rms = [&](const Surface& s) {
    double sum = 0;
    for (const auto& p : s.vertices) sum += std::pow(std::hypot(p[0] - c, p[1] - c, p[2] - c) - r, 2);
    return std::sqrt(sum / double(s.vertices.size()));
  };
  TriangleMesh mesh;
  mesh.triangles = smoothed.surface.triangles;
  const double ball = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double volume = testing::signedVolume(mesh, smoothed.surface.vertices);
  const double before = rms(plain.surface), after = rms(smoothed.surface);
  std::cout << "[ study ] sphere r = " << r << ": RMS distance " << before << " -> " << after << " ("
            << before / after << "x), volume " << volume << " against " << ball << " ("
            << 100 * (volume / ball - 1) << " %)\n";
  EXPECT_GE(before / after, 3.0);
  EXPECT_LT(std::abs(volume / ball - 1), 0.01);
  EXPECT_NEAR(smoothed.smooth->volumeAfter, volume, 1e-9 * volume);
  // One label on the background: the complex is that label's surface, and its smoothing
  // smooth()'s (up to the order of the neighbours' sums).
  smooth(plain.surface, fifty);
  ASSERT_EQ(plain.surface.vertices.size(), smoothed.surface.vertices.size());
  double gap = 0;
  for (std::size_t v = 0; v < plain.surface.vertices.size(); ++v)
    for (int a = 0; a < 3; ++a) gap = std::max(gap, std::abs(plain.surface.vertices[v][std::size_t(a)] - smoothed.surface.vertices[v][std::size_t(a)]));
  EXPECT_LT(gap, 1e-9);
}

TEST(ComplexSmoothing, MirroredAnisotropicGeometry) {
  // Smoothing in physical space under a mirrored, anisotropic frame: one point per grid edge in
  // every label, each on its segment (through the inverse geometry), normals still outwards.
  std::mt19937_64 rng(99);
  ImageGeometry g;
  g.spacing = {0.8, 1.3, 1.1};
  g.origin = {2.0, -1.0, 0.5};
  g.direction = {{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}}};
  ASSERT_LT(g.handedness(), 0);
  for (int image = 0; image < 30; ++image) {
    const Dims dims{4, 3, 5};
    const std::vector<std::uint16_t> data = testing::randomLabels(rng, dims, 2 + image % 9, true);
    if (!caseChecked(std::uint64_t(image))) continue;
    LabelOptions options;
    options.walls = LabelWalls::Shared;
    options.threads = 1;
    options.smooth = SmoothOptions{};
    const std::vector<LabelSurface> surfaces = extractLabels(VolumeView::of(data.data(), dims, g), options);
    std::map<std::array<int, 4>, Bits> pointOf;
    for (const LabelSurface& l : surfaces) {
      const Surface& s = l.surface;
      EXPECT_GT(l.smooth->volumeAfter, 0) << "image " << image;
      EXPECT_GT(l.smooth->volumeBefore, 0) << "image " << image;
      TriangleMesh mesh;
      mesh.triangles = s.triangles;
      EXPECT_NEAR(testing::signedVolume(mesh, s.vertices), l.smooth->volumeAfter, 1e-9 * l.smooth->volumeAfter);
      for (std::size_t v = 0; v < s.vertices.size(); ++v) {
        const auto [it, added] = pointOf.try_emplace(gridEdge(s.surfels[v]), bitsOf(s.vertices[v]));
        EXPECT_EQ(it->second, bitsOf(s.vertices[v])) << "image " << image << ": a grid edge at two points";
        const P3 q = g.toIndex(s.vertices[v]);
        const Voxel c = s.surfels[v].inside(), d = s.surfels[v].outside();
        const int axis = gridEdge(s.surfels[v])[3];
        for (int a = 0; a < 3; ++a)
          if (a != axis) EXPECT_NEAR(q[std::size_t(a)], double(c[a]), 1e-9) << "image " << image;
        const double t = (q[std::size_t(axis)] - c[axis]) / double(d[axis] - c[axis]);
        EXPECT_GE(t, 1e-3 - 1e-9) << "image " << image;
        EXPECT_LE(t, 1 - 1e-3 + 1e-9) << "image " << image;
      }
    }
  }
}

TEST(ComplexSmoothing, Refusals) {
  const std::vector<std::uint8_t> data{1, 2, 0, 1, 2, 2, 0, 1};
  const VolumeView view = VolumeView::of(data.data(), {2, 2, 2});
  LabelOptions options;
  options.smooth = SmoothOptions{};
  EXPECT_THROW(extractLabels(view, options), InvalidInput);  // independent walls
  options.walls = LabelWalls::Shared;
  options.smooth->mu = -0.5;  // not below -lambda
  EXPECT_THROW(extractLabels(view, options), InvalidInput);
  options.smooth->mu = -0.73;
  options.smooth->iterations = kMaxSmoothIterations + 1;
  EXPECT_THROW(extractLabels(view, options), InvalidInput);
  options.smooth->iterations = 3;
  EXPECT_EQ(extractLabels(view, options).size(), 2u);
}

}  // namespace
}  // namespace surftrack
