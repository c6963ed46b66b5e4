// Shared walls of label maps (LabelWalls::Shared; docs/theory.md, "Shared walls") against
// computations that do not use them:
//  - every 2 x 2 x 2 cube of up to 8 labels in every priority order (all 545,835 ordered set
//    partitions of the corners), for the four pairs: each wall separates two labels and is a
//    supporting plane of the level sets it bounds (the hull property of Definition 9, checked by
//    plane sides); each label's triangles close up inside the cube; each face's trace is a
//    function of the face's four corners alone and the two cubes of a face see it reversed;
//  - 1,000 random label images of 2 to 40 labels (dense random labels, fixed seeds): every wall
//    triangle of a label has exactly one reversed twin in another label (or lies on the domain's
//    border), at bit-identical coordinates; the walls between priorities >= t and < t are
//    exactly the binary surface of the voxels of priority >= t made by the independent path;
//    voxel centres and random points lie inside exactly one label or the background (winding
//    numbers); every label's mesh is a closed oriented 2-manifold, with vertices at equal points
//    exactly at its counted pinch copies.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <set>
#include <unordered_map>
#include <vector>

#include "CaseSubset.h"
#include "ClosedManifold.h"
#include "DigitalCube.h"
#include "FlatKeyMap.h"
#include "LabelPatterns.h"
#include "Labels.h"
#include "MeshChecks.h"
#include "NestedWalls.h"
#include "PairTestName.h"
#include "TriangleIntersection.h"

