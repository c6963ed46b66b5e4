// Definition 9 in one digital 3-cube (see LocalConvexVolume.h).
//
// Coordinates are doubled: corner i is 2 * cornerOffset(i), the midpoint of edge k is
// cornerOffset(low) + cornerOffset(high); all hull tests are then exact integer arithmetic.
// Every point of P u A(P) is an extreme point of the hull (a corner is a vertex of the cube;
// a midpoint is the end of the hull's trace on its cube edge, whose other end is a 0-voxel),
// so no three of them are collinear and the points lying on a supporting plane are exactly
// the vertices of that hull face.
#include "LocalConvexVolume.h"

#include <algorithm>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "DigitalCube.h"
#include "Voxel.h"

namespace surftrack {
namespace {

using Point = std::array<int, 3>;
using Triangle = std::array<std::uint8_t, 3>;

Point operator-(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point cross(const Point& a, const Point& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
int dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Point doubledCorner(int i) {
  Voxel v = cube::cornerOffset(i);
  return {2 * v.x, 2 * v.y, 2 * v.z};
}
Point doubledMidpoint(int k) {
  Voxel v = cube::cornerOffset(cube::edgeLowCorner(k)) + cube::cornerOffset(cube::edgeHighCorner(k));
  return {v.x, v.y, v.z};
}

struct HullPoint {
  Point p;
  int edge;  // cube edge of a midpoint, -1 for a voxel of P
};

// Orders the vertices of a convex face counter-clockwise seen from the side `normal` points
// to (gift wrapping: the next vertex leaves every other one on its left), starting at the
// vertex of smallest edge index.
std::vector<HullPoint> orderAroundFace(std::vector<HullPoint> face, const Point& normal) {
  std::iter_swap(face.begin(), std::min_element(face.begin(), face.end(), [](auto& a, auto& b) {
                   return a.edge < b.edge;
                 }));
  for (std::size_t i = 1; i < face.size(); ++i) {
    const Point& a = face[i - 1].p;
    auto isNext = [&](const HullPoint& b) {
      for (const HullPoint& w : face) {
        if (w.edge == b.edge || w.p == a) continue;
        int side = dot(cross(b.p - a, w.p - a), normal);
        if (side == 0) throw std::logic_error("collinear points on a local convex volume face");
        if (side < 0) return false;
      }
      return true;
    };
    auto next = std::find_if(face.begin() + i, face.end(), isNext);
    if (next == face.end()) throw std::logic_error("face ordering failed");
    std::iter_swap(face.begin() + i, next);
  }
  return face;
}

// Appends the faces of Conv(points) whose vertices are all midpoints, as outward triangles:
// brute force over the triples, a triple spans a face iff all points lie on one side of its
// plane. Planar faces with more than 3 vertices become a fan from the smallest edge index.
void appendMidpointFaces(const std::vector<HullPoint>& points, std::vector<Triangle>& out) {
  const int n = int(points.size());
  std::vector<std::uint32_t> seen;  // faces already emitted, as bit sets of point indices
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) {
        const Point& a = points[i].p;
        Point normal = cross(points[j].p - a, points[k].p - a);
        if (normal == Point{0, 0, 0}) throw std::logic_error("collinear hull points");
        std::uint32_t onPlane = 0;
        bool above = false, below = false;
        for (int m = 0; m < n; ++m) {
          int s = dot(normal, points[m].p - a);
          above |= s > 0;
          below |= s < 0;
          if (s == 0) onPlane |= 1u << m;
        }
        if (above && below) continue;  // not a supporting plane
        if (above) normal = Point{-normal[0], -normal[1], -normal[2]};  // make it outward
        if (std::find(seen.begin(), seen.end(), onPlane) != seen.end()) continue;
        seen.push_back(onPlane);
        std::vector<HullPoint> face;
        for (int m = 0; m < n; ++m)
          if (onPlane >> m & 1) face.push_back(points[m]);
        if (std::any_of(face.begin(), face.end(), [](auto& q) { return q.edge < 0; })) continue;
        face = orderAroundFace(std::move(face), normal);
        for (std::size_t f = 1; f + 1 < face.size(); ++f)
          out.push_back({std::uint8_t(face[0].edge), std::uint8_t(face[f].edge),
                         std::uint8_t(face[f + 1].edge)});
      }
}

// The kappa-components of the 1-corners of the cube, as bit sets of corners.
std::vector<std::uint8_t> components(int adjacency, std::uint8_t config) {
  std::vector<std::uint8_t> out;
  std::uint8_t left = config;
  while (left) {
    std::uint8_t comp = left & -left, grown = 0;
    while (grown != comp) {
      grown = comp;
      for (int i = 0; i < cube::kCorners; ++i)
        for (int j = 0; j < cube::kCorners; ++j)
          if ((comp >> i & 1) && (config >> j & 1) &&
              areAdjacent(adjacency, cube::cornerOffset(i), cube::cornerOffset(j)))
            comp |= std::uint8_t(1u << j);
    }
    out.push_back(comp);
    left &= ~comp;
  }
  return out;
}

// Groups triangles into patches (connected under sharing an edge), patches ordered by their
// smallest edge index, triangles in their original order within a patch.
CubeTriangulation groupIntoPatches(const std::vector<Triangle>& tris) {
  const int n = int(tris.size());
  if (n > CubeTriangulation::kMaxTriangles) throw std::logic_error("kMaxTriangles exceeded");
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto shareEdge = [](const Triangle& s, const Triangle& t) {
    int common = 0;
    for (auto a : s) common += std::count(t.begin(), t.end(), a);
    return common >= 2;
  };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (shareEdge(tris[i], tris[j])) parent[find(i)] = find(j);
  std::vector<int> minEdge(n, 99), roots;
  for (int i = 0; i < n; ++i) {
    int r = find(i);
    minEdge[r] = std::min<int>(minEdge[r], *std::min_element(tris[i].begin(), tris[i].end()));
    if (r == i) roots.push_back(r);
  }
  std::sort(roots.begin(), roots.end(), [&](int a, int b) { return minEdge[a] < minEdge[b]; });
  if (int(roots.size()) > CubeTriangulation::kMaxPatches) throw std::logic_error("kMaxPatches exceeded");

  CubeTriangulation t;
  t.patchOfEdge.fill(-1);
  for (int p = 0; p < int(roots.size()); ++p) {
    t.patchBegin[p] = t.triangleCount;
    for (int i = 0; i < n; ++i) {
      if (find(i) != roots[p]) continue;
      t.triangles[t.triangleCount++] = tris[i];
      for (auto e : tris[i]) t.patchOfEdge[e] = std::int8_t(p);
    }
  }
  t.patchCount = std::uint8_t(roots.size());
  for (int p = t.patchCount; p <= CubeTriangulation::kMaxPatches; ++p) t.patchBegin[p] = t.triangleCount;
  return t;
}

}  // namespace

CubeTriangulation computeCubeTriangulation(AdjacencyPair pair, std::uint8_t config) {
  if (kappa(pair) == 6) {
    // Definition 28: the kappa-lambda analog of I is the lambda-kappa analog of the negative
    // image; its 1-voxels are our 0-voxels, so the orientation is reversed.
    AdjacencyPair dual = lambda(pair) == 18 ? AdjacencyPair::k18_6 : AdjacencyPair::k26_6;
    CubeTriangulation t = computeCubeTriangulation(dual, std::uint8_t(~config));
    for (auto& tri : t.triangles) std::swap(tri[1], tri[2]);
    return t;
  }
  std::vector<Triangle> tris;
  for (std::uint8_t comp : components(kappa(pair), config)) {
    // Definition 9: Conv(P u A(P)), A(P) the midpoints of the edges from P to 0-voxels.
    std::vector<HullPoint> points;
    for (int i = 0; i < cube::kCorners; ++i) {
      if (!(comp >> i & 1)) continue;
      points.push_back({doubledCorner(i), -1});
      for (int axis = 0; axis < 3; ++axis) {
        int j = i ^ (1 << axis);
        if (!(config >> j & 1)) {
          int k = cube::edgeBetween(i, j);
          points.push_back({doubledMidpoint(k), k});
        }
      }
    }
    appendMidpointFaces(points, tris);
  }
  return groupIntoPatches(tris);
}

ConfigurationTables computeConfigurationTables() {
  ConfigurationTables tables{};
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (int config = 0; config < 256; ++config)
      tables[int(pair)][config] = computeCubeTriangulation(pair, std::uint8_t(config));
  return tables;
}

std::string configurationTablesSource(const ConfigurationTables& tables) {
  std::ostringstream os;
  os << "// Generated by tools/generate_configuration_tables.cpp from lib/LocalConvexVolume.cpp\n"
        "// (Definition 9, paper 5.1). Do not edit. One CubeTriangulation per configuration:\n"
        "// {triangleCount, patchCount, {{triangles}}, {{patchBegin}}, {{patchOfEdge}}}\n";
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    os << "{{  // " << toString(pair) << "\n";
    for (int config = 0; config < 256; ++config) {
      const CubeTriangulation& t = tables[int(pair)][config];
      os << "  {" << int(t.triangleCount) << ", " << int(t.patchCount) << ", {{";
      for (int i = 0; i < t.triangleCount; ++i)
        os << (i ? ", " : "") << "{{" << int(t.triangles[i][0]) << ", " << int(t.triangles[i][1])
           << ", " << int(t.triangles[i][2]) << "}}";
      os << "}}, {{";
      for (std::size_t p = 0; p < t.patchBegin.size(); ++p) os << (p ? ", " : "") << int(t.patchBegin[p]);
      os << "}}, {{";
      for (int k = 0; k < cube::kEdges; ++k) os << (k ? ", " : "") << int(t.patchOfEdge[k]);
      os << "}}},  // 0x" << "0123456789abcdef"[config >> 4] << "0123456789abcdef"[config & 15] << "\n";
    }
    os << "}},\n";
  }
  return os.str();
}

}  // namespace surftrack
