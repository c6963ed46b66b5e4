// decimateComplex (ComplexDecimation.h; docs/theory.md §12, "Decimating the complex").
#include "ComplexDecimation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include "Cancellation.h"
#include "CheckedDecimater.h"
#include "ComplexLinkGuard.h"
#include "DistanceGuard.h"
#include "EmbeddingGuard.h"
#include "MeshTriangles.h"
#include "SurfaceMesh.h"
#include "TopologyGuard.h"
#include "TriangleGrid.h"
#include "UnionFind.h"

namespace surftrack::refine {
namespace {

using Tri = std::array<std::uint32_t, 3>;

/// Each vertex's triangles (compressed rows).
struct VertexTriangles {
  std::vector<std::uint32_t> start, list;
  VertexTriangles(std::size_t vertices, const std::vector<Tri>& triangles) : start(vertices + 1, 0) {
    for (const Tri& t : triangles)
      for (std::uint32_t v : t) ++start[v + 1];
    for (std::size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
    list.resize(start.back());
    std::vector<std::uint32_t> at(start.begin(), start.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      for (std::uint32_t v : triangles[t]) list[at[v]++] = t;
  }
};

/// The triangles `ts` at vertex v form one closed disc around it: each of their edges at v is
/// in exactly two of them, once each way, and they are joined through those edges.
bool closedDisc(std::uint32_t v, const std::vector<std::uint32_t>& ts, const std::vector<Tri>& triangles) {
  if (ts.size() < 3) return false;
  // Each triangle's edge out of v (to `next`) and into v (from `prev`), in its orientation.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> around;  // (prev, next)
  for (std::uint32_t t : ts) {
    const Tri& x = triangles[t];
    const int k = int(std::find(x.begin(), x.end(), v) - x.begin());
    around.push_back({x[std::size_t((k + 2) % 3)], x[std::size_t((k + 1) % 3)]});
  }
  // One disc: following next -> the triangle whose prev it is walks all of them in one cycle.
  std::size_t at = 0, steps = 0;
  std::vector<char> seen(ts.size(), 0);
  do {
    if (seen[at]) return false;
    seen[at] = 1;
    ++steps;
    std::size_t found = ts.size();
    for (std::size_t j = 0; j < ts.size(); ++j)
      if (around[j].first == around[at].second) {
        if (found != ts.size()) return false;  // an edge of more than two
        found = j;
      }
    if (found == ts.size()) return false;  // a border
    at = found;
  } while (at != 0);
  if (steps != ts.size()) return false;
  // No edge in two triangles the same way (then the walk above could still close).
  for (std::size_t i = 0; i < ts.size(); ++i)
    for (std::size_t j = i + 1; j < ts.size(); ++j)
      if (around[i].second == around[j].second || around[i].first == around[j].first) return false;
  return true;
}

}  // namespace

ComplexDecimationReport decimateComplex(const std::vector<Point3>& points, std::vector<Tri>& triangles,
                                        const std::vector<std::array<std::uint32_t, 2>>& sides,
                                        std::vector<char>& removed, const DecimationParameters& p) {
  requireDecimationParameters(p);
  if (sides.size() != triangles.size())
    throw std::invalid_argument("decimateComplex: " + std::to_string(triangles.size()) + " triangles but " +
                                std::to_string(sides.size()) + " sides");
  for (const Tri& t : triangles)
    for (std::uint32_t v : t)
      if (v >= points.size()) throw std::invalid_argument("decimateComplex: a vertex index is out of range");
  throwIfCancelled(p.cancel, "decimation");
  ComplexDecimationReport report;
  report.trianglesBefore = triangles.size();
  removed.assign(triangles.size(), 0);
  const std::size_t n = points.size();

  // 1. Free vertices (one wall, one closed disc for both its regions) and singular ones (some
  //    region's triangles at it are not one closed disc: a pinch).
  std::vector<char> freeVertex(n, 0), singular(n, 0);
  {
    const VertexTriangles at(n, triangles);
    std::vector<std::uint32_t> ts;
    for (std::uint32_t v = 0; v < n; ++v) {
      const auto b = at.list.begin() + at.start[v], e = at.list.begin() + at.start[v + 1];
      if (b == e) continue;
      bool oneWall = true;
      std::vector<std::uint32_t> regions;
      for (auto it = b; it != e; ++it) {
        oneWall = oneWall && sides[*it] == sides[*b];
        regions.push_back(sides[*it][0]);
        regions.push_back(sides[*it][1]);
      }
      std::sort(regions.begin(), regions.end());
      regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
      for (std::uint32_t r : regions) {
        ts.clear();
        for (auto it = b; it != e; ++it)
          if (sides[*it][0] == r || sides[*it][1] == r) ts.push_back(*it);
        if (!closedDisc(v, ts, triangles)) singular[v] = 1;
      }
      freeVertex[v] = oneWall && !singular[v];
      if (!freeVertex[v]) ++report.lockedVertices;
    }
  }

  // 2. The walls, by their ordered pair of regions.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> walls;
  for (std::uint32_t t = 0; t < triangles.size(); ++t) walls[{sides[t][0], sides[t][1]}].push_back(t);
  report.walls = walls.size();

  // 3. The whole complex: its incidence (ComplexLinkGuard.h) and a grid of its triangles for
  //    the obstacles of each wall, both following the walls' decimations.
  ComplexIncidence incidence;
  for (const Tri& t : triangles) incidence.add(t);
  Box3 bounds{{0, 0, 0}, {0, 0, 0}};
  double edgeLength = 0;
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      bounds.lo[k] = v ? std::min(bounds.lo[k], points[v][k]) : points[v][k];
      bounds.hi[k] = v ? std::max(bounds.hi[k], points[v][k]) : points[v][k];
    }
  auto triangleOfIndex = [&](std::uint32_t t) {
    return Triangle3{points[triangles[t][0]], points[triangles[t][1]], points[triangles[t][2]]};
  };
  for (const Tri& t : triangles) edgeLength += norm(sub(points[t[0]], points[t[1]]));
  edgeLength = triangles.empty() ? 1.0 : edgeLength / double(triangles.size());
  TriangleGrid grid;
  grid.reset(bounds, 2 * edgeLength);
  std::vector<std::uint32_t> version(triangles.size(), 0);
  for (std::uint32_t t = 0; t < triangles.size(); ++t) grid.insert(t, 0, boxOf(triangleOfIndex(t)));

