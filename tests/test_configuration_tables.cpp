// The configuration tables (§5.1, Definition 9) against independent properties, for all
// 4 pairs x 256 configurations: vertices = cut edges; triangle edges on cube faces = the
// beta-arcs of Definition 38 (i)-(iii) computed from the per-edge rule (docs/theory.md,
// 'The beta-adjacency');
// closedness and orientation within a cube and across neighbouring cubes; supporting planes of
// the local volume; the strict-26 tube; patches = triangulated loops; no triangle in a cube face
// (the owning cube of block meshing); regeneration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "LocalConvexVolume.h"

namespace surftrack {
namespace {

using Point = std::array<int, 3>;
using Arc = std::pair<int, int>;  // directed: (from, to) cube edges

bool on(int config, int corner) { return (config >> corner) & 1; }
int lowCorner(int k) { return cube::edgeLowCorner(k); }
int highCorner(int k) { return cube::edgeHighCorner(k); }
bool isCut(int config, int k) { return on(config, lowCorner(k)) != on(config, highCorner(k)); }
int oneCorner(int config, int k) { return on(config, lowCorner(k)) ? lowCorner(k) : highCorner(k); }
int zeroCorner(int config, int k) { return on(config, lowCorner(k)) ? highCorner(k) : lowCorner(k); }

// Doubled coordinates: corners at 0/2, edge midpoints at 1.
Point corner2(int i) { return {2 * (i & 1), 2 * (i >> 1 & 1), 2 * (i >> 2 & 1)}; }
Point mid2(int k) {
  Point a = corner2(lowCorner(k)), b = corner2(highCorner(k));
  return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}
Point sub(Point a, Point b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point cross(Point a, Point b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
int dot(Point a, Point b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point normalOf(const std::array<std::uint8_t, 3>& t) {
  return cross(sub(mid2(t[1]), mid2(t[0])), sub(mid2(t[2]), mid2(t[0])));
}

// Edge k lies on the cube face {bit `axis` of the corners == side}.
bool onFace(int k, int axis, int side) {
  return axis != cube::edgeAxis(k) && (lowCorner(k) >> axis & 1) == side;
}
bool shareCubeFace(int k1, int k2) {
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      if (onFace(k1, axis, side) && onFace(k2, axis, side)) return true;
  return false;
}

std::string where(AdjacencyPair pair, int config) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "pair %s config 0x%02x", toString(pair).c_str(), config);
  return buf;
}

// The beta-neighbour of the surfel on cut edge k across the cube face spanned by its edge and
// `axis`, by the 4-row rule of docs/theory.md, 'The beta-adjacency' (Definition 38 (i)-(iii)):
// u the 1-voxel, u+n the 0-voxel, e the unit vector along `axis` pointing into the cube.
int betaNeighbourInFace(AdjacencyPair pair, int config, int k, int axis) {
  const int u = oneCorner(config, k), un = zeroCorner(config, k), e = 1 << axis;
  const bool a = on(config, u ^ e), b = on(config, un ^ e);
  if (a && !b) return cube::edgeBetween(u ^ e, un ^ e);                         // (iii)
  if (!a && (!b || kappa(pair) == 6)) return cube::edgeBetween(u, u ^ e);      // (i)
  return cube::edgeBetween(un ^ e, un);                                        // (ii)
}

// The expected beta-arcs inside the cube, as unordered pairs (min, max).
std::set<Arc> expectedBetaArcs(AdjacencyPair pair, int config) {
  std::set<Arc> arcs;
  for (int k = 0; k < 12; ++k) {
    if (!isCut(config, k)) continue;
    for (int axis = 0; axis < 3; ++axis) {
      if (axis == cube::edgeAxis(k)) continue;
      int nb = betaNeighbourInFace(pair, config, k, axis);
      arcs.insert({std::min(k, nb), std::max(k, nb)});
    }
  }
  return arcs;
}

// Strict 26-configuration: exactly two set bits (of config for kappa = 26, of ~config for
// lambda = 26) at diagonally opposite corners. Returns the corner p, or -1.
int strict26Corner(AdjacencyPair pair, int config) {
  int bits = kappa(pair) == 26 ? config : lambda(pair) == 26 ? (~config & 0xFF) : 0;
  for (int p = 0; p < 8; ++p)
    if (bits == ((1 << p) | (1 << (7 - p)))) return p;
  return -1;
}

// The corners of value `value` connected to `seed` under `adjacency` inside the cube.
int componentOf(int config, int value, int adjacency, int seed) {
  int comp = 1 << seed, grown = 0;
  while (grown != comp) {
    grown = comp;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j)
        if ((comp >> i & 1) && on(config, j) == bool(value) &&
            areAdjacent(adjacency, cube::cornerOffset(i), cube::cornerOffset(j)))
          comp |= 1 << j;
  }
  return comp;
}

template <class F>
void forAllConfigurations(F f) {
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (int config = 0; config < 256; ++config) {
      SCOPED_TRACE(where(pair, config));
      f(pair, config, configurationTable(pair, std::uint8_t(config)));
    }
}

TEST(ConfigurationTables, VerticesAreExactlyTheCutEdges) {
  forAllConfigurations([](AdjacencyPair, int config, const CubeTriangulation& t) {
    std::set<int> vertices, cut;
    for (auto& tri : t.allTriangles()) vertices.insert(tri.begin(), tri.end());
    for (int k = 0; k < 12; ++k)
      if (isCut(config, k)) cut.insert(k);
    EXPECT_EQ(vertices, cut);
  });
}

// The owning cube of a triangle (docs/theory.md, "Label maps by blocks"): no triangle of any
// entry lies in a face of its cube (its three cut edges never share one), so the componentwise
// minimum of the six voxels of its three surfels is the cube's min corner. Block meshing
// (mergeLabelFragments) orders the triangles it gathers from several blocks by that cube, so
// this must hold for every triangle of every configuration of every pair. Checked on surfels
// placed in a cube away from the origin (with negative coordinates too: the cubes of the
// domain's low faces have min corner -1).
TEST(ConfigurationTables, OwningCubeIsTheMinimumOfATrianglesVoxels) {
  int triangles = 0;
  for (const Voxel m : {Voxel{5, -1, 7}, Voxel{-1, -1, -1}, Voxel{0, 3, -1}})
    forAllConfigurations([&](AdjacencyPair, int config, const CubeTriangulation& t) {
      for (auto& tri : t.allTriangles()) {
        for (int axis = 0; axis < 3; ++axis)
          for (int side = 0; side < 2; ++side)
            EXPECT_FALSE(onFace(tri[0], axis, side) && onFace(tri[1], axis, side) && onFace(tri[2], axis, side))
                << "triangle in the cube face axis " << axis << " side " << side;
        Voxel low{1 << 20, 1 << 20, 1 << 20};
        for (int k : tri) {
          ASSERT_TRUE(isCut(config, k));
          const Surfel s = cube::surfelOnEdge(m, k, std::uint8_t(config));
          for (const Voxel v : {s.inside(), s.outside()}) {
            EXPECT_GE(cube::cornerOf(m, v), 0);  // both voxels are corners of the cube
            low = {std::min(low.x, v.x), std::min(low.y, v.y), std::min(low.z, v.z)};
          }
        }
        EXPECT_EQ(low, m);
        ++triangles;
      }
    });
  EXPECT_GT(triangles, 3 * 4 * 256);  // every entry but the two uniform ones has a triangle
}

TEST(ConfigurationTables, FaceEdgesAreExactlyTheBetaArcs) {
  forAllConfigurations([](AdjacencyPair pair, int config, const CubeTriangulation& t) {
    // The rule itself: each cut edge has exactly 2 arcs (one per cube face through its edge),
    // to cut edges on that face, and the relation is symmetric.
    std::map<int, int> degree;
    for (int k = 0; k < 12; ++k) {
      if (!isCut(config, k)) continue;
      for (int axis = 0; axis < 3; ++axis) {
        if (axis == cube::edgeAxis(k)) continue;
        int nb = betaNeighbourInFace(pair, config, k, axis);
        ASSERT_TRUE(nb >= 0 && nb != k && isCut(config, nb) && shareCubeFace(k, nb));
        bool back = false;
        for (int axis2 = 0; axis2 < 3; ++axis2)
          if (axis2 != cube::edgeAxis(nb)) back |= betaNeighbourInFace(pair, config, nb, axis2) == k;
        EXPECT_TRUE(back) << "rule not symmetric for " << k << "-" << nb;
      }
    }
    const std::set<Arc> expected = expectedBetaArcs(pair, config);
    for (const Arc& a : expected) degree[a.first]++, degree[a.second]++;
    for (auto [k, d] : degree) EXPECT_EQ(d, 2) << "edge " << k;

    std::set<Arc> faceEdges;
    for (auto& tri : t.allTriangles())
      for (int i = 0; i < 3; ++i) {
        int a = tri[i], b = tri[(i + 1) % 3];
        if (shareCubeFace(a, b)) faceEdges.insert({std::min(a, b), std::max(a, b)});
      }
    EXPECT_EQ(faceEdges, expected);
  });
}

// Within one cube: every triangle has 3 distinct vertices and is unique; an edge on a cube
// face is used by exactly one triangle (its other side is in the neighbouring cube); an inner
// edge is used by exactly two triangles, once in each direction.
TEST(ConfigurationTables, FaceEdgesUsedOnceInnerEdgesTwiceInOppositeDirections) {
  forAllConfigurations([](AdjacencyPair, int, const CubeTriangulation& t) {
    std::map<Arc, int> directedUse;
    std::set<std::array<std::uint8_t, 3>> seen;
    for (auto tri : t.allTriangles()) {
      EXPECT_TRUE(tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]);
      std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
      EXPECT_TRUE(seen.insert(tri).second) << "duplicate triangle";
      for (int i = 0; i < 3; ++i) directedUse[{tri[i], tri[(i + 1) % 3]}]++;
    }
    for (auto [arc, n] : directedUse) {
      auto [a, b] = arc;
      EXPECT_EQ(n, 1) << a << "->" << b;
      bool reverse = directedUse.count({b, a});
      if (shareCubeFace(a, b))
        EXPECT_FALSE(reverse) << "face edge " << a << "-" << b << " used twice";
      else
        EXPECT_TRUE(reverse) << "inner edge " << a << "->" << b << " used once";
    }
  });
}

// The directed arcs on cube face {bit axis == side}, in the coordinates of that face.
std::set<Arc> directedFaceArcs(const CubeTriangulation& t, int axis, int side) {
  std::set<Arc> out;
  for (auto& tri : t.allTriangles())
    for (int i = 0; i < 3; ++i) {
      int a = tri[i], b = tri[(i + 1) % 3];
      if (onFace(a, axis, side) && onFace(b, axis, side)) out.insert({a, b});
    }
  return out;
}

// Across the face shared by two neighbouring cubes, the arcs of one cube are exactly the
// reversed arcs of the other, whatever the other 4 voxels: together the tables give a closed
// oriented surface (paper §5.2; docs/theory.md, 'Loops and their triangulation').
TEST(ConfigurationTables, FaceArcsAreReversedInTheNeighbouringCube) {
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (int axis = 0; axis < 3; ++axis) {
      const int bit = 1 << axis;
      auto shift = [&](int k) {  // edge on face side 1 -> same grid edge in the next cube
        return cube::edgeBetween(lowCorner(k) ^ bit, highCorner(k) ^ bit);
      };
      for (int lower = 0; lower < 256; ++lower) {
        std::set<Arc> expected;
        for (auto [a, b] : directedFaceArcs(configurationTable(pair, lower), axis, 1))
          expected.insert({shift(b), shift(a)});
        for (int upper = 0; upper < 256; ++upper) {
          bool sameFace = true;
          for (int i = 0; i < 8; ++i)
            if ((i & bit) && on(lower, i) != on(upper, i ^ bit)) sameFace = false;
          if (!sameFace) continue;
          EXPECT_EQ(directedFaceArcs(configurationTable(pair, upper), axis, 0), expected)
              << where(pair, lower) << " below " << where(pair, upper) << " along axis " << axis;
        }
      }
    }
}

TEST(ConfigurationTables, Strict26IsOneTubeOfSixTriangles) {
  int strictCount = 0;
  forAllConfigurations([&](AdjacencyPair pair, int config, const CubeTriangulation& t) {
    const int p = strict26Corner(pair, config);
    if (p < 0) return;
    ++strictCount;
    const int q = 7 - p;
    std::set<Arc> expectedInner;  // A_i on [p, p + e_i], B_j on [q, q - e_j], i != j
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j) {
          int ai = cube::edgeBetween(p, p ^ (1 << i)), bj = cube::edgeBetween(q, q ^ (1 << j));
          expectedInner.insert({std::min(ai, bj), std::max(ai, bj)});
        }
    std::set<Arc> inner;
    for (auto& tri : t.allTriangles())
      for (int i = 0; i < 3; ++i) {
        int a = tri[i], b = tri[(i + 1) % 3];
        if (!shareCubeFace(a, b)) inner.insert({std::min(a, b), std::max(a, b)});
      }
    EXPECT_EQ(inner, expectedInner);
    EXPECT_EQ(t.triangleCount, 6);
    EXPECT_EQ(t.patchCount, 1);
  });
  EXPECT_EQ(strictCount, 8);  // 4 body diagonals, for (26,6) and (6,26)
}

