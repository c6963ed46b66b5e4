// decimateComplex (ComplexDecimation.h; docs/theory.md §12, "Decimating the complex").
#include "ComplexDecimation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include "Cancellation.h"
#include "CheckedDecimater.h"
#include "ComplexLinkGuard.h"
#include "DecimatedComplex.h"
#include "ProvenDistanceGuard.h"
#include "EmbeddingGuard.h"
#include "JunctionLines.h"
#include "MeshTriangles.h"
#include "SurfaceMesh.h"
#include "TopologyGuard.h"
#include "TriangleGrid.h"
#include "UnionFind.h"

namespace surftrack::refine {
namespace {

using Tri = std::array<std::uint32_t, 3>;

/// Each vertex's live triangles (compressed rows).
struct VertexTriangles {
  std::vector<std::uint32_t> start, list;
  VertexTriangles(std::size_t vertices, const std::vector<Tri>& triangles, const std::vector<char>& removed)
      : start(vertices + 1, 0) {
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (!removed[t])
        for (std::uint32_t v : triangles[t]) ++start[v + 1];
    for (std::size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
    list.resize(start.back());
    std::vector<std::uint32_t> at(start.begin(), start.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      if (!removed[t])
        for (std::uint32_t v : triangles[t]) list[at[v]++] = t;
  }
};

/// How far a wall goes in decimateWalls: to its own target; past it while both its regions are
/// above theirs (their excess shared among their walls by size); or, when balancing, for a
/// region still above its target, past it while the other region may lose more
/// (DecimatedComplex::mayLose: the region's excess shared among its walls by size, the other's
/// slack taken first come first served).
enum class WallGoal { OwnTarget, RegionShare, Balance };

/// The walls' own decimation (docs/theory.md §12, "Decimating the complex", conditions 1-4) of
/// the complex's live triangles, in `rounds` rounds; returns the vertices it found locked.
std::size_t decimateWalls(DecimatedComplex& c, const DecimationParameters& p, int rounds, WallGoal mode) {
  const std::vector<Point3>& points = c.points;
  std::vector<Tri>& triangles = c.triangles;
  const std::vector<std::array<std::uint32_t, 2>>& sides = c.sides;
  std::vector<char>& removed = c.removed;
  const std::size_t n = points.size();
  std::size_t lockedVertices = 0;

  // 1. Free vertices (one wall, one closed disc for both its regions) and singular ones (some
  //    region's triangles at it are not one closed disc: a pinch).
  std::vector<char> freeVertex(n, 0), singular(n, 0);
  {
    const VertexTriangles at(n, triangles, removed);
    std::vector<std::uint32_t> star;
    for (std::uint32_t v = 0; v < n; ++v) {
      const auto b = at.list.begin() + at.start[v], e = at.list.begin() + at.start[v + 1];
      if (b == e) continue;
      star.assign(b, e);
      const bool oneWall = std::all_of(b, e, [&](std::uint32_t t) { return sides[t] == sides[*b]; });
      singular[v] = singularVertex(v, star, triangles, sides);
      freeVertex[v] = oneWall && !singular[v];
      if (!freeVertex[v]) ++lockedVertices;
    }
  }

  // 3. The whole complex: its incidence (ComplexLinkGuard.h) and a grid of its triangles for
  //    the obstacles of each wall, both following the walls' decimations.
  ComplexIncidence incidence;
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    if (!removed[t]) incidence.add(triangles[t]);
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
  std::size_t liveTriangles = 0;
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    if (!removed[t]) {
      edgeLength += norm(sub(points[triangles[t][0]], points[triangles[t][1]]));
      ++liveTriangles;
    }
  edgeLength = liveTriangles ? edgeLength / double(liveTriangles) : 1.0;
  TriangleGrid grid;
  grid.reset(bounds, 2 * edgeLength);
  std::vector<std::uint32_t> version(triangles.size(), 0);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    if (!removed[t]) grid.insert(t, 0, boxOf(triangleOfIndex(t)));

  // 4. Each wall's mesh and decimater, over the undecimated complex.
  using Mesh = SurfaceMesh;
  struct Wall {
    std::vector<std::uint32_t> ts;  // its live triangles at the start
    std::uint32_t wall = 0;
    std::size_t target = 0, kept = 0, live = 0;  // kept: its triangles outside its mesh
    Box3 box;
    std::unique_ptr<Mesh> mesh;
    OpenMesh::VPropHandleT<std::uint32_t> identity;
    std::vector<std::uint32_t> triangleOfFace;  // face index -> triangle
    std::unique_ptr<CheckedDecimaterT<Mesh>> decimater;
    OpenMesh::Decimater::ModQuadricT<Mesh>::Handle quadric;
    ModProvenDistanceT<Mesh>::Handle distance;
    OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle flipping;
    ModTopologyGuardT<Mesh>::Handle topology;
    ModEmbeddingGuardT<Mesh>::Handle embedding;
    ModComplexLinkT<Mesh>::Handle link;
  };
  std::vector<std::unique_ptr<Wall>> states;  // (the modules' handles cannot be copied)
  std::vector<std::uint32_t> wallOf(triangles.size(), 0);  // 1 + the index in states of a triangle's wall mesh
  for (std::uint32_t wall = 0; wall < c.walls.size(); ++wall) {
    if (!p.targetReduction && mode != WallGoal::OwnTarget) break;
    const std::array<std::uint32_t, 2> pair = sides[c.walls[wall][0]];
    if (mode == WallGoal::OwnTarget ? c.target[wall] && c.live[wall] <= c.target[wall]
                                    : !c.mayLose(pair[0]) || !c.mayLose(pair[1]) ||
                                          (mode == WallGoal::Balance && !c.aboveTarget(pair[0]) && !c.aboveTarget(pair[1])))
      continue;
    std::vector<std::uint32_t> ts;
    for (std::uint32_t t : c.walls[wall])
      if (!removed[t]) ts.push_back(t);
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
    states.push_back(std::make_unique<Wall>());
    Wall& w = *states.back();
    w.ts = ts;
    w.wall = wall;
    w.target = c.target[wall];
    std::vector<std::uint32_t> failedVertices;
    for (bool failed = true; failed;) {
      failed = false;
      w.mesh = std::make_unique<Mesh>();
      Mesh& mesh = *w.mesh;
      mesh.add_property(w.identity);
      w.triangleOfFace.clear();
      std::unordered_map<std::uint32_t, Mesh::VertexHandle> vertexOfFan;
      for (std::uint32_t i = 0; i < ts.size() && !failed; ++i) {
        if (!inMesh[i]) continue;
        std::array<Mesh::VertexHandle, 3> vh;
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t root = fans.find(3 * i + std::uint32_t(k)), v = triangles[ts[i]][std::size_t(k)];
          auto [it, added] = vertexOfFan.try_emplace(root);
          if (added) {
            it->second = mesh.add_vertex(Mesh::Point(points[v][0], points[v][1], points[v][2]));
            mesh.property(w.identity, it->second) = v;
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
        if (std::size_t(f.idx()) != w.triangleOfFace.size()) throw std::logic_error("decimateComplex: face numbering");
        w.triangleOfFace.push_back(ts[i]);
      }
    }
    Mesh& mesh = *w.mesh;
    std::vector<char> meshFree(mesh.n_vertices(), 0), meshSingular(mesh.n_vertices(), 0);
    for (auto v : mesh.vertices()) {
      const std::uint32_t c = mesh.property(w.identity, v);
      meshFree[std::size_t(v.idx())] = freeVertex[c] && !mesh.is_boundary(v) && !mesh.is_isolated(v) &&
                                       std::find(failedVertices.begin(), failedVertices.end(), c) == failedVertices.end();
      meshSingular[std::size_t(v.idx())] = singular[c];
    }
    if (std::none_of(meshFree.begin(), meshFree.end(), [](char c) { return c != 0; })) {
      states.pop_back();
      continue;
    }
    w.box = boxOf(triangleOfIndex(ts[0]));
    for (std::uint32_t t : ts) {
      const Box3 b = boxOf(triangleOfIndex(t));
      for (int k = 0; k < 3; ++k) {
        w.box.lo[k] = std::min(w.box.lo[k], b.lo[k]);
        w.box.hi[k] = std::max(w.box.hi[k], b.hi[k]);
      }
    }
    w.kept = ts.size() - mesh.n_faces();
    w.live = mesh.n_faces();
    prepareForDecimation(mesh);
    w.decimater = std::make_unique<CheckedDecimaterT<Mesh>>(mesh);
    CheckedDecimaterT<Mesh>& decimater = *w.decimater;
    decimater.add(w.quadric);
    decimater.add(w.flipping);
    decimater.add(w.link);  // (first of the guards: the cheapest refusals)
    decimater.add(w.topology);
    decimater.add(w.embedding);
    decimater.module(w.quadric).unset_max_err();
    if (p.maxError) {
      decimater.module(w.quadric).set_max_err(*p.maxError * *p.maxError, false);
      decimater.add(w.distance);
      decimater.module(w.distance).set_tolerance(*p.maxError);
      // Measured against the undecimated wall, its pieces where earlier passes left them.
      std::vector<Triangle3> original;
      for (std::uint32_t t : c.walls[wall]) original.push_back(c.original[t]);
      std::vector<std::vector<Triangle3>> pieces;
      for (std::uint32_t t : w.triangleOfFace) pieces.push_back(c.pieces[t]);
      decimater.module(w.distance).set_history(std::move(original), std::move(pieces));
    }
    decimater.module(w.flipping).set_max_normal_deviation(p.maxNormalDeviation);
    decimater.module(w.link).set_complex(w.identity, std::move(meshFree), std::move(meshSingular), &incidence);
    decimater.module(w.embedding).set_complex(w.identity);
    if (!decimater.initialize()) throw std::logic_error("decimateComplex: the decimater refused its modules");
    for (std::uint32_t t : w.triangleOfFace) wallOf[t] = std::uint32_t(states.size());
  }

  // 5. The walls decimated in rounds, each wall a part of the way to its target in each round,
  //    so that no wall takes every chord between junction vertices before the next one starts
  //    (the link condition over the complex refuses a chord twice).
  //    With WallGoal::RegionShare, a wall's share of a region's excess in a round is in
  //    proportion to its live triangles among those of the region's walls decimated here.
  std::vector<std::size_t> decimatedLive(c.regionLive.size(), 0);
  for (int round = 1; round <= rounds; ++round) {
    std::fill(decimatedLive.begin(), decimatedLive.end(), 0);
    for (const auto& state : states)
      for (std::uint32_t r : sides[state->ts[0]]) decimatedLive[r] += state->live;
    for (std::size_t k = 0; k < states.size(); ++k) {
      Wall& w = *states[k];
      Mesh& mesh = *w.mesh;
      const std::size_t n = w.ts.size();
      std::size_t goal = mode == WallGoal::OwnTarget
                             ? n - (n - std::min(n, w.target)) * std::size_t(round) / std::size_t(rounds)
                             : w.live + w.kept;
      // No region below its target (the reduction of its triangles): after the junction lines'
      // collapses, some walls are below theirs and others above (JunctionLines.h, condition 5).
      const std::array<std::uint32_t, 2> regions = sides[w.ts[0]];
      if (p.targetReduction) {
        std::size_t excess = w.live + w.kept;
        for (std::uint32_t r : regions) {
          const std::size_t over = c.mayLose(r);
          if (mode == WallGoal::Balance && !c.aboveTarget(r)) {
            // Its slack, as it comes, in whole collapses (two triangles each): never below its floor.
            excess = std::min(excess, over - over % 2);
            continue;
          }
          excess = std::min(excess, over);
          if (mode != WallGoal::OwnTarget && decimatedLive[r])
            excess = std::min(excess, (over * w.live + decimatedLive[r] - 1) / decimatedLive[r]);
        }
        // Balancing, only a region above its target asks (its neighbours may have given it all).
        if (mode == WallGoal::Balance && !c.aboveTarget(regions[0]) && !c.aboveTarget(regions[1])) excess = 0;
        goal = mode == WallGoal::OwnTarget ? std::max(goal, w.live + w.kept - excess) : w.live + w.kept - excess;
      }
      const std::size_t meshGoal = goal > w.kept ? goal - w.kept : 0;
      if (w.live <= meshGoal) continue;
      throwIfCancelled(p.cancel, "decimation");
      // The obstacles: the complex's triangles near the wall that are not in its mesh, now.
      std::vector<Triangle3> obstacles;
      std::vector<Tri> obstacleNames;
      const double margin = 1e-6 * edgeLength;
      const Box3 query{{w.box.lo[0] - margin, w.box.lo[1] - margin, w.box.lo[2] - margin},
                       {w.box.hi[0] + margin, w.box.hi[1] + margin, w.box.hi[2] + margin}};
      std::vector<std::uint32_t> near;
      grid.near(query, [&](std::uint32_t t, std::uint32_t tag) {
        if (tag == version[t] && !removed[t] && wallOf[t] != k + 1) near.push_back(t);
      });
      std::sort(near.begin(), near.end());
      near.erase(std::unique(near.begin(), near.end()), near.end());
      for (std::uint32_t t : near) {
        const Triangle3 x = triangleOfIndex(t);
        if (!boxOf(x).meets(query)) continue;
        obstacles.push_back(x);
        obstacleNames.push_back(triangles[t]);
      }
      w.decimater->module(w.embedding).set_obstacles(std::move(obstacles), std::move(obstacleNames));
      auto& quadricModule = w.decimater->module(w.quadric);
      // (n_faces() counts the faces deleted in earlier rounds too.)
      const std::size_t deleted = mesh.n_faces() - w.live;
      w.decimater->decimateToFaces(
          meshGoal + deleted, [&](const auto& ci) { return quadricModule.collapse_priority(ci); }, p.cancel);
      // The wall's triangles written back: the survivors' vertices, in their orientation.
      const std::size_t liveBefore = w.live;
      w.live = 0;
      for (auto f : mesh.all_faces()) {
        const std::uint32_t t = w.triangleOfFace[std::size_t(f.idx())];
        if (removed[t]) continue;
        if (mesh.status(f).deleted()) {
          removed[t] = 1;
          ++version[t];
          continue;
        }
        ++w.live;
        Tri now;
        int c = 0;
        for (auto v : mesh.fv_range(f)) now[std::size_t(c++)] = mesh.property(w.identity, v);
        if (ComplexIncidence::triangleKey(now) == ComplexIncidence::triangleKey(triangles[t])) continue;
        triangles[t] = now;
        grid.insert(t, ++version[t], boxOf(triangleOfIndex(t)));
      }
      for (std::uint32_t r : regions) c.regionLive[r] -= liveBefore - w.live;
    }
  }
  // The walls' state handed back: their live triangles and the pieces each answers for.
  for (const auto& state : states) {
    Wall& w = *state;
    c.live[w.wall] = w.live + w.kept;
    if (!p.maxError) continue;
    for (auto f : w.mesh->all_faces()) {
      const std::uint32_t t = w.triangleOfFace[std::size_t(f.idx())];
      c.pieces[t] = removed[t] ? std::vector<Triangle3>{} : w.decimater->module(w.distance).pieces(f);
    }
  }
  return lockedVertices;
}

constexpr int kJunctionPasses = 3;

}  // namespace

ComplexDecimationReport decimateComplex(const std::vector<Point3>& points, std::vector<Tri>& triangles,
                                        const std::vector<std::array<std::uint32_t, 2>>& sides,
                                        std::vector<char>& removed, const DecimationParameters& p,
                                        std::optional<std::uint32_t> background) {
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

  // The walls, by their ordered pair of regions; each one's target.
  DecimatedComplex c{points, triangles, sides, removed};
  {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> index;
    c.wallOf.resize(triangles.size());
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
      const auto [it, added] = index.try_emplace({sides[t][0], sides[t][1]}, std::uint32_t(c.walls.size()));
      if (added) c.walls.emplace_back();
      c.walls[it->second].push_back(t);
      c.wallOf[t] = it->second;
    }
  }
  report.walls = c.walls.size();
  std::uint32_t regions = 0;
  for (const auto& pair : sides) regions = std::max({regions, pair[0] + 1, pair[1] + 1});
  c.regionLive.assign(regions, 0);
  c.regionTarget.assign(regions, 0);
  for (const auto& ts : c.walls) {
    c.live.push_back(ts.size());
    c.target.push_back(p.targetReduction ? std::size_t(std::llround((1 - *p.targetReduction) * double(ts.size()))) : 0);
    report.targetTriangles += c.target.back();
    for (std::uint32_t r : sides[ts[0]]) c.regionLive[r] += c.live.back();
  }
  // A region's target is its own share of its triangles (as its label's report states it), not
  // its walls' targets summed, each rounded.
  if (p.targetReduction)
    for (std::size_t r = 0; r < regions; ++r)
      c.regionTarget[r] = std::size_t(std::llround((1 - *p.targetReduction) * double(c.regionLive[r])));
  // The background's surface is not made: no target of its own holds its walls back.
  if (background && *background < regions) c.regionTarget[*background] = 0;
  // With a distance bound, each triangle is at first its own piece of the original surface
  // (ProvenDistanceGuard.h).
  if (p.maxError) {
    c.original.resize(triangles.size());
    c.pieces.resize(triangles.size());
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
      c.original[t] = c.triangleAt(t);
      c.pieces[t].assign(1, c.original[t]);
    }
  }

