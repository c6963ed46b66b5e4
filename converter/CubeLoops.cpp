#include "CubeLoops.h"

#include <stdexcept>

namespace surftrack {
namespace {

EdgeSurfels computeEdgeSurfels() {
  EdgeSurfels out{};
  for (int config = 0; config < 256; ++config)
    for (int k = 0; k < cube::kEdges; ++k) {
      if (!cube::edgeIsCut(k, std::uint8_t(config))) continue;
      const Surfel s = cube::surfelOnEdge(Voxel{}, k, std::uint8_t(config));
      EdgeSurfel& e = out[config][k];
      e.inside = s.c;
      e.n = s.n;
      const int a = axisOf(s.n), b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
      e.cubeSlot = std::uint8_t(s.c[b] | s.c[c] << 1);
      // Out-arcs: the 4 edge neighbours by increasing Direction code of e (SurfaceGraph.h).
      int index = 0;
      for (Direction d = 0; d < 6; ++d)
        if (axisOf(d) != a) e.arcOf[d] = std::uint8_t(index++);
    }
  return out;
}

/// The direction from surfel s's edge to the cube face it shares with surfel t's edge, if the
/// two surfels' voxels all lie in one face of the cube (a 2-cube {u, u+n, u+e, u+n+e}).
int faceDirection(const Surfel& s, const Surfel& t) {
  for (Direction e = 0; e < 6; ++e) {
    if (axisOf(e) == axisOf(s.n)) continue;
    const Voxel face[4] = {s.inside(), s.outside(), s.inside() + unitVector(e), s.outside() + unitVector(e)};
    auto inFace = [&](Voxel v) { return v == face[0] || v == face[1] || v == face[2] || v == face[3]; };
    if (inFace(t.inside()) && inFace(t.outside())) return e;
  }
  return -1;
}

using Loops = std::array<CubeLoops, 4>;

Loops computeLoops() {
  Loops out{};
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (int config = 0; config < 256; ++config) {
      const CubeTriangulation& table = configurationTable(pair, std::uint8_t(config));
      for (int p = 0; p < table.patchCount; ++p) {
        // Directed triangle edges whose reverse is not in the patch: the boundary loop.
        std::array<int, cube::kEdges> next;
        next.fill(-1);
        int boundary = 0;
        const auto triangles = table.patchTriangles(p);
        for (const auto& tri : triangles)
          for (int j = 0; j < 3; ++j) {
            const int a = tri[j], b = tri[(j + 1) % 3];
            bool inner = false;
            for (const auto& other : triangles)
              for (int i = 0; i < 3; ++i) inner |= other[i] == b && other[(i + 1) % 3] == a;
            if (!inner) next[a] = b, ++boundary;
          }
        // A loop of l surfels has l - 2 triangles; the strict-26 tube has 6 surfels and 6
        // triangles and stays length 0 (walked by the general search).
        if (boundary != int(triangles.size()) + 2) continue;
        CubeLoop& loop = out[int(pair)][config][p];
        loop.positionOf.fill(CubeLoop::kNotInLoop);
        int k = table.triangles[table.patchBegin[p]][0];
        for (int i = 0; i < boundary; ++i, k = next[k]) {
          const Surfel s = cube::surfelOnEdge(Voxel{}, k, std::uint8_t(config));
          const Surfel t = cube::surfelOnEdge(Voxel{}, next[k], std::uint8_t(config));
          const int e = faceDirection(s, t);
          if (e < 0) throw std::logic_error("configuration table: a loop edge off the cube faces");
          loop.edge[i] = std::uint8_t(k);
          loop.arc[i] = edgeSurfels()[config][k].arcOf[e];
          loop.cubeSlot[i] = edgeSurfels()[config][k].cubeSlot;
          loop.positionOf[k] = std::uint8_t(i);
        }
        if (k != loop.edge[0]) throw std::logic_error("configuration table: a patch boundary is not one loop");
        loop.length = std::uint8_t(boundary);
        for (const auto& tri : triangles) {
          auto& out = loop.triangles[loop.triangleCount++];
          for (int j = 0; j < 3; ++j) out[j] = loop.positionOf[tri[j]];
        }
      }
    }
  return out;
}

}  // namespace

const EdgeSurfels& edgeSurfels() {
  static const EdgeSurfels table = computeEdgeSurfels();
  return table;
}

const CubeLoops& cubeLoops(AdjacencyPair pair) {
  static const Loops loops = computeLoops();
  return loops[int(pair)];
}

}  // namespace surftrack