// Each vertex is a surfel on the edge [p, q], p the 1-voxel, q the 0-voxel: every triangle's
// normal points from the 1-voxel to the 0-voxel of each of its three vertices.
TEST(ConfigurationTables, NormalsPointFromOneVoxelsToZeroVoxels) {
  forAllConfigurations([](AdjacencyPair, int config, const CubeTriangulation& t) {
    for (auto& tri : t.allTriangles()) {
      Point n = normalOf(tri);
      for (int k : tri)
        EXPECT_GT(dot(n, sub(corner2(zeroCorner(config, k)), corner2(oneCorner(config, k)))), 0)
            << "triangle " << int(tri[0]) << "," << int(tri[1]) << "," << int(tri[2]);
    }
  });
}

// Definition 9: every triangle spans a supporting plane of Conv(P u A(P)) touching it only in
// midpoints, P the kappa-component of its 1-voxels (kappa >= 18), or, for kappa = 6
// (Definition 28), of Conv(Q u A(Q)), Q the lambda-component of its 0-voxels.
TEST(ConfigurationTables, TrianglesLieOnSupportingPlanesOfTheLocalVolume) {
  forAllConfigurations([](AdjacencyPair pair, int config, const CubeTriangulation& t) {
    const int value = kappa(pair) == 6 ? 0 : 1;
    const int adjacency = value ? kappa(pair) : lambda(pair);
    auto innerCorner = [&](int k) { return value ? oneCorner(config, k) : zeroCorner(config, k); };
    for (auto& tri : t.allTriangles()) {
      const int comp = componentOf(config, value, adjacency, innerCorner(tri[0]));
      for (int k : tri) EXPECT_TRUE(comp >> innerCorner(k) & 1) << "vertices in different components";
      const Point n = normalOf(tri), a = mid2(tri[0]);
      const int sign = value ? 1 : -1;  // the local volume lies behind (value 1) / in front (value 0)
      for (int i = 0; i < 8; ++i) {
        if (!(comp >> i & 1)) continue;
        EXPECT_LT(sign * dot(n, sub(corner2(i), a)), 0) << "corner " << i;
        for (int axis = 0; axis < 3; ++axis)
          if (on(config, i ^ (1 << axis)) != bool(value)) {
            EXPECT_LE(sign * dot(n, sub(mid2(cube::edgeBetween(i, i ^ (1 << axis))), a)), 0);
          }
      }
    }
  });
}

