// Independent checks of triangle meshes for the tests: closed oriented 2-manifolds by counting,
// signed volumes and winding numbers, and the Euler characteristic of a kappa-component from
// its voxels alone (docs/theory.md, 'Euler characteristic and genus'), never from the engine's
// surfaces.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>
#include <vector>

#include "ClosedManifold.h"
#include "DigitalCube.h"
#include "TriangleMesh.h"
#include "VoxelComponents.h"

namespace surftrack::testing {

using Point = std::array<double, 3>;

// ---------------------------------------------------------------------------------------------
// Combinatorial checks on an indexed mesh.

/// Closed, consistently oriented 2-manifold whose vertex set is exactly `boundaryKeys`:
///  - every triangle has 3 distinct vertices, no triangle is repeated;
///  - every directed edge is used once and its reverse once (each undirected edge by exactly two
///    triangles, in opposite directions);
///  - the star of every vertex is one disc: its triangles (v, a, b) chain a -> b into one cycle;
///  - the surfels are the boundary's, each once, every vertex used.
/// On success `euler` is V - E + F.
inline ::testing::AssertionResult isClosedManifoldOn(const TriangleMesh& mesh,
                                              const std::vector<std::uint64_t>& boundaryKeys,
                                              long* euler = nullptr) {
  const std::size_t V = mesh.surfels.size();
  std::vector<std::uint64_t> keys = sortedKeys(mesh.surfels);
  if (std::adjacent_find(keys.begin(), keys.end()) != keys.end())
    return ::testing::AssertionFailure() << "a surfel is two vertices";
  if (keys != boundaryKeys)
    return ::testing::AssertionFailure() << "vertex set (" << V << ") differs from the boundary ("
                                         << boundaryKeys.size() << " surfels)";
  const checks::Topology topology = checks::topologyOf(V, mesh.triangles);
  if (!topology.manifoldVertices) return ::testing::AssertionFailure() << topology.problem;
  std::vector<char> used(V, 0);
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t) used[v] = 1;
  for (std::uint32_t v = 0; v < V; ++v)
    if (!used[v]) return ::testing::AssertionFailure() << "vertex " << v << " (" << mesh.surfels[v] << ") is unused";
  if (euler) *euler = long(topology.euler);
  return ::testing::AssertionSuccess();
}

// ---------------------------------------------------------------------------------------------
// Geometry: signed volume and winding numbers.

inline double signedVolume(const TriangleMesh& mesh, const std::vector<Point>& p) {
  double volume = 0;
  for (const auto& t : mesh.triangles) {
    const Point &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
    volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return volume / 6;
}

/// Sum of the signed solid angles of the triangles seen from q, over 4 pi (Van Oosterom and
/// Strackee): +1 inside a closed surface oriented outward, 0 outside.
inline double windingNumber(const TriangleMesh& mesh, const std::vector<Point>& p, const Point& q) {
  double total = 0;
  for (const auto& t : mesh.triangles) {
    Point v[3];
    double len[3];
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) v[j][k] = p[t[j]][k] - q[k];
      len[j] = std::sqrt(v[j][0] * v[j][0] + v[j][1] * v[j][1] + v[j][2] * v[j][2]);
    }
    auto dot = [](const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const double det = v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1]) -
                       v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0]) +
                       v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
    const double den = len[0] * len[1] * len[2] + dot(v[0], v[1]) * len[2] +
                       dot(v[0], v[2]) * len[1] + dot(v[1], v[2]) * len[0];
    total += 2 * std::atan2(det, den);
  }
  return total / (4 * std::numbers::pi);
}

// ---------------------------------------------------------------------------------------------
// Euler characteristic of a kappa-component O, from its voxels only (docs/theory.md, 'Euler
// characteristic and genus').

/// kappa = 26: the union of the closed unit cubes centred at O's voxels. In doubled coordinates
/// its cells are the points 2v + {-1,0,1}^3; a cell's dimension is its number of even coordinates.
/// kappa = 6: the cubical complex whose cells are the boxes v + {0,1}^S (S a set of axes) with all
/// 2^|S| voxels in O: vertices, 6-adjacent pairs, 2x2 squares, 2x2x2 cubes.
/// The pairs 18-6 and 6-18 differ from 26-6 and 6-26 only in the strict 26-configurations
/// (Def. 38 (iv)): the only 2x2x2 blocks whose 1-voxels (0-voxels) are two kappa-components
/// (lambda-components) when kappa = 18 (lambda = 18). There the 26-6 complex joins the two
/// corner cubes at one point, which the 18-6 solid splits: chi grows by 1 per such block with
/// both corners in O (chi(A u B) = chi(A) + chi(B) - chi(point)). And the 6-26 complex has an
/// empty hexagon of six 6-adjacent voxels around the two 0-corners linked through the cube,
/// which the 6-18 solid fills with a disc: chi grows by 1 per such block with its six 1-voxels
/// in O.
inline long voxelEuler(const std::vector<Voxel>& O, const VoxelComponents& voxels, int component,
                AdjacencyPair pair) {
  auto inO = [&](Voxel v) { return voxels.value(v) && voxels.component(v) == component; };
  long chi = 0;
  if (kappa(pair) != 6) {
    std::vector<std::uint64_t> cells;
    for (const Voxel& v : O)
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            cells.push_back(Surfel{Voxel{2 * v.x + dx, 2 * v.y + dy, 2 * v.z + dz}, 0}.key());
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    for (std::uint64_t k : cells) {
      const Voxel c = Surfel::fromKey(k).c;
      const int even = (c.x % 2 == 0) + (c.y % 2 == 0) + (c.z % 2 == 0);
      chi += (even % 2 == 0) ? 1 : -1;
    }
  } else {
    for (const Voxel& v : O)
      for (int axes = 0; axes < 8; ++axes) {
        bool all = true;
        for (int corner = 0; corner < 8 && all; ++corner)
          if ((corner & ~axes) == 0) all = inO(v + cube::cornerOffset(corner));
        if (all) chi += (std::popcount(unsigned(axes)) % 2 == 0) ? 1 : -1;
      }
  }
  if (pair == AdjacencyPair::k18_6 || pair == AdjacencyPair::k6_18) {
    // Blocks with a corner in O: min corners O - {0,1}^3.
    std::vector<std::uint64_t> blocks;
    for (const Voxel& v : O)
      for (int corner = 0; corner < 8; ++corner) blocks.push_back(Surfel{v - cube::cornerOffset(corner), 0}.key());
    std::sort(blocks.begin(), blocks.end());
    blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
    for (std::uint64_t k : blocks) {
      const Voxel m = Surfel::fromKey(k).c;
      int inside = 0;
      std::uint8_t config = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const Voxel w = m + cube::cornerOffset(corner);
        const bool one = voxels.value(w);
        config |= std::uint8_t(one << corner);
        inside += one && inO(w);
      }
      for (int i = 0; i < 4; ++i) {
        const std::uint8_t diagonal = std::uint8_t((1u << i) | (1u << (7 - i)));
        if (pair == AdjacencyPair::k18_6 && config == diagonal && inside == 2) ++chi;
        if (pair == AdjacencyPair::k6_18 && config == std::uint8_t(~diagonal) && inside == 6) ++chi;
      }
    }
  }
  return chi;
}

}  // namespace surftrack::testing