namespace surftrack {
namespace {

using testing::allPriorityPatterns;
using testing::caseChecked;
using testing::randomLabels;
using testing::Ranks;

std::array<int, 3> doubledMidpoint(int edge) {
  const Voxel a = cube::cornerOffset(cube::edgeLowCorner(edge)), b = cube::cornerOffset(cube::edgeHighCorner(edge));
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}

std::string patternText(const Ranks& rank, const CubeWalls& walls) {
  std::string out = "ranks";
  for (int r : rank) out += " " + std::to_string(r);
  out += "; walls";
  for (int w = 0; w < walls.count; ++w) {
    const auto& t = walls.triangles[std::size_t(w)];
    out += " (" + std::to_string(t.edges[0]) + "," + std::to_string(t.edges[1]) + "," + std::to_string(t.edges[2]) + " " +
           std::to_string(t.inside) + ">" + std::to_string(t.outside) + ")";
  }
  return out;
}

using I3 = std::array<long, 3>;
I3 minus(const I3& a, const I3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
I3 crossOf(const I3& a, const I3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
long dotOf(const I3& a, const I3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }


class SharedWallCubes : public ::testing::TestWithParam<AdjacencyPair> {};

TEST_P(SharedWallCubes, EveryPriorityPatternOfACube) {
  const AdjacencyPair pair = GetParam();
  const std::vector<Ranks> patterns = allPriorityPatterns();
  ASSERT_EQ(patterns.size(), 545835u);  // the ordered Bell (Fubini) number of 8
  // Face traces: key (the face's dense ranks, its side) -> directed segments per label, as face
  // edge pairs; face edge j of the face normal to axis a: the cube edge parallel to the other
  // axis u or v, in the face's own numbering.
  // Indexed by key * 2 + side (a face's dense ranks take 12 bits); empty optional: not seen.
  std::vector<std::optional<std::vector<std::array<int, 3>>>> traces(std::size_t(1) << 13);
  std::size_t pinchedPatterns = 0, pairsTested = 0, checked = 0, foreignPatterns = 0, threeOrMore = 0, maxTriangles = 0;
  for (std::size_t c = 0; c < patterns.size(); ++c) {
    // 6-26 is 26-6 on the reversed priorities (cubeWalls): one pattern in 7 of it, for time.
    if (!caseChecked(c) || (pair == AdjacencyPair::k6_26 && c % 7)) continue;
    ++checked;
    const Ranks& rank = patterns[c];
    const int levels = *std::max_element(rank.begin(), rank.end()) + 1;
    if (levels >= 3) ++threeOrMore;
    const CubeWalls walls = cubeWalls(rank, pair);
    maxTriangles = std::max(maxTriangles, std::size_t(walls.count));
    // Each label's triangles: the walls it is inside of, and those it is outside of, reversed.
    std::vector<std::vector<std::array<int, 3>>> label(static_cast<std::size_t>(levels));
    std::set<std::array<int, 3>> distinct;
    bool foreign = false, pinchedInner = false;
    for (int w = 0; w < walls.count; ++w) {
      const WallTriangle& t = walls.triangles[std::size_t(w)];
      ASSERT_GT(t.inside, t.outside) << "pattern " << c;
      ASSERT_LT(int(t.inside), levels);
      std::array<int, 3> sorted{t.edges[0], t.edges[1], t.edges[2]};
      std::sort(sorted.begin(), sorted.end());
      ASSERT_TRUE(distinct.insert(sorted).second) << "a wall twice, pattern " << c;
      // Each vertex's cube edge is cut at every level the wall bounds: one end >= inside, one
      // <= outside.
      for (int k : t.edges) {
        const int a = rank[std::size_t(cube::edgeLowCorner(k))], b = rank[std::size_t(cube::edgeHighCorner(k))];
        ASSERT_GE(std::max(a, b), int(t.inside)) << "pattern " << c;
        ASSERT_LE(std::min(a, b), int(t.outside)) << "pattern " << c;
        if (a != t.inside && b != t.inside) foreign = true;
        if (a != t.outside && b != t.outside) foreign = true;
      }
      // The hull property (Definition 9): for kappa = 26 every corner of priority > outside lies
      // behind the wall's plane; for the complement's analog (kappa = 6, lambda = 26) every
      // corner of priority < inside lies in front of it.
      const auto p0 = doubledMidpoint(t.edges[0]), p1 = doubledMidpoint(t.edges[1]), p2 = doubledMidpoint(t.edges[2]);
      const std::array<int, 3> u{p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, v{p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
      const std::array<int, 3> n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      ASSERT_NE(n, (std::array<int, 3>{0, 0, 0}));
      for (int i = 0; i < 8; ++i) {
        const Voxel q = cube::cornerOffset(i);
        const int side = n[0] * (2 * q.x - p0[0]) + n[1] * (2 * q.y - p0[1]) + n[2] * (2 * q.z - p0[2]);
        if (pair == AdjacencyPair::k26_6 && rank[std::size_t(i)] > t.outside) {
          ASSERT_LE(side, 0) << "pattern " << c;
        }
        if (pair == AdjacencyPair::k6_26 && rank[std::size_t(i)] < t.inside) {
          ASSERT_GE(side, 0) << "pattern " << c;
        }
      }
      label[t.inside].push_back({t.edges[0], t.edges[1], t.edges[2]});
      label[t.outside].push_back({t.edges[0], t.edges[2], t.edges[1]});
    }
    if (foreign) ++foreignPatterns;
    // The walls of a cube meet only in the vertices and edges they share (refine/'s exact-enough
    // test, itself checked against CGAL in test_refine): a planar face subdivided differently at
    // two levels, or a hull touching another level's face along a segment across its triangles,
    // would not. Pairs strictly on one side of either's plane cannot meet and are skipped; 6-26 is
    // the same computation on the reversed priorities (cubeWalls), so 26-6 only (for time).
    for (int w = 0; w < walls.count; ++w)
      for (int x = w + 1; x < walls.count; ++x) {
        std::array<I3, 3> a, b;
        refine::Triangle3 ta, tb;
        for (int j = 0; j < 3; ++j) {
          const auto pa = doubledMidpoint(walls.triangles[std::size_t(w)].edges[std::size_t(j)]);
          const auto pb = doubledMidpoint(walls.triangles[std::size_t(x)].edges[std::size_t(j)]);
          a[std::size_t(j)] = {pa[0], pa[1], pa[2]};
          b[std::size_t(j)] = {pb[0], pb[1], pb[2]};
          ta[std::size_t(j)] = {double(pa[0]), double(pa[1]), double(pa[2])};
          tb[std::size_t(j)] = {double(pb[0]), double(pb[1]), double(pb[2])};
        }
        auto strictlyAside = [](const std::array<I3, 3>& plane, const std::array<I3, 3>& t) {
          const I3 n = crossOf(minus(plane[1], plane[0]), minus(plane[2], plane[0]));
          int below = 0, above = 0;
          for (const I3& p : t) {
            const long d = dotOf(n, minus(p, plane[0]));
            below += d < 0;
            above += d > 0;
          }
          return below == 3 || above == 3;
        };
        if (pair != AdjacencyPair::k26_6 || strictlyAside(a, b) || strictlyAside(b, a)) continue;
        std::vector<int> shared;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (walls.triangles[std::size_t(w)].edges[std::size_t(i)] == walls.triangles[std::size_t(x)].edges[std::size_t(j)])
              shared.push_back(3 * i + j);
        ASSERT_FALSE(refine::trianglesMeetOutsideShared(ta, tb, shared, 1e-9))
            << "pattern " << c << " " << patternText(rank, walls) << ": walls " << w << " and " << x << " meet improperly";
        ++pairsTested;
      }
    for (int r = 0; r < levels; ++r) {
      // Inner edges (not on one cube face) closed up: each directed edge once, its reverse once.
      std::multiset<std::pair<int, int>> inner;
      for (const auto& t : label[std::size_t(r)])
        for (int j = 0; j < 3; ++j) {
          const int a = t[std::size_t(j)], b = t[std::size_t((j + 1) % 3)];
          const auto pa = doubledMidpoint(a), pb = doubledMidpoint(b);
          int face = -1;
          for (int axis = 0; axis < 3 && face < 0; ++axis)
            for (int s : {0, 2})
              if (pa[std::size_t(axis)] == s && pb[std::size_t(axis)] == s) face = 2 * axis + s / 2;
          if (face < 0) inner.insert({a, b});
        }
      // (Twice each way: the label's region touches itself along that edge, a pinch.)
      for (const auto& [a, b] : inner) {
        ASSERT_EQ(inner.count({b, a}), inner.count({a, b}))
            << "pattern " << c << " label " << r << " open at " << a << "-" << b;
        if (inner.count({a, b}) > 1) pinchedInner = true;
      }
    }
    if (pinchedInner) ++pinchedPatterns;
    // Per face and side, all labels' segments together: compared with the first cube seen.
    for (int face = 0; face < 6; ++face) {
      const int axis = face / 2, side = face % 2;
      const auto [u, v] = cube::otherAxes(axis);
      std::array<int, 4> corner{};
      for (int j = 0; j < 4; ++j) corner[std::size_t(j)] = side << axis | (j & 1) << u | (j >> 1 & 1) << v;
      std::array<std::uint8_t, 4> fr{};
      for (int j = 0; j < 4; ++j) fr[std::size_t(j)] = rank[std::size_t(corner[std::size_t(j)])];
      std::array<std::uint8_t, 4> sorted = fr;
      std::sort(sorted.begin(), sorted.end());
      const auto end = std::unique(sorted.begin(), sorted.end());
      std::uint32_t key = 0;
      for (int j = 0; j < 4; ++j)
        key |= std::uint32_t(std::lower_bound(sorted.begin(), end, fr[std::size_t(j)]) - sorted.begin()) << (3 * j);
      auto local = [&](int edge) {
        const int lo = cube::edgeLowCorner(edge), hi = cube::edgeHighCorner(edge);
        int a = -1, b = -1;
        for (int j = 0; j < 4; ++j) {
          if (corner[std::size_t(j)] == lo) a = j;
          if (corner[std::size_t(j)] == hi) b = j;
        }
        return 4 * a + b;
      };
      auto onThisFace = [&](int edge) {
        const auto p = doubledMidpoint(edge);
        return p[std::size_t(axis)] == 2 * side;
      };
      std::vector<std::array<int, 3>> segs;  // (face-local label, from, to)
      for (int r = 0; r < levels; ++r) {
        // A label's segments on the face; a segment used both ways bounds a zero-thickness rim
        // of the label's region (two of its sheets meeting on the face) and leaves no trace.
        std::multiset<std::pair<int, int>> own;
        for (const auto& t : label[std::size_t(r)])
          for (int j = 0; j < 3; ++j) {
            const int a = t[std::size_t(j)], b = t[std::size_t((j + 1) % 3)];
            if (onThisFace(a) && onThisFace(b)) own.insert({a, b});
          }
        for (const auto& [a, b] : own) {
          if (own.count({b, a})) continue;
          ASSERT_EQ(own.count({a, b}), 1u) << "pattern " << c;
          ASSERT_TRUE(std::binary_search(sorted.begin(), end, std::uint8_t(r)))
              << "pattern " << c << ": label " << r << " has a trace on a face without its voxels";
          const int fl = int(std::lower_bound(sorted.begin(), end, std::uint8_t(r)) - sorted.begin());
          // The frame (u, v, axis) is left-handed for axis y: directions flip there.
          if (axis == 1)
            segs.push_back({fl, local(b), local(a)});
          else
            segs.push_back({fl, local(a), local(b)});
        }
      }
      std::sort(segs.begin(), segs.end());
      auto& seen = traces[std::size_t(key) * 2 + std::size_t(side)];
      if (!seen) {
        seen = segs;
      } else {
        ASSERT_EQ(*seen, segs) << "pattern " << c << " face " << face << ": the trace is not the face's";
      }
    }
  }
  // The two cubes of a face see the same segments, reversed.
  std::size_t faces = 0;
  for (std::size_t key = 0; key < traces.size() / 2; ++key) {
    if (!traces[2 * key] || !traces[2 * key + 1]) continue;
    ++faces;
    std::vector<std::array<int, 3>> reversed;
    for (const auto& s : *traces[2 * key + 1]) reversed.push_back({s[0], s[2], s[1]});
    std::sort(reversed.begin(), reversed.end());
    EXPECT_EQ(*traces[2 * key], reversed) << "face pattern " << key;
  }
  if (!testing::kSanitizedBuild) {
    EXPECT_EQ(faces, 75u);
  }  // the ordered set partitions of 4 corners
  std::cout << "[ study ] " << toString(pair) << ": " << checked << " priority patterns, " << threeOrMore
            << " with >= 3 labels, " << foreignPatterns
            << " where a label's triangles use a vertex between two other labels, " << pinchedPatterns
            << " where a label touches itself along an edge inside the cube; at most " << maxTriangles
            << " walls per cube; " << faces << " face patterns; " << pairsTested
            << " pairs of walls tested for intersection\n";
}

INSTANTIATE_TEST_SUITE_P(Pairs, SharedWallCubes, ::testing::Values(AdjacencyPair::k26_6, AdjacencyPair::k6_26),
                         testing::pairTestName);

// ---------------------------------------------------------------------------------------------
// Random label images.

using Key3 = std::array<long long, 3>;  // a point, doubled: exact for midpoints
using DirectedTriangle = std::array<Key3, 3>;  // rotated so that the least point comes first

Key3 keyOf(const std::array<double, 3>& p) {
  Key3 k;
  for (int i = 0; i < 3; ++i) {
    const double d = 2 * p[std::size_t(i)];
    k[std::size_t(i)] = std::llround(d);
    EXPECT_EQ(double(k[std::size_t(i)]), d) << "a vertex off the half-integer grid";
  }
  return k;
}

DirectedTriangle directed(Key3 a, Key3 b, Key3 c) {
  DirectedTriangle t{a, b, c};
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

DirectedTriangle reversedOf(const DirectedTriangle& t) { return directed(t[0], t[2], t[1]); }

/// Every triangle of every surface, with its label index.
std::map<DirectedTriangle, std::vector<int>> trianglesByLabel(const std::vector<LabelSurface>& surfaces) {
  std::map<DirectedTriangle, std::vector<int>> out;
  for (std::size_t l = 0; l < surfaces.size(); ++l) {
    const Surface& s = surfaces[l].surface;
    for (const auto& t : s.triangles)
      out[directed(keyOf(s.vertices[t[0]]), keyOf(s.vertices[t[1]]), keyOf(s.vertices[t[2]]))].push_back(int(l));
  }
  return out;
}

/// The planar faces of a set of triangles: coplanar triangles of one orientation joined through
/// shared edges, each face as its plane and its vertex set, so that two triangulations of the
/// same faces compare equal.
std::set<std::pair<std::array<long long, 4>, std::set<Key3>>> planarFaces(const std::set<DirectedTriangle>& triangles) {
  std::vector<DirectedTriangle> list(triangles.begin(), triangles.end());
  std::vector<std::array<long long, 4>> plane(list.size());
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto& t = list[i];
    const Key3 u{t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
    const Key3 v{t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
    Key3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const long long g = std::gcd(std::gcd(std::llabs(n[0]), std::llabs(n[1])), std::llabs(n[2]));
    for (auto& x : n) x /= g;
    plane[i] = {n[0], n[1], n[2], n[0] * t[0][0] + n[1] * t[0][1] + n[2] * t[0][2]};
  }
  std::vector<std::size_t> parent(list.size());
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::map<std::pair<std::array<long long, 4>, std::array<Key3, 2>>, std::size_t> byEdge;
  for (std::size_t i = 0; i < list.size(); ++i)
    for (int j = 0; j < 3; ++j) {
      std::array<Key3, 2> e{list[i][std::size_t(j)], list[i][std::size_t((j + 1) % 3)]};
      std::sort(e.begin(), e.end());
      const auto [it, added] = byEdge.try_emplace({plane[i], e}, i);
      if (!added) parent[find(i)] = find(it->second);
    }
  std::map<std::size_t, std::pair<std::array<long long, 4>, std::set<Key3>>> groups;
  for (std::size_t i = 0; i < list.size(); ++i) {
    auto& g = groups[find(i)];
    g.first = plane[i];
    g.second.insert(list[i].begin(), list[i].end());
  }
  std::set<std::pair<std::array<long long, 4>, std::set<Key3>>> out;
  for (const auto& [root, g] : groups) out.insert(g);
  return out;
}

/// The Euler characteristic of the union of the closed unit cubes centred at `voxels` (the
/// 26-6 solid of a binary image, docs/theory.md §9), by counting its cells in doubled
/// coordinates: a cell's dimension is its number of even coordinates (the cube of voxel v spans
/// 2v - 1 .. 2v + 1).
long closedCubesEuler(const std::vector<Voxel>& voxels) {
  std::set<std::array<int, 3>> cells;
  for (const Voxel& v : voxels)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) cells.insert({2 * v.x + dx, 2 * v.y + dy, 2 * v.z + dz});
  long chi = 0;
  for (const auto& c : cells) {
    const int even = !(c[0] & 1) + !(c[1] & 1) + !(c[2] & 1);
    chi += even % 2 ? -1 : 1;
  }
  return chi;
}

TEST(SharedWalls, ThousandRandomLabelImages) {
  std::mt19937_64 rng(2026);
  std::size_t eulerChecked = 0, unsplit = 0, unsplitLabels = 0, joined = 0, joinedLabels = 0, images = 0, labelsSeen = 0, pinchedLabels = 0, copies = 0, pinchedEdges = 0, points = 0, walls = 0;
  for (int image = 0; image < 1000; ++image) {
    std::uniform_int_distribution<int> side(2, 5);
    const Dims dims{side(rng), side(rng), side(rng)};
    const int count = std::uniform_int_distribution<int>(2, 40)(rng);
    const bool withBackground = image % 2 == 0;
    const std::vector<std::uint16_t> data = randomLabels(rng, dims, count, withBackground);
    if (!caseChecked(std::uint64_t(image))) continue;
    ++images;
    LabelOptions options;
    options.walls = LabelWalls::Shared;
    options.threads = 1;
    options.background = withBackground ? 0 : 65535;  // absent: only the outside is background
    const VolumeView view = VolumeView::of(data.data(), dims);
    const std::vector<LabelSurface> surfaces = extractLabels(view, options);
    // Priorities: the background 0, then by increasing label (the surfaces come in that order).
    std::vector<std::uint16_t> values(data);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    if (withBackground && values[0] == 0) values.erase(values.begin());
    ASSERT_EQ(surfaces.size(), values.size());
    for (std::size_t l = 0; l < values.size(); ++l) ASSERT_EQ(surfaces[l].label, LabelValue(values[l]));
    auto priorityOf = [&](Voxel v) -> int {  // 0 background or outside, 1 + label index
      if (!dims.contains(v)) return 0;
      const std::uint16_t x = data[std::size_t(v.x) + std::size_t(dims.nx) * (std::size_t(v.y) + std::size_t(dims.ny) * std::size_t(v.z))];
      if (withBackground && x == 0) return 0;
      return int(std::lower_bound(values.begin(), values.end(), x) - values.begin()) + 1;
    };

    // Twins: each triangle of label A reversed in exactly one other label B (A inside, B outside)
    // or, when it has none, the background outside.
    const auto all = trianglesByLabel(surfaces);
    std::map<DirectedTriangle, int> outsideOf;  // priority outside each directed triangle
    for (const auto& [t, owners] : all) {
      ASSERT_EQ(owners.size(), 1u) << "image " << image << ": a triangle twice in one orientation";
      const auto twin = all.find(reversedOf(t));
      if (twin != all.end()) {
        ASSERT_NE(twin->second[0], owners[0]) << "image " << image << ": a label's triangle and its reverse";
        outsideOf[t] = twin->second[0] + 1;
      } else {
        if (!withBackground) {
          // Only the outside of the domain is background: the triangle lies over the border.
          for (const Key3& p : t) {
            bool border = false;
            for (int a = 0; a < 3; ++a) {
              const int n = a == 0 ? dims.nx : a == 1 ? dims.ny : dims.nz;
              border |= p[std::size_t(a)] == -1 || p[std::size_t(a)] == 2 * n - 1;
            }
            ASSERT_TRUE(border) << "image " << image << ": a wall without its twin inside the domain";
          }
        }
        outsideOf[t] = 0;
      }
      ++walls;
    }
    // The walls between priorities >= t and < t are the binary surface of priority >= t, made by
    // the independent path (26-6, the pair of the levels), up to the triangulation of planar
    // faces.
    const int levels = int(values.size());
    for (int t = 1; t <= levels; ++t) {
      std::vector<std::uint8_t> binary(data.size());
      for (int z = 0, i = 0; z < dims.nz; ++z)
        for (int y = 0; y < dims.ny; ++y)
          for (int x = 0; x < dims.nx; ++x, ++i) binary[std::size_t(i)] = priorityOf({x, y, z}) >= t;
      std::set<DirectedTriangle> expected;
      if (std::count(binary.begin(), binary.end(), 1)) {
        LabelOptions b;
        b.threads = 1;
        b.labels = LabelSelection::list({LabelValue(1)});
        const auto level = extractLabels(VolumeView::of(binary.data(), dims), b);
        const Surface& s = level.at(0).surface;
        for (const auto& tri : s.triangles)
          expected.insert(directed(keyOf(s.vertices[tri[0]]), keyOf(s.vertices[tri[1]]), keyOf(s.vertices[tri[2]])));
      }
      std::set<DirectedTriangle> got;
      for (const auto& [tri, owners] : all)
        if (owners[0] + 1 >= t && outsideOf[tri] < t) got.insert(tri);
      // The same faces; a face of V_t may be cut along the edges of higher levels' faces.
      ASSERT_EQ(planarFaces(got), planarFaces(expected)) << "image " << image << ": level " << t;
    }
    // chi(V_t): the level sets' solids (the 26-6 analog of B_t has the topology of its voxels).
    std::vector<long> chiLevel(std::size_t(levels) + 2, 0);
    for (int t = 1; t <= levels; ++t) {
      std::vector<Voxel> at;
      for (int z = 0; z < dims.nz; ++z)
        for (int y = 0; y < dims.ny; ++y)
          for (int x = 0; x < dims.nx; ++x)
            if (priorityOf({x, y, z}) >= t) at.push_back({x, y, z});
      chiLevel[std::size_t(t)] = closedCubesEuler(at);
    }
    // Each label: a closed oriented 2-manifold; vertices at one point are exactly its pinch copies.
    for (const LabelSurface& l : surfaces) {
      const Surface& s = l.surface;
      const checks::Topology topology = checks::topologyOf(s.vertices.size(), s.triangles);
      // A closed oriented 2-cycle: every directed edge as often as its reverse; a 2-manifold
      // unless an edge is left with four triangles, which must be counted.
      std::map<std::pair<std::uint32_t, std::uint32_t>, int> directedUses;
      for (const auto& t : s.triangles)
        for (int j = 0; j < 3; ++j) ++directedUses[{t[std::size_t(j)], t[std::size_t((j + 1) % 3)]}];
      std::size_t crowded = 0;
      for (const auto& [e, uses] : directedUses) {
        const auto back = directedUses.find({e.second, e.first});
        ASSERT_TRUE(back != directedUses.end() && back->second == uses) << "image " << image << ": not closed";
        crowded += e.first < e.second && uses > 1;
      }
      ASSERT_EQ(crowded, l.unsplitEdges) << "image " << image;
      if (l.unsplitEdges == 0) {
        ASSERT_TRUE(topology.manifoldVertices) << "image " << image << " label " << l.label.text() << ": " << topology.problem;
      }
      unsplit += l.unsplitEdges;
      if (l.unsplitEdges) ++unsplitLabels;
      ASSERT_LE(l.joinedEdges, l.pinchedEdges);
      joined += l.joinedEdges;
      if (l.joinedEdges) ++joinedLabels;
      if (l.unsplitEdges == 0) {
        ASSERT_EQ(topology.euler, s.euler);  // (figures count an edge per two triangles)
      }
      std::vector<Key3> keys;
      for (const auto& p : s.vertices) keys.push_back(keyOf(p));
      std::sort(keys.begin(), keys.end());
      const auto distinct = std::size_t(std::unique(keys.begin(), keys.end()) - keys.begin());
      ASSERT_EQ(s.vertices.size() - distinct, l.pinchCopies) << "image " << image;
      ++labelsSeen;
      if (l.pinchCopies) ++pinchedLabels;
      copies += l.pinchCopies;
      pinchedEdges += l.pinchedEdges;
      // The identity below is for a region without pinches; opening a pinch changes chi by the
      // number of the region's pieces around the vertex less one, which the copies (one per
      // sheet) do not give when a piece is not a disc (docs/theory.md §12).
      if (l.pinchCopies || l.pinchedEdges) continue;
      ++eulerChecked;
      // Its Euler characteristic (docs/theory.md §12): R_t = closure(V_t minus V_t+1), so
      // chi(R_t) = chi(V_t) - chi(V_t+1) + chi(S), S = R_t n V_t+1 the part of its mesh spanned
      // by the vertices on edges reaching priority t + 1 (each cube's hulls are convex); opening
      // the pinches adds the vertex copies and removes the extra sheets of pinched edges; the
      // opened region is a 3-manifold whose boundary, the mesh, has chi = 2 chi(region).
      const int p = int(&l - surfaces.data()) + 1;
      auto onHigher = [&](const Key3& k) {
        Voxel c{}, d{};
        for (int a = 0; a < 3; ++a) {
          const long long lo = (k[std::size_t(a)] - (k[std::size_t(a)] & 1)) / 2;
          c[a] = int(lo);
          d[a] = int(lo + (k[std::size_t(a)] & 1));
        }
        return std::max(priorityOf(c), priorityOf(d)) > p;
      };
      std::map<std::array<Key3, 2>, int> edgeUses;
      std::set<std::array<Key3, 3>> faces;
      for (const auto& t : s.triangles) {
        std::array<Key3, 3> k{keyOf(s.vertices[t[0]]), keyOf(s.vertices[t[1]]), keyOf(s.vertices[t[2]])};
        std::sort(k.begin(), k.end());
        faces.insert(k);
        ++edgeUses[{k[0], k[1]}];
        ++edgeUses[{k[1], k[2]}];
        ++edgeUses[{k[0], k[2]}];
      }
      long chiS = 0, edgeCopies = 0;
      for (std::size_t v = 0; v < distinct; ++v) chiS += onHigher(keys[v]);
      for (const auto& [e, uses] : edgeUses) {
        chiS -= onHigher(e[0]) && onHigher(e[1]);
        edgeCopies += uses / 2 - 1;
      }
      for (const auto& f : faces) chiS += onHigher(f[0]) && onHigher(f[1]) && onHigher(f[2]);
      const long region = chiLevel[std::size_t(p)] - chiLevel[std::size_t(p) + 1] + chiS;
      ASSERT_EQ(edgeCopies, 0);
      EXPECT_EQ(topology.euler, 2 * region) << "image " << image << " label " << l.label.text() << " dims " << dims.nx << "x"
                                            << dims.ny << "x" << dims.nz << " chi(V_t) " << chiLevel[std::size_t(p)]
                                            << " chi(V_t+1) " << chiLevel[std::size_t(p) + 1] << " chi(S) " << chiS
                                            << " copies " << l.pinchCopies << " edge copies " << edgeCopies;
    }
    // Inside exactly one label or the background: voxel centres (in their own label) and random
    // points, by winding numbers.
    std::vector<TriangleMesh> meshes(surfaces.size());
    for (std::size_t l = 0; l < surfaces.size(); ++l) meshes[l].triangles = surfaces[l].surface.triangles;
    auto check = [&](const testing::Point& q, int expected) {
      double sum = 0;
      int inside = 0;
      for (std::size_t l = 0; l < surfaces.size(); ++l) {
        const double w = testing::windingNumber(meshes[l], surfaces[l].surface.vertices, q);
        ASSERT_NEAR(w, std::round(w), 1e-6);
        ASSERT_TRUE(std::round(w) == 0 || std::round(w) == 1) << "winding " << w;
        if (std::round(w) == 1) inside = int(l) + 1;
        sum += std::round(w);
      }
      ASSERT_LE(sum, 1) << "image " << image << ": a point inside two labels";
      if (expected >= 0) {
        ASSERT_EQ(inside, expected) << "image " << image;
      }
      ++points;
    };
    for (int z = 0; z < dims.nz; ++z)
      for (int y = 0; y < dims.ny; ++y)
        for (int x = 0; x < dims.nx; ++x) check({double(x), double(y), double(z)}, priorityOf({x, y, z}));
    std::uniform_real_distribution<double> unit(0, 1);
    for (int k = 0; k < 12; ++k)
      check({-0.9 + unit(rng) * (dims.nx + 0.8), -0.9 + unit(rng) * (dims.ny + 0.8), -0.9 + unit(rng) * (dims.nz + 0.8)}, -1);
  }
  EXPECT_GE(images, testing::subsetMinimum(1000));
  EXPECT_GE(eulerChecked, testing::subsetMinimum(3000));
  std::cout << "[ study ] " << images << " random images, " << labelsSeen << " labels, " << walls
            << " directed wall triangles, " << points << " points; " << pinchedLabels << " labels with pinches, "
            << copies << " vertex copies, " << pinchedEdges << " pinched edges; " << joinedLabels << " labels with "
            << joined << " edges taken as joined; " << unsplitLabels
            << " labels with " << unsplit << " edges no copy separates; Euler characteristic checked on "
            << eulerChecked << " labels without pinches\n";
}

/// The smallest pinch (docs/theory.md, "Shared walls"): label 1 at (1, 2, 2) and (1, 0, 0), label
/// 2 at (1, 1, 1) between them, the background elsewhere. Label 1's two regions both reach the
/// vertex between (1, 1, 1) and (2, 1, 1), (0, 1, 1), from opposite cubes.
TEST(SharedWalls, TheSmallestPinch) {
  const Dims dims{3, 3, 3};
  std::vector<std::uint8_t> data(27, 0);
  auto at = [&](int x, int y, int z) -> std::uint8_t& { return data[std::size_t(x + 3 * (y + 3 * z))]; };
  at(1, 1, 1) = 2;
  at(1, 2, 2) = 1;
  at(1, 0, 0) = 1;
  LabelOptions options;
  options.walls = LabelWalls::Shared;
  const auto surfaces = extractLabels(VolumeView::of(data.data(), dims), options);
  ASSERT_EQ(surfaces.size(), 2u);
  const LabelSurface& one = surfaces[0];
  EXPECT_GT(one.pinchCopies, 0u);
  EXPECT_EQ(surfaces[1].pinchCopies, 0u);
  const checks::Topology topology = checks::topologyOf(one.surface.vertices.size(), one.surface.triangles);
  EXPECT_TRUE(topology.manifoldVertices) << topology.problem;
  EXPECT_FALSE(one.surface.warnings.empty());
  std::cout << "[ study ] smallest pinch: label 1 has " << one.pinchCopies << " copies, " << one.pinchedEdges
            << " pinched edges, " << topology.components << " components, euler " << topology.euler << "\n";
}

/// Under a mirrored geometry the normals still point out of each label (placeSurface's rule):
/// every label's signed volume is positive, and the same as without the mirror.
TEST(SharedWalls, MirroredGeometryKeepsNormalsOutwards) {
  std::mt19937_64 rng(25);
  for (int image = 0; image < 50; ++image) {
    const Dims dims{4, 3, 5};
    const std::vector<std::uint16_t> data = randomLabels(rng, dims, 6, true);
    LabelOptions options;
    options.walls = LabelWalls::Shared;
    options.threads = 1;
    ImageGeometry mirror;
    mirror.spacing = {0.5, 2.0, 1.5};
    mirror.direction = {{{1, 0, 0}, {0, 1, 0}, {0, 0, -1}}};
    const auto plain = extractLabels(VolumeView::of(data.data(), dims), options);
    const auto mirrored = extractLabels(VolumeView::of(data.data(), dims, mirror), options);
    ASSERT_EQ(plain.size(), mirrored.size());
    for (std::size_t l = 0; l < plain.size(); ++l) {
      TriangleMesh a, b;
      a.triangles = plain[l].surface.triangles;
      b.triangles = mirrored[l].surface.triangles;
      const double va = testing::signedVolume(a, plain[l].surface.vertices);
      const double vb = testing::signedVolume(b, mirrored[l].surface.vertices);
      EXPECT_GT(va, 0);
      EXPECT_NEAR(vb, va * 0.5 * 2.0 * 1.5, 1e-9 * (1 + va)) << "image " << image;
    }
  }
}

/// The scan runs by slabs of planes on the arena's threads (two slabs a thread) and puts their
/// walls together in slab order: every thread count gives the one-thread result, array for
/// array, on random images thin and thick along z (one plane included: fewer planes than
/// slabs), with a selection of labels, and with the complex smoothed and decimated.
TEST(SharedWalls, EveryThreadCountGivesTheSameSurfaces) {
  std::mt19937_64 rng(31);
  for (int image = 0; image < 300; ++image) {
    std::uniform_int_distribution<int> side(1, 7);
    const Dims dims{side(rng), side(rng), image % 3 == 0 ? 1 + image % 2 : side(rng) + 3};
    const std::vector<std::uint16_t> data = randomLabels(rng, dims, std::uniform_int_distribution<int>(2, 12)(rng), true);
    LabelOptions options;
    options.walls = LabelWalls::Shared;
    if (image % 4 == 1) options.labels = LabelSelection::list({LabelValue(1), LabelValue(3)});
    if (image % 5 == 2) {
      options.smooth = SmoothOptions{};
      options.smooth->iterations = 3;
      options.decimate = DecimateOptions{};
      options.decimate->reduction = 0.5;
    }
    if (image % 7 == 3) options.pair = AdjacencyPair::k6_26;
    options.threads = 1;
    std::vector<LabelSurface> one;
    try {
      one = extractLabels(VolumeView::of(data.data(), dims), options);
    } catch (const InvalidInput&) {
      continue;  // (a selected label absent from this image)
    }
    for (const int threads : {2, 3, 8}) {
      options.threads = threads;
      const auto many = extractLabels(VolumeView::of(data.data(), dims), options);
      ASSERT_EQ(many.size(), one.size());
      for (std::size_t l = 0; l < one.size(); ++l) {
        const Surface &a = one[l].surface, &b = many[l].surface;
        ASSERT_EQ(many[l].label, one[l].label);
        ASSERT_EQ(b.surfels, a.surfels) << "image " << image << ", " << threads << " threads, label " << l;
        ASSERT_EQ(b.triangles, a.triangles) << "image " << image << ", " << threads << " threads, label " << l;
        ASSERT_EQ(b.vertices, a.vertices) << "image " << image << ", " << threads << " threads, label " << l;
        ASSERT_EQ(many[l].voxels, one[l].voxels);
      }
    }
  }
}

TEST(SharedWalls, Refusals) {
  std::vector<std::uint8_t> data(8, 1);
  LabelOptions options;
  options.walls = LabelWalls::Shared;
  options.boundaries = LabelBoundaries::Largest;
  EXPECT_THROW(extractLabels(VolumeView::of(data.data(), Dims{2, 2, 2}), options), InvalidInput);
  options.boundaries = LabelBoundaries::All;
  options.seeds = {Voxel{0, 0, 0}};
  EXPECT_THROW(extractLabels(VolumeView::of(data.data(), Dims{2, 2, 2}), options), InvalidInput);
  options.seeds.clear();
  options.pair = AdjacencyPair::k18_6;
  EXPECT_THROW(extractLabels(VolumeView::of(data.data(), Dims{2, 2, 2}), options), InvalidInput);
}

}  // namespace
}  // namespace surftrack

namespace surftrack {
namespace {

/// lib/FlatKeyMap.h, which numbers the vertices of the shared walls' scan, against
/// std::unordered_map on random keys with repeats (the table grows many times), with and
/// without room reserved ahead (at the start and part of the way).
TEST(FlatKeyMap, AgreesWithAnUnorderedMap) {
  std::mt19937_64 rng(7);
  for (const std::uint64_t range : {std::uint64_t(50), std::uint64_t(1) << 20, ~std::uint64_t(0) - 1})
  for (const std::size_t reserveAt : {std::size_t(0), std::size_t(1000), std::size_t(1) << 30}) {
    FlatKeyMap flat;
    std::unordered_map<std::uint64_t, std::uint32_t> reference;
    std::uniform_int_distribution<std::uint64_t> key(0, range);
    for (std::uint32_t i = 0; i < 200000; ++i) {
      if (i == reserveAt) flat.reserve(150000);
      const std::uint64_t k = key(rng);
      const auto [it, added] = reference.try_emplace(k, i);
      ASSERT_EQ(flat.tryEmplace(k, i), std::make_pair(it->second, added)) << "key " << k;
    }
    ASSERT_EQ(flat.size(), reference.size());
  }
}

}  // namespace
}  // namespace surftrack
