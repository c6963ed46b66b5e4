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

#include <algorithm>
#include <array>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "BinaryBrickCache.h"
#include "ConfigurationTable.h"
#include "CubeLoops.h"
#include "DigitalCube.h"
#include "HugePages.h"
#include "SurfaceGraph.h"
#include "TriangleMesh.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace surftrack {

namespace detail {

[[noreturn]] inline void throwUnreachable(const Surfel& t, Voxel m, int edge) {
  std::ostringstream msg;
  msg << "extractLoops: the surface graph does not match the image: from " << t
      << ", the loop of the digital 3-cube with min corner " << m << " misses cube edge " << edge;
  throw std::logic_error(msg.str());
}

/// The graph vertices on the cube edges of one patch of one cube.
struct PatchVertices {
  std::array<std::int32_t, cube::kEdges> onEdge;
  std::array<std::uint32_t, cube::kEdges> found;
  std::array<std::uint8_t, cube::kEdges> edgeOfFound;
  int count = 0;
  PatchVertices() { onEdge.fill(-1); }
  void add(int edge, std::uint32_t v) {
    onEdge[edge] = std::int32_t(v);
    edgeOfFound[count] = std::uint8_t(edge);
    found[count++] = v;
  }
};

/// A loop (§5.2): from vertex v on the loop's cube edge at position `start`, around the patch
/// in the order of its CubeLoop, taking at each surfel the out-arc that leads to the next edge;
/// byPosition[i] is the vertex at loop position i. False if a vertex reached is not the surfel
/// its cube edge must carry or the walk does not close: the caller then searches the patch and
/// reports the mismatch.
inline bool walkLoop(const SurfaceGraph& graph, Voxel m, const std::array<EdgeSurfel, cube::kEdges>& onEdges,
                     const CubeLoop& loop, int start, std::uint32_t v,
                     std::array<std::uint32_t, cube::kEdges>& byPosition) {
  const int length = loop.length;
  const auto& rowStart = graph.graph.m_forward.m_rowstart;
  const auto& column = graph.graph.m_forward.m_column;
  std::uint32_t current = v;
  bool matches = true;
  for (int step = 0, i = start; step < length; ++step, i = i + 1 == length ? 0 : i + 1) {
    const EdgeSurfel& expected = onEdges[loop.edge[i]];
    const Surfel& s = graph.surfels[current];
    matches &= (s.c.x == m.x + expected.inside.x) & (s.c.y == m.y + expected.inside.y) &
               (s.c.z == m.z + expected.inside.z) & (s.n == expected.n);
    byPosition[i] = current;
    current = column[rowStart[current] + loop.arc[i]];
  }
  return matches && current == v;
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

/// The loop algorithm over vertices [begin, end), reading cube configurations from `bricks`;
/// findBrick(bx, by, bz) gives the index in `bricks` of the brick of voxels 8 (bx, by, bz) +
/// [0, 8)^3 (binarising it if need be) or throws. Each patch belongs to its first vertex (the
/// smallest index among its surfels): the patches of the vertices of the range are appended to
/// `triangles` in the order of their first vertex, then of its 4 cubes — the order of one walk
/// over all vertices, so that ranges walked apart and joined in order give the same mesh.
/// flags[v] bit q: the patch of surfel v in cube cubesOf(surfels[v])[q] has been walked; only
/// the flags of the range are read and written.
template <class FindBrick>
void extractLoopsOf(const SurfaceGraph& graph, const BinaryBricks& bricks, FindBrick&& findBrick, std::uint32_t begin,
                    std::uint32_t end, std::uint8_t* flags, std::vector<std::array<std::uint32_t, 3>>& triangles) {
  const std::vector<Surfel>& surfels = graph.surfels;
  const auto tables = configurationTables(graph.pair);
  const CubeLoops& loops = cubeLoops(graph.pair);
  const EdgeSurfels& onEdges = edgeSurfels();
  auto inRange = [&](std::uint32_t u) { return u >= begin && u < end; };
  // The 4 cubes around a surfel lie in the 3x3x3 neighbourhood of its 1-voxel, which its brick
  // holds. Tracked graphs number their vertices brick by brick, so the brick of the last
  // surfel is almost always the brick of the next one: remember it rather than look it up.
  Voxel lastBrick{1 << 30, 0, 0};
  std::uint32_t brick = 0;

  for (std::uint32_t v = begin; v < end; ++v) {
    if (flags[v] == 0xF) continue;
    const Surfel& t = surfels[v];
    const Voxel brickOfT{t.c.x >> 3, t.c.y >> 3, t.c.z >> 3};
    if (brickOfT != lastBrick) [[unlikely]] {
      brick = findBrick(brickOfT.x, brickOfT.y, brickOfT.z);
      lastBrick = brickOfT;
    }
    const Neighbourhood around = bricks.neighbourhood(brick, t.c);
    for (int q = 0; q < 4; ++q) {
      if (flags[v] & (1u << q)) continue;
      const auto [offset, edge] = cube::kCubesAroundSurfel[t.n][q];
      const Voxel m = t.c + offset;
      const std::uint8_t config = around.cubeConfiguration(offset);
      const CubeTriangulation& table = tables[config];
      const int patch = table.patchOfEdge[edge];
      if (patch < 0) throwUnreachable(t, m, edge);

      // A loop (almost always): walk it and emit its triangles by loop position.
      const CubeLoop& loop = loops[config][patch];
      std::array<std::uint32_t, cube::kEdges> byPosition;
      if (loop.length != 0 &&
          walkLoop(graph, m, onEdges[config], loop, loop.positionOf[edge], v, byPosition)) {
        std::uint32_t first = v;
        for (int i = 0; i < loop.length; ++i) {
          first = std::min(first, byPosition[i]);
          if (inRange(byPosition[i])) flags[byPosition[i]] |= std::uint8_t(1u << loop.cubeSlot[i]);
        }
        if (first == v)
          for (int i = 0; i < loop.triangleCount; ++i) {
            const auto& tri = loop.triangles[i];
            triangles.push_back({byPosition[tri[0]], byPosition[tri[1]], byPosition[tri[2]]});
          }
        continue;
      }

      // The strict-26 tube, or a graph that does not match the image (which this reports).
      PatchVertices patchVertices;
      walkPatch(graph, m, config, patch, table, v, patchVertices);
      std::uint32_t first = v;
      for (int i = 0; i < patchVertices.count; ++i) {
        const std::uint32_t u = patchVertices.found[i];
        first = std::min(first, u);
        if (inRange(u)) flags[u] |= std::uint8_t(1u << onEdges[config][patchVertices.edgeOfFound[i]].cubeSlot);
      }
      for (const auto& tri : table.patchTriangles(patch)) {
        const std::int32_t a = patchVertices.onEdge[tri[0]], b = patchVertices.onEdge[tri[1]],
                           c = patchVertices.onEdge[tri[2]];
        if ((a | b | c) < 0) throwUnreachable(t, m, a < 0 ? tri[0] : b < 0 ? tri[1] : tri[2]);
        if (first == v) triangles.push_back({std::uint32_t(a), std::uint32_t(b), std::uint32_t(c)});
      }
    }
  }
}

/// The loop algorithm over all vertices (extractLoopsOf), on `threads` threads (0: all cores)
/// when findBrick may be called from several at once: runs of vertices walked apart, their
/// triangles joined in order. The mesh is the same for any number of threads.
template <class FindBrick>
TriangleMesh extractLoops(const SurfaceGraph& graph, const BinaryBricks& bricks, FindBrick&& findBrick,
                          int threads = 1) {
  const std::vector<Surfel>& surfels = graph.surfels;
  const std::uint32_t n = std::uint32_t(surfels.size());
  TriangleMesh mesh;
  reserveHugePages(mesh.surfels, surfels.size());
  mesh.surfels.assign(surfels.begin(), surfels.end());
  std::vector<std::uint8_t> flags(surfels.size(), 0);
  // Runs of up to 2^14 vertices, about 64 runs at least; left to choose (0), small surfaces
  // stay on this thread (waking threads would cost more).
  const std::uint32_t kRun = std::clamp<std::uint32_t>(n / 64, 64, 1u << 14);
  if (n == 0 || threads == 1 || (threads == 0 && n < (1u << 16))) {
    reserveHugePages(mesh.triangles, 2 * surfels.size() + 16);
    extractLoopsOf(graph, bricks, findBrick, 0, n, flags.data(), mesh.triangles);
    return mesh;
  }
  const std::size_t runs = (n + kRun - 1) / kRun;
  std::vector<std::vector<std::array<std::uint32_t, 3>>> parts(runs);
  std::vector<std::size_t> start(runs + 1, 0);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), runs, [&](std::size_t r) {
      const std::uint32_t begin = std::uint32_t(r * kRun), end = std::min(n, begin + kRun);
      parts[r].reserve(2 * std::size_t(end - begin) + 16);
      extractLoopsOf(graph, bricks, findBrick, begin, end, flags.data(), parts[r]);
    });
  });
  for (std::size_t r = 0; r < runs; ++r) start[r + 1] = start[r] + parts[r].size();
  resizeHugePages(mesh.triangles, start[runs]);
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), runs, [&](std::size_t r) {
      std::copy(parts[r].begin(), parts[r].end(), mesh.triangles.begin() + std::ptrdiff_t(start[r]));
      parts[r] = {};
    });
  });
  return mesh;
}

}  // namespace detail

