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

/// Index q of the cube with min corner m among cube::cubesOf(s) (m must contain s's edge): bit 0
/// is set when the cube extends towards -b from s's edge, bit 1 towards -c (b < c the two axes
/// orthogonal to s's normal).
inline int cubeSlot(const Surfel& s, Voxel m) {
  const auto [b, c] = cube::otherAxes(axisOf(s.n));
  return (s.inside()[b] != m[b] ? 1 : 0) | (s.inside()[c] != m[c] ? 2 : 0);
}

[[noreturn]] inline void throwUnreachable(const Surfel& t, Voxel m, int edge) {
  std::ostringstream msg;
  msg << "extractLoops: the surface graph does not match the image: from " << t
      << ", the loop of the digital 3-cube with min corner " << m << " misses cube edge " << edge;
  throw std::logic_error(msg.str());
}

/// The graph vertices on the cube edges of one patch of one cube.
struct PatchVertices {
  std::array<std::int64_t, cube::kEdges> onEdge;
  std::array<std::uint32_t, cube::kEdges> found{};
  int count = 0;
  PatchVertices() { onEdge.fill(-1); }
  void add(int edge, std::uint32_t v) {
    onEdge[edge] = v;
    found[count++] = v;
  }
};

/// A loop (§5.2): from vertex v, follow the two face arcs each surfel has inside the cube (the
/// edge neighbours towards the cube's two faces through the surfel's edge) until back at v.
/// False if the walk does not close on the patch's cube edges.
inline bool walkLoop(const SurfaceGraph& graph, Voxel m, std::uint8_t config, int patch,
                     const CubeTriangulation& table, std::uint32_t v, PatchVertices& out) {
  std::uint32_t previous = v, current = v;
  do {
    const Surfel& s = graph.surfels[current];
    const int edge = cube::edgeOf(m, s);
    if (edge < 0 || table.patchOfEdge[edge] != patch || out.onEdge[edge] >= 0 ||
        cube::surfelOnEdge(m, edge, config) != s)
      return false;
    out.add(edge, current);
    const int q = cubeSlot(s, m);
    auto arcs = boost::adjacent_vertices(current, graph.graph).first;
    const std::uint32_t a = arcs[q & 1], b = arcs[2 + (q >> 1)];
    const std::uint32_t next = (a != previous || previous == current) ? a : b;
    previous = current;
    current = next;
  } while (current != v && out.count < cube::kEdges);
  return current == v;
}

/// Any patch, the strict-26 tube included: breadth-first over all arcs that stay on the patch's
/// cube edges (the tube is connected through its vertex links).
inline void walkPatch(const SurfaceGraph& graph, Voxel m, std::uint8_t config, int patch,
                      const CubeTriangulation& table, std::uint32_t v, PatchVertices& out) {
  out = PatchVertices{};
  out.add(cube::edgeOf(m, graph.surfels[v]), v);
  for (int i = 0; i < out.count; ++i)
    for (auto [a, end] = boost::adjacent_vertices(out.found[i], graph.graph); a != end; ++a) {
      const Surfel& s = graph.surfels[*a];
      const int k = cube::edgeOf(m, s);
      if (k < 0 || table.patchOfEdge[k] != patch || out.onEdge[k] >= 0) continue;
      if (cube::surfelOnEdge(m, k, config) != s) throwUnreachable(graph.surfels[v], m, k);
      out.add(k, *a);
    }
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
  detail::PatchVertices patchVertices;

  for (std::uint32_t v = 0; v < surfels.size(); ++v) {
    if (flags[v] == 0xF) continue;
    const Surfel& t = surfels[v];
    const std::array<Voxel, 4> cubes = cube::cubesOf(t);
    const Neighbourhood around = cache.neighbourhood(t.inside());
    for (int q = 0; q < 4; ++q) {
      if (flags[v] & (1u << q)) continue;
      const Voxel m = cubes[q];
      const std::uint8_t config = cube::configurationAt(around, m);
      const CubeTriangulation& table = configurationTable(graph.pair, config);
      const int edge = cube::edgeOf(m, t);
      const int patch = edge < 0 ? -1 : table.patchOfEdge[edge];  // edge >= 0: m is one of t's cubes
      if (patch < 0 || cube::surfelOnEdge(m, edge, config) != t) detail::throwUnreachable(t, m, edge);

      // A loop of l surfels has l - 2 triangles; anything else is the strict-26 tube.
      const auto triangles = table.patchTriangles(patch);
      patchVertices = detail::PatchVertices{};
      if (!detail::walkLoop(graph, m, config, patch, table, v, patchVertices) ||
          std::size_t(patchVertices.count) != triangles.size() + 2)
        detail::walkPatch(graph, m, config, patch, table, v, patchVertices);

      for (const auto& tri : triangles) {
        std::array<std::uint32_t, 3> out{};
        for (int j = 0; j < 3; ++j) {
          if (patchVertices.onEdge[tri[j]] < 0) detail::throwUnreachable(t, m, tri[j]);
          out[j] = std::uint32_t(patchVertices.onEdge[tri[j]]);
        }
        mesh.triangles.push_back(out);
      }
      for (int i = 0; i < patchVertices.count; ++i) {
        const std::uint32_t w = patchVertices.found[i];
        flags[w] |= std::uint8_t(1u << detail::cubeSlot(surfels[w], m));
      }
    }
  }
  return mesh;
}

}  // namespace surftrack