  // 4. Each wall in turn.
  std::vector<std::uint32_t> stamp(triangles.size(), 0);  // 1 + the wall's index: a triangle of the wall's mesh
  std::uint32_t wallIndex = 0;
  for (const auto& [pair, ts] : walls) {
    ++wallIndex;
    const std::size_t target =
        p.targetReduction ? std::size_t(std::llround((1 - *p.targetReduction) * double(ts.size()))) : 0;
    report.targetTriangles += target;
    if (std::none_of(ts.begin(), ts.end(), [&](std::uint32_t t) {
          return freeVertex[triangles[t][0]] || freeVertex[triangles[t][1]] || freeVertex[triangles[t][2]];
        }))
      continue;
    throwIfCancelled(p.cancel, "decimation");
    // Its triangles but those on an edge of more than two of them or of two the same way (a
    // pinch of both regions), which stay, as obstacles; each vertex one mesh vertex per fan of
    // the wall around it (corners joined across the edges of two triangles).
    std::unordered_map<std::uint64_t, std::vector<std::pair<std::uint32_t, int>>> edges;  // -> (index in ts, corner)
    for (std::uint32_t i = 0; i < ts.size(); ++i)
      for (int k = 0; k < 3; ++k)
        edges[ComplexIncidence::edgeKey(triangles[ts[i]][std::size_t(k)], triangles[ts[i]][std::size_t((k + 1) % 3)])]
            .push_back({i, k});
    std::vector<char> inMesh(ts.size(), 1);
    for (const auto& [key, uses] : edges)
      if (uses.size() > 2 ||
          (uses.size() == 2 && triangles[ts[uses[0].first]][std::size_t(uses[0].second)] ==
                                   triangles[ts[uses[1].first]][std::size_t(uses[1].second)]))
        for (const auto& u : uses) inMesh[u.first] = 0;
    UnionFind fans(3 * ts.size());
    for (const auto& [key, uses] : edges) {
      if (uses.size() != 2 || !inMesh[uses[0].first] || !inMesh[uses[1].first]) continue;
      const auto [i, a] = uses[0];
      const auto [j, b] = uses[1];
      // Edge (x, y) at corners a, a+1 of triangle i and y, x at corners b, b+1 of triangle j.
      fans.join(3 * i + std::uint32_t(a), 3 * j + std::uint32_t((b + 1) % 3));
      fans.join(3 * i + std::uint32_t((a + 1) % 3), 3 * j + std::uint32_t(b));
    }
    // The mesh; a triangle OpenMesh refuses (a complex vertex it cannot link) stays, with its
    // vertices, and the mesh is made again without it.
    SurfaceMesh mesh;
    OpenMesh::VPropHandleT<std::uint32_t> identity;
    std::vector<std::uint32_t> triangleOfFace;  // face index -> triangle
    std::vector<std::uint32_t> failedVertices;
    for (bool failed = true; failed;) {
      failed = false;
      mesh = SurfaceMesh();
      mesh.add_property(identity);
      triangleOfFace.clear();
      std::unordered_map<std::uint32_t, SurfaceMesh::VertexHandle> vertexOfFan;
      for (std::uint32_t i = 0; i < ts.size() && !failed; ++i) {
        if (!inMesh[i]) continue;
        std::array<SurfaceMesh::VertexHandle, 3> vh;
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t root = fans.find(3 * i + std::uint32_t(k)), v = triangles[ts[i]][std::size_t(k)];
          auto [it, added] = vertexOfFan.try_emplace(root);
          if (added) {
            it->second = mesh.add_vertex(SurfaceMesh::Point(points[v][0], points[v][1], points[v][2]));
            mesh.property(identity, it->second) = v;
          }
          vh[std::size_t(k)] = it->second;
        }
        const auto f = mesh.add_face(vh[0], vh[1], vh[2]);
        if (!f.is_valid()) {
          inMesh[i] = 0;
          failed = true;
          for (std::uint32_t v : triangles[ts[i]]) failedVertices.push_back(v);
          continue;
        }
        if (std::size_t(f.idx()) != triangleOfFace.size()) throw std::logic_error("decimateComplex: face numbering");
        triangleOfFace.push_back(ts[i]);
      }
    }
    Box3 box = boxOf(triangleOfIndex(ts[0]));
    for (std::uint32_t t : ts) {
      const Box3 b = boxOf(triangleOfIndex(t));
      for (int k = 0; k < 3; ++k) {
        box.lo[k] = std::min(box.lo[k], b.lo[k]);
        box.hi[k] = std::max(box.hi[k], b.hi[k]);
      }
    }
    for (std::uint32_t t : triangleOfFace) stamp[t] = wallIndex;
    std::vector<char> meshFree(mesh.n_vertices(), 0), meshSingular(mesh.n_vertices(), 0);
    for (auto v : mesh.vertices()) {
      const std::uint32_t c = mesh.property(identity, v);
      meshFree[std::size_t(v.idx())] = freeVertex[c] && !mesh.is_boundary(v) && !mesh.is_isolated(v);
      meshSingular[std::size_t(v.idx())] = singular[c];
    }
    for (auto v : mesh.vertices())
      if (std::find(failedVertices.begin(), failedVertices.end(), mesh.property(identity, v)) != failedVertices.end())
        meshFree[std::size_t(v.idx())] = 0;
    if (std::none_of(meshFree.begin(), meshFree.end(), [](char c) { return c != 0; })) continue;