  // The walls first, as far as they go with the junction lines locked; then, while a region is
  // above its target, the junction lines (JunctionLines.h) and the walls again on what those
  // collapses freed, up to kJunctionPasses times (each pass frees less than the one before).
  report.lockedVertices = decimateWalls(c, p, 4, WallGoal::OwnTarget);
  for (int pass = 0; pass < kJunctionPasses; ++pass) {
    bool above = false;
    for (std::uint32_t r = 0; r < c.regionLive.size(); ++r) above = above || c.mayLose(r);  // (no target: any)
    if (!above) break;
    const std::size_t collapses = simplifyJunctionLines(c, p);
    report.junctionCollapses += collapses;
    if (!collapses) break;
    decimateWalls(c, p, 2, WallGoal::OwnTarget);
  }
  // Last, what the locked walls could not give: the walls whose two regions are both still
  // above target go past their own targets, each by its share of those regions' excess.
  decimateWalls(c, p, 4, WallGoal::RegionShare);
  // And a region still above its target takes a little more from its neighbours at theirs
  // (DecimatedComplex::balancing), its walls first, then its junction lines and its walls again.
  if (p.targetReduction) {
    c.balancing = true;
    for (int pass = 0; pass <= kJunctionPasses; ++pass) {
      bool above = false;
      for (std::uint32_t r = 0; r < c.regionLive.size(); ++r) above = above || c.aboveTarget(r);
      if (!above) break;
      if (pass) {
        const std::size_t collapses = simplifyJunctionLines(c, p);
        report.junctionCollapses += collapses;
        if (!collapses) break;
      }
      decimateWalls(c, p, pass ? 2 : 4, WallGoal::Balance);
    }
  }
  report.trianglesAfter = std::size_t(std::count(removed.begin(), removed.end(), 0));
  return report;
}

}  // namespace surftrack::refine