// Patches: connected under edge sharing, vertex-disjoint, consistent with patchBegin and
// patchOfEdge. An ordinary patch is a disc whose boundary (its face edges) is one loop through
// all its l vertices, triangulated without inner vertices: l - 2 triangles. The strict-26
// tube is an annulus: 6 vertices, 12 edges, 6 triangles (Euler characteristic 0).
TEST(ConfigurationTables, PatchesAreTriangulatedLoops) {
  forAllConfigurations([](AdjacencyPair pair, int config, const CubeTriangulation& t) {
    ASSERT_LE(t.patchCount, CubeTriangulation::kMaxPatches);
    ASSERT_EQ(t.patchBegin[0], 0);
    for (int p = 0; p < t.patchCount; ++p) ASSERT_LT(t.patchBegin[p], t.patchBegin[p + 1]);
    ASSERT_EQ(t.patchBegin[t.patchCount], t.triangleCount);
    for (int k = 0; k < 12; ++k) EXPECT_EQ(t.patchOfEdge[k] >= 0, isCut(config, k));
    for (int p = 0; p < t.patchCount; ++p) {
      SCOPED_TRACE("patch " + std::to_string(p));
      auto tris = t.patchTriangles(p);
      std::set<int> vertices;
      std::set<Arc> edges, faceEdges;
      for (auto& tri : tris)
        for (int i = 0; i < 3; ++i) {
          int a = tri[i], b = tri[(i + 1) % 3];
          vertices.insert(a);
          EXPECT_EQ(t.patchOfEdge[a], p);
          edges.insert({std::min(a, b), std::max(a, b)});
          if (shareCubeFace(a, b)) faceEdges.insert({a, b});
        }
      // Connected under sharing an edge.
      std::vector<bool> reached(tris.size(), false);
      reached[0] = true;
      for (bool grew = true; grew;) {
        grew = false;
        for (std::size_t i = 0; i < tris.size(); ++i)
          for (std::size_t j = 0; j < tris.size(); ++j) {
            if (!reached[i] || reached[j]) continue;
            int common = 0;
            for (auto v : tris[i]) common += std::count(tris[j].begin(), tris[j].end(), v);
            if (common >= 2) reached[j] = grew = true;
          }
      }
      EXPECT_TRUE(std::all_of(reached.begin(), reached.end(), [](bool r) { return r; }));
      const int V = int(vertices.size()), E = int(edges.size()), F = int(tris.size());
      if (strict26Corner(pair, config) >= 0) {
        EXPECT_EQ(V, 6);
        EXPECT_EQ(E, 12);
        EXPECT_EQ(F, 6);
        continue;
      }
      EXPECT_EQ(V - E + F, 1);
      EXPECT_EQ(F, V - 2);
      // The face edges form a single directed cycle through all vertices.
      std::map<int, int> next;
      for (auto [a, b] : faceEdges) EXPECT_TRUE(next.emplace(a, b).second);
      ASSERT_EQ(int(next.size()), V);
      const int start = *vertices.begin();
      int v = start, steps = 0;
      do {
        v = next.count(v) ? next[v] : -1;
        ++steps;
      } while (v != start && v >= 0 && steps <= V);
      EXPECT_EQ(v, start);
      EXPECT_EQ(steps, V) << "the boundary of the patch is not one loop";
    }
  });
}