    // The obstacles: the complex's triangles near the wall that are not in its mesh.
    std::vector<Triangle3> obstacles;
    std::vector<Tri> obstacleNames;
    const double margin = 1e-6 * edgeLength;
    const Box3 query{{box.lo[0] - margin, box.lo[1] - margin, box.lo[2] - margin},
                     {box.hi[0] + margin, box.hi[1] + margin, box.hi[2] + margin}};
    std::vector<std::uint32_t> near;
    grid.near(query, [&](std::uint32_t t, std::uint32_t tag) {
      if (tag == version[t] && !removed[t] && stamp[t] != wallIndex) near.push_back(t);
    });
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    for (std::uint32_t t : near) {
      const Triangle3 x = triangleOfIndex(t);
      if (!boxOf(x).meets(query)) continue;
      obstacles.push_back(x);
      obstacleNames.push_back(triangles[t]);
    }

    mesh.request_vertex_status();
    mesh.request_edge_status();
    mesh.request_halfedge_status();
    mesh.request_face_status();
    mesh.request_face_normals();
    mesh.update_face_normals();
    {
      CheckedDecimaterT<SurfaceMesh> decimater(mesh);
      OpenMesh::Decimater::ModQuadricT<SurfaceMesh>::Handle quadric;
      ModSampledDistanceT<SurfaceMesh>::Handle distance;
      OpenMesh::Decimater::ModNormalFlippingT<SurfaceMesh>::Handle flipping;
      ModTopologyGuardT<SurfaceMesh>::Handle topology;
      ModEmbeddingGuardT<SurfaceMesh>::Handle embedding;
      ModComplexLinkT<SurfaceMesh>::Handle link;
      decimater.add(quadric);
      decimater.add(flipping);
      decimater.add(link);  // (first of the guards: the cheapest refusals)
      decimater.add(topology);
      decimater.add(embedding);
      decimater.module(quadric).unset_max_err();
      if (p.maxError) {
        decimater.module(quadric).set_max_err(*p.maxError * *p.maxError, false);
        decimater.add(distance);
        decimater.module(distance).set_tolerance(*p.maxError);
      }
      decimater.module(flipping).set_max_normal_deviation(p.maxNormalDeviation);
      decimater.module(link).set_complex(identity, std::move(meshFree), std::move(meshSingular), &incidence);
      decimater.module(embedding).set_complex(identity, std::move(obstacles), std::move(obstacleNames));
      if (!decimater.initialize()) throw std::logic_error("decimateComplex: the decimater refused its modules");
      const std::size_t kept = ts.size() - mesh.n_faces();  // the wall's triangles outside its mesh
      auto& quadricModule = decimater.module(quadric);
      decimater.decimateToFaces(
          target > kept ? target - kept : 0, [&](const auto& ci) { return quadricModule.collapse_priority(ci); },
          p.cancel);
    }
    // The wall's triangles written back: the survivors' vertices, in their orientation.
    for (auto f : mesh.all_faces()) {
      const std::uint32_t t = triangleOfFace[std::size_t(f.idx())];
      if (mesh.status(f).deleted()) {
        removed[t] = 1;
        ++version[t];
        continue;
      }
      Tri now;
      int k = 0;
      for (auto v : mesh.fv_range(f)) now[std::size_t(k++)] = mesh.property(identity, v);
      if (ComplexIncidence::triangleKey(now) == ComplexIncidence::triangleKey(triangles[t])) continue;
      triangles[t] = now;
      grid.insert(t, ++version[t], boxOf(triangleOfIndex(t)));
    }
  }
  report.trianglesAfter = std::size_t(std::count(removed.begin(), removed.end(), 0));
  return report;
}

}  // namespace surftrack::refine