/// The kappa-lambda-continuous analog of the boundary whose surface graph is `graph`, tracked in
/// `image` with pair `graph.pair`, as an indexed mesh: vertex v is graph vertex v (same surfel,
/// same order); triangles are oriented from the 1-voxels to the 0-voxels (§5.1). The cube
/// configurations are read from `image`, so this also checks that the graph is a boundary of
/// it: throws std::logic_error if not (a loop surfel that the arcs do not reach, or a vertex
/// that is not a boundary surfel of the image).
template <class BinaryImage>
TriangleMesh extractLoops(const BinaryImage& image, const SurfaceGraph& graph) {
  BinaryBrickCache<BinaryImage> cache(image);
  return detail::extractLoops(graph, cache.bricks(),
                              [&](int bx, int by, int bz) { return cache.brickIndex(bx, by, bz); });
}

/// The same from the graph alone, with the cube configurations read from the bricks of the
/// image that trackComponent keeps with the graph (SurfaceGraph::bricks): no second pass over
/// the image. Throws std::invalid_argument for a graph that has vertices but no bricks (not made
/// by trackComponent: use the overload with the image), std::logic_error if the graph does not
/// match its bricks.
/// On `threads` threads (0: all cores), the same mesh for any number.
inline TriangleMesh extractLoops(const SurfaceGraph& graph, int threads = 1) {
  if (graph.bricks.empty() && graph.surfelCount() != 0)
    throw std::invalid_argument(
        "extractLoops: this surface graph carries no image bricks (it was not made by "
        "trackComponent); call extractLoops(image, graph)");
  return detail::extractLoops(graph, graph.bricks, [&](int bx, int by, int bz) {
    const std::uint32_t b = graph.bricks.find(bx, by, bz);
    if (b == BinaryBricks::kMissing) {
      std::ostringstream msg;
      msg << "extractLoops: the surface graph has a vertex in brick " << Voxel{bx, by, bz}
          << " (voxels 8x that + [0,8)^3), which its bricks do not hold";
      throw std::logic_error(msg.str());
    }
    return b;
  }, threads);
}

}  // namespace surftrack