// Definition 28 and the influence of the adjacency (Figure 4): (6, lambda) is (lambda, 6) on
// the negative image with orientation reversed; (26,6) differs from (18,6) only on the strict
// 26-configurations of 1-voxels, (6,26) from (6,18) only on those of 0-voxels.
TEST(ConfigurationTables, DualityAndInfluenceOfTheAdjacency) {
  auto normalized = [](const CubeTriangulation& t, bool reverse) {
    std::set<std::array<std::uint8_t, 3>> out;
    for (auto tri : t.allTriangles()) {
      if (reverse) std::swap(tri[1], tri[2]);
      std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
      out.insert(tri);
    }
    return out;
  };
  using P = AdjacencyPair;
  for (int c = 0; c < 256; ++c) {
    SCOPED_TRACE(c);
    const std::uint8_t nc = std::uint8_t(~c);
    EXPECT_EQ(normalized(configurationTable(P::k6_18, c), false),
              normalized(configurationTable(P::k18_6, nc), true));
    EXPECT_EQ(normalized(configurationTable(P::k6_26, c), false),
              normalized(configurationTable(P::k26_6, nc), true));
    EXPECT_EQ(normalized(configurationTable(P::k26_6, c), false) ==
                  normalized(configurationTable(P::k18_6, c), false),
              strict26Corner(P::k26_6, c) < 0);
    EXPECT_EQ(normalized(configurationTable(P::k6_26, c), false) ==
                  normalized(configurationTable(P::k6_18, c), false),
              strict26Corner(P::k6_26, c) < 0);
  }
}

