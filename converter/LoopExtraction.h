// From the surface graph of a kappa-lambda-boundary to its triangulated continuous analog
// (paper §5.2, the loop algorithm printed after Proposition 39, extended to the strict-26
// configurations as the paper suggests). Inside each of the 4 digital 3-cubes around a surfel,
// the beta-arcs of the surface graph form a loop (or, in a strict 26-configuration, the
// 6-surfel tube); the configuration table (§5.1) gives its triangles as cube edges, and the
// loop's arcs give the graph vertex on each of those edges. Each (surfel, cube) pair carries a
// flag, so each patch is emitted exactly once.
//
// Cost: O(1) per (surfel, cube) — a configuration from the brick cache, a table look-up, a
// walk over at most 6 surfels' arcs — hence O(|Sigma|) overall. Nothing is sized by the volume and no surfel is
// ever searched for: vertices are resolved through the arcs.
#pragma once

#include <array>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "BinaryBrickCache.h"
#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "SurfaceGraph.h"
#include "TriangleMesh.h"

namespace surftrack {

namespace detail {

/// Index q of the cube with min corner m in cube::cubesOf(s) (m must contain s's edge).
inline int cubeSlot(const Surfel& s, Voxel m) {
  const std::array<Voxel, 4> cubes = cube::cubesOf(s);
  for (int q = 0; q < 4; ++q)
    if (cubes[q] == m) return q;
  return -1;
}

[[noreturn]] inline void throwUnreachable(const Surfel& t, Voxel m, int edge) {
  std::ostringstream msg;
  msg << "extractLoops: the surface graph does not match the image: in the digital 3-cube with "
         "min corner "
      << m << ", the surfel on cube edge " << edge << " of the patch of " << t
      << " is not a boundary surfel of the image or is not reached through the graph's arcs";
  throw std::logic_error(msg.str());
}

}  // namespace detail

/// The kappa-lambda-continuous analog of the boundary whose surface graph is `graph`, tracked in
/// `image` with pair `graph.pair`, as an indexed mesh: vertex v is graph vertex v (same surfel,
/// same order); triangles are oriented from the 1-voxels to the 0-voxels (§5.1).
/// Throws std::logic_error if the graph does not match the image (a loop surfel that the
/// arcs do not reach, or a vertex that is not a boundary surfel of the image).
template <class BinaryImage>
TriangleMesh extractLoops(const BinaryImage& image, const SurfaceGraph& graph) {
  const std::vector<Surfel>& surfels = graph.surfels;
  TriangleMesh mesh;
  mesh.surfels = surfels;
  mesh.triangles.reserve(2 * surfels.size());
  // flags[v] bit q: the patch of surfel v in cube cubesOf(surfels[v])[q] has been emitted.
  std::vector<std::uint8_t> flags(surfels.size(), 0);

  // The 4 cubes around a surfel lie in the 3x3x3 neighbourhood of its 1-voxel: read them from
  // the tracker's brick cache rather than voxel by voxel from the image.
  BinaryBrickCache<BinaryImage> cache(image);
  for (std::uint32_t v = 0; v < surfels.size(); ++v) {
    const Surfel& t = surfels[v];
    if (flags[v] == 0xF) continue;
    const std::array<Voxel, 4> cubes = cube::cubesOf(t);
    const Neighbourhood around = cache.neighbourhood(t.inside());
    for (int q = 0; q < 4; ++q) {
      if (flags[v] & (1u << q)) continue;
      const Voxel m = cubes[q];
      const std::uint8_t config = cube::configurationAt(around, m);
      const CubeTriangulation& table = configurationTable(graph.pair, config);
      const int edge = cube::edgeOf(m, t);  // in 0..11: m is one of t's cubes
      const int patch = edge < 0 ? -1 : table.patchOfEdge[edge];
      if (patch < 0 || cube::surfelOnEdge(m, edge, config) != t) detail::throwUnreachable(t, m, edge);

      // Resolve the graph vertex on each cube edge of the patch by walking the arcs of the
      // vertices found so far that stay on edges of this patch in this cube (the loop is a
      // cycle of face arcs; the strict-26 tube is connected through its vertex links).
      std::array<std::int64_t, cube::kEdges> vertexOnEdge;
      vertexOnEdge.fill(-1);
      std::array<std::uint32_t, cube::kEdges> found{};
      int foundCount = 0;
      vertexOnEdge[edge] = v;
      found[foundCount++] = v;
      for (int i = 0; i < foundCount; ++i) {
        for (auto [a, end] = boost::adjacent_vertices(found[i], graph.graph); a != end; ++a) {
          const std::uint32_t w = *a;
          const int k = cube::edgeOf(m, surfels[w]);
          if (k < 0 || table.patchOfEdge[k] != patch || vertexOnEdge[k] >= 0) continue;
          if (cube::surfelOnEdge(m, k, config) != surfels[w]) detail::throwUnreachable(t, m, k);
          vertexOnEdge[k] = w;
          found[foundCount++] = w;
        }
      }

      for (const auto& tri : table.patchTriangles(patch)) {
        std::array<std::uint32_t, 3> out{};
        for (int j = 0; j < 3; ++j) {
          if (vertexOnEdge[tri[j]] < 0) detail::throwUnreachable(t, m, tri[j]);
          out[j] = std::uint32_t(vertexOnEdge[tri[j]]);
        }
        mesh.triangles.push_back(out);
      }
      for (int i = 0; i < foundCount; ++i)
        flags[found[i]] |= std::uint8_t(1u << detail::cubeSlot(surfels[found[i]], m));
    }
  }
  return mesh;
}

}  // namespace surftrack