TEST(ConfigurationTables, KnownConfigurations) {
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    SCOPED_TRACE(toString(pair));
    auto count = [&](int c) {
      const auto& t = configurationTable(pair, std::uint8_t(c));
      return std::pair<int, int>(t.triangleCount, t.patchCount);
    };
    EXPECT_EQ(count(0x00), std::make_pair(0, 0));
    EXPECT_EQ(count(0xFF), std::make_pair(0, 0));
    EXPECT_EQ(count(0x01), std::make_pair(1, 1));  // one 1-voxel: a triangle
    EXPECT_EQ(count(0xFE), std::make_pair(1, 1));  // one 0-voxel
    EXPECT_EQ(count(0x03), std::make_pair(2, 1));  // two 6-adjacent voxels: a quad
    EXPECT_EQ(count(0x0F), std::make_pair(2, 1));  // a plane of 4 voxels: a quad
    EXPECT_EQ(count(0x69), std::make_pair(4, 4));  // checkerboard: 4 corner triangles
    EXPECT_EQ(count(0x81), pair == AdjacencyPair::k26_6 ? std::make_pair(6, 1) : std::make_pair(2, 2));
    EXPECT_EQ(count(0x7E), pair == AdjacencyPair::k6_26 ? std::make_pair(6, 1) : std::make_pair(2, 2));
    // The triangle of a single 1-voxel at corner 0 joins edges 0, 4, 8, facing away from it.
    auto tri = configurationTable(pair, 0x01).triangles[0];
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    EXPECT_EQ(tri, (std::array<std::uint8_t, 3>{0, 4, 8}));
  }
}

// The compiled-in tables (from the generated .inc) are exactly what the generator computes
// now: same bytes in memory and same generated source text.
TEST(ConfigurationTables, RegenerationGivesTheCompiledTable) {
  const ConfigurationTables computed = computeConfigurationTables();
  ConfigurationTables compiled{};
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (int c = 0; c < 256; ++c) {
      compiled[int(pair)][c] = configurationTable(pair, std::uint8_t(c));
      EXPECT_EQ(std::memcmp(&compiled[int(pair)][c], &computed[int(pair)][c], sizeof(CubeTriangulation)), 0)
          << where(pair, c);
    }
  EXPECT_EQ(configurationTablesSource(compiled), configurationTablesSource(computed));
}

}  // namespace
}  // namespace surftrack
