// extractLabels with LabelWalls::Shared (docs/theory.md, "Shared walls"): every label's surface
// as a part of one conforming complex. One scan of the digital 3-cubes gives each cube's walls
// (converter/NestedWalls.h: the nested analogs of the labels in priority order, the background
// lowest, then by increasing label); each wall triangle goes to the two labels it separates,
// as it is to the one inside and reversed to the one outside. A vertex is a grid edge between
// two voxels of different labels (a surfel), numbered per label at its first use; where a label
// touches itself at a vertex or an edge the pinch is split (converter/PinchSplit.h) and counted.
// With LabelOptions::smooth the walls also make the complex itself (every wall once, over one
// vertex per surfel), which is smoothed as a whole (ComplexSmoothing.h); each label's vertex
// then takes its complex vertex's point, so a vertex has one point in every label. With
// LabelOptions::decimate the complex (smoothed or not) is decimated wall by wall
// (WallDecimation.h), and each label's triangles are its walls' survivors, over its own vertices
// (a pinch's copies kept where they were: the decimation never touches a pinch).
// The priorities and the walls are found by slabs of planes in parallel and put together in
// slab order, the complex (with smoothing or decimation) numbered in one pass over the walls,
// and each label's mesh built from its own walls and finished in parallel, so the meshes are
// those of one scan in cube order, the same for any `threads`.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "BoundaryMapping.h"
#include "ComplexSmoothing.h"
#include "DigitalCube.h"
#include "FlatKeyMap.h"
#include "HugePages.h"
#include "Image.h"
#include "Labels.h"
#include "NestedWalls.h"
#include "PhysicalRange.h"
#include "PinchSplit.h"
#include "ScannedLabel.h"
#include "SourceImage.h"
#include "WallDecimation.h"

namespace surftrack {

/// The surfaces of the labels select(labels) picks (indices into the increasing non-background
/// labels of the image), with shared walls.
template <class T, class Select>
std::vector<LabelSurface> sharedWallSurfaces(const VolumeRef<T>& image, const VoxelSource& source,
                                             const LabelOptions& o, Select&& select) {
  const Dims dims = image.dims;
  const T background = o.background.as<T>();
  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  auto cancelled = [&] { return o.cancel && o.cancel->load(std::memory_order_relaxed); };
  // Slabs of planes [z0, z1) for the parallel passes: a few per thread. Each pass's result is
  // put together in slab order, so it is the one-thread scan's whatever the count.
  auto slabs = [&](int z0, int z1) {
    const int parts = std::clamp(2 * arena.max_concurrency(), 1, std::max(1, z1 - z0));
    std::vector<std::pair<int, int>> out(std::size_t(parts), {0, 0});
    for (int k = 0; k < parts; ++k)
      out[std::size_t(k)] = {z0 + int(std::int64_t(z1 - z0) * k / parts), z0 + int(std::int64_t(z1 - z0) * (k + 1) / parts)};
    return out;
  };
  const std::size_t nx = std::size_t(dims.nx), nxy = nx * std::size_t(dims.ny), voxelCount = nxy * std::size_t(dims.nz);

  // 1. Priorities: the background (and every voxel outside the domain) 0, the labels 1, 2, ...
  //    by increasing value. The labels are found by runs of equal values (slabs in parallel).
  const auto planeSlabs = slabs(0, dims.nz);
  std::vector<std::vector<T>> found(planeSlabs.size());
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), planeSlabs.size(), [&](std::size_t k) {
      std::vector<T>& f = found[k];
      for (int z = planeSlabs[k].first; z < planeSlabs[k].second; ++z)
        for (int y = 0; y < dims.ny; ++y)
          for (int x = 0; x < dims.nx; ++x) {
            const T v = image.at(x, y, z);
            if (v != background && (f.empty() || v != f.back())) f.push_back(v);
          }
      std::sort(f.begin(), f.end());
      f.erase(std::unique(f.begin(), f.end()), f.end());
    });
  });
  std::vector<T> labels;
  for (auto& f : found) {
    labels.insert(labels.end(), f.begin(), f.end());
    std::vector<T>().swap(f);
  }
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  const std::vector<std::size_t> selected = select(labels);
  // Written once, in parallel: fresh memory on huge pages (lib/HugePages.h).
  const FreshArray<std::uint32_t> priority = freshArray<std::uint32_t>(voxelCount);
  // Each slab counts its voxels per priority, unless a count array per slab would be large
  // beside the volume (millions of labels on many threads): then one pass counts them after.
  const bool countBySlab = (labels.size() + 1) * planeSlabs.size() <= voxelCount / 4;
  std::vector<std::vector<std::uint64_t>> slabVoxels(planeSlabs.size());
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), planeSlabs.size(), [&](std::size_t k) {
      std::vector<std::uint64_t>& count = slabVoxels[k];
      count.assign(countBySlab ? labels.size() + 1 : 1, 0);
      T last = background;
      std::uint32_t p = 0;
      for (int z = planeSlabs[k].first; z < planeSlabs[k].second; ++z)
        for (int y = 0; y < dims.ny; ++y) {
          std::uint32_t* row = priority.get() + std::size_t(z) * nxy + std::size_t(y) * nx;
          for (int x = 0; x < dims.nx; ++x) {
            const T v = image.at(x, y, z);
            if (v != last) {
              last = v;
              p = v == background ? 0u
                                  : std::uint32_t(std::lower_bound(labels.begin(), labels.end(), v) - labels.begin()) + 1;
            }
            row[x] = p;
            if (countBySlab) ++count[p];
          }
        }
    });
  });
  std::vector<std::uint64_t> voxels(labels.size() + 1, 0);
  for (auto& count : slabVoxels) {
    if (countBySlab)
      for (std::size_t p = 0; p < count.size(); ++p) voxels[p] += count[p];
    std::vector<std::uint64_t>().swap(count);
  }
  if (!countBySlab)
    for (std::size_t i = 0; i < voxelCount; ++i) ++voxels[priority[i]];
  auto priorityAt = [&](const Voxel& v) -> std::uint32_t {
    if (!dims.contains(v)) return 0;
    return priority[std::size_t(v.x) + nx * std::size_t(v.y) + nxy * std::size_t(v.z)];
  };

  // 2. The walls, in the order of the cubes (slabs of cube planes in parallel): each wall
  //    triangle as its cube (index of m + (1, 1, 1) in the grid of cubes), its three cube edges
  //    and the priorities of its two sides.
  const std::uint64_t cx = std::uint64_t(dims.nx) + 1, cxy = cx * (std::uint64_t(dims.ny) + 1);
  if (cxy * (std::uint64_t(dims.nz) + 1) >= std::uint64_t(1) << 52)
    throw std::length_error("shared walls: more than 2^52 cubes");
  struct Wall {
    std::uint64_t cubeAndEdges;  // cube | edge 0 << 52 | edge 1 << 56 | edge 2 << 60
    std::uint32_t inside, outside;
  };
  auto cubeOf = [&](const Wall& w) {
    const std::uint64_t c = w.cubeAndEdges & ((std::uint64_t(1) << 52) - 1);
    const std::uint64_t z = c / cxy, r = c - z * cxy, y = r / cx;
    return Voxel{int(r - y * cx) - 1, int(y) - 1, int(z) - 1};
  };
  auto edgeOf = [](const Wall& w, int k) { return int(w.cubeAndEdges >> (52 + 4 * k) & 15u); };
  const auto cubeSlabs = slabs(-1, dims.nz);
  std::vector<std::vector<Wall>> slabWalls(cubeSlabs.size());
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), cubeSlabs.size(), [&](std::size_t k) {
      std::unordered_map<std::uint32_t, CubeWalls> cache;  // by the corners' local ranks, 3 bits each
      std::vector<Wall>& out = slabWalls[k];
      for (int z = cubeSlabs[k].first; z < cubeSlabs[k].second; ++z) {
        if (cancelled()) throw Cancelled("extraction cancelled");
        for (int y = -1; y < dims.ny; ++y)
          for (int x = -1; x < dims.nx; ++x) {
            const Voxel m{x, y, z};
            std::array<std::uint32_t, 8> p;
            if (x >= 0 && y >= 0 && z >= 0 && x + 1 < dims.nx && y + 1 < dims.ny && z + 1 < dims.nz) {
              const std::uint32_t* c = priority.get() + std::size_t(x) + nx * std::size_t(y) + nxy * std::size_t(z);
              p = {c[0], c[1], c[nx], c[nx + 1], c[nxy], c[nxy + 1], c[nxy + nx], c[nxy + nx + 1]};
            } else {
              for (int i = 0; i < 8; ++i) p[std::size_t(i)] = priorityAt(m + cube::cornerOffset(i));
            }
            if (std::all_of(p.begin() + 1, p.end(), [&](std::uint32_t q) { return q == p[0]; })) continue;
            std::array<std::uint32_t, 8> distinct = p;
            std::sort(distinct.begin(), distinct.end());
            const auto end = std::unique(distinct.begin(), distinct.end());
            std::array<std::uint8_t, 8> local;
            std::uint32_t key = 0;
            for (int i = 0; i < 8; ++i) {
              local[std::size_t(i)] = std::uint8_t(std::lower_bound(distinct.begin(), end, p[std::size_t(i)]) - distinct.begin());
              key |= std::uint32_t(local[std::size_t(i)]) << (3 * i);
            }
            auto at = cache.find(key);
            if (at == cache.end()) at = cache.emplace(key, cubeWalls(local, o.pair)).first;
            const CubeWalls& walls = at->second;
            const std::uint64_t cube = std::uint64_t(x + 1) + cx * std::uint64_t(y + 1) + cxy * std::uint64_t(z + 1);
            for (int w = 0; w < walls.count; ++w) {
              const WallTriangle& t = walls.triangles[std::size_t(w)];
              if (out.size() == out.capacity()) reserveHugePages(out, std::max<std::size_t>(4096, 2 * out.capacity()));
              out.push_back({cube | std::uint64_t(t.edges[0]) << 52 | std::uint64_t(t.edges[1]) << 56 |
                                 std::uint64_t(t.edges[2]) << 60,
                             distinct[t.inside], distinct[t.outside]});
            }
          }
      }
    });
  });
  std::vector<std::size_t> wallStart(cubeSlabs.size() + 1, 0);
  for (std::size_t k = 0; k < cubeSlabs.size(); ++k) wallStart[k + 1] = wallStart[k] + slabWalls[k].size();
  const std::size_t wallCount = wallStart.back();
  if (wallCount > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("shared walls: more than 2^32 - 1 wall triangles");
  const FreshArray<Wall> walls = freshArray<Wall>(wallCount);
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), cubeSlabs.size(), [&](std::size_t k) {
      std::copy(slabWalls[k].begin(), slabWalls[k].end(), walls.get() + wallStart[k]);
      std::vector<Wall>().swap(slabWalls[k]);
    });
  });
  // The grid edge of a wall's corner k, as the key of its surfel along +axis from its low voxel.
  auto edgeKey = [&](const Voxel& m, int edge) {
    return Surfel{m + cube::cornerOffset(cube::edgeLowCorner(edge)), directionOf(cube::edgeAxis(edge), +1)}.key();
  };
  // A new vertex's surfel, from the low voxel of its edge where fromLow(priority low, priority
  // high) says so, else from its high voxel.
  auto surfelOf = [&](const Voxel& m, int edge, auto&& fromLow) {
    const Voxel lo = m + cube::cornerOffset(cube::edgeLowCorner(edge));
    const Voxel hi = m + cube::cornerOffset(cube::edgeHighCorner(edge));
    const int axis = cube::edgeAxis(edge);
    return fromLow(priorityAt(lo), priorityAt(hi)) ? Surfel{lo, directionOf(axis, +1)} : Surfel{hi, directionOf(axis, -1)};
  };

  // The complex, with smoothing or decimation: every wall once, as the cube gives it (from its
  // higher priority to its lower), over one vertex per grid edge numbered at its first use, its
  // surfel oriented from its voxel of higher priority; the walls of every label, selected or
  // not, so that the smoothed points do not depend on the selection. Wall w is its triangle w.
  const bool smoothing = o.smooth.has_value(), decimating = o.decimate.has_value();
  const bool keepComplex = smoothing || decimating;
  struct Complex {
    std::vector<Surfel> surfels;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::array<std::uint32_t, 2>> sides;  // each triangle's (inside, outside) priorities
  } complex;
  if (keepComplex) {
    FlatKeyMap vertexOf;
    complex.triangles.resize(wallCount);
    complex.sides.resize(wallCount);
    for (std::size_t w = 0; w < wallCount; ++w) {
      const Voxel m = cubeOf(walls[w]);
      for (int k = 0; k < 3; ++k) {
        const int edge = edgeOf(walls[w], k);
        const auto [v, added] = vertexOf.tryEmplace(edgeKey(m, edge), std::uint32_t(complex.surfels.size()));
        if (added) complex.surfels.push_back(surfelOf(m, edge, [](std::uint32_t pl, std::uint32_t ph) { return pl > ph; }));
        complex.triangles[w][std::size_t(k)] = v;
      }
      complex.sides[w] = {walls[w].inside, walls[w].outside};
    }
  }

  // Each selected label's walls, in order: its slot's range of wallsOf (count, prefix sum, fill).
  std::vector<int> slot(labels.size() + 1, -1);  // priority -> index into the selection, -1 if not selected
  for (std::size_t k = 0; k < selected.size(); ++k) slot[selected[k] + 1] = int(k);
  std::vector<std::size_t> wallsStart(selected.size() + 1, 0);
  for (std::size_t w = 0; w < wallCount; ++w)
    for (const std::uint32_t side : {walls[w].inside, walls[w].outside})
      if (slot[side] >= 0) ++wallsStart[std::size_t(slot[side]) + 1];
  for (std::size_t k = 0; k < selected.size(); ++k) wallsStart[k + 1] += wallsStart[k];
  const FreshArray<std::uint32_t> wallsOf = freshArray<std::uint32_t>(wallsStart.back());
  {
    std::vector<std::size_t> next(wallsStart.begin(), wallsStart.end() - 1);
    for (std::size_t w = 0; w < wallCount; ++w)
      for (const std::uint32_t side : {walls[w].inside, walls[w].outside})
        if (slot[side] >= 0) wallsOf[next[std::size_t(slot[side])]++] = std::uint32_t(w);
  }

  // 3. With smoothing, the complex smoothed from the midpoint mapping (then the geometry); with
  //    decimation, the complex decimated (after the smoothing).
  const ImageGeometry geometry = source.geometry();
  const bool mirrored = geometry.handedness() < 0;
  std::vector<refine::Point3> smoothed;
  SmoothReport complexReport;
  if (keepComplex) {
    smoothed.resize(complex.surfels.size());
    for (std::size_t v = 0; v < smoothed.size(); ++v) smoothed[v] = geometry.toPhysical(MidpointMapping{}(complex.surfels[v]));
  }
  if (smoothing) {
    if (cancelled()) throw Cancelled("extraction cancelled");
    complexReport = smoothComplex(smoothed, complex.surfels, complex.triangles, geometry, *o.smooth, o.cancel);
  }
  std::vector<std::array<std::uint32_t, 3>> undecimated;  // the complex's triangles before
  std::vector<char> removed;
  if (decimating) {
    if (cancelled()) throw Cancelled("extraction cancelled");
    undecimated = complex.triangles;
    decimateWalls(smoothed, complex.triangles, complex.sides, removed, *o.decimate, o.cancel);
  }

  // A label's mesh in grid edges: each of its walls in order, turned over where the label is
  // its outside. The label's own surfel has its voxel inside; a vertex of two other labels (a
  // junction) is oriented from the one of higher priority.
  struct Building {
    std::vector<Surfel> surfels;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::uint32_t> complexVertex;  // with smoothing or decimation: each vertex's in the complex
  };
  // (Triangle i of label k is wall wallsOf[wallsStart[k] + i], the complex's triangle of that
  // index, reversed where the label is its outside.)
  auto build = [&](std::size_t k) {
    Building b;
    const std::uint32_t label = std::uint32_t(selected[k] + 1);
    FlatKeyMap vertexOf;
    const std::size_t n = wallsStart[k + 1] - wallsStart[k];
    vertexOf.reserve(n / 2 + 16);  // (a closed surface has about half as many vertices as triangles)
    b.surfels.reserve(n / 2 + 16);
    b.triangles.reserve(n);
    std::uint64_t lastCube = ~std::uint64_t(0);
    Voxel m{};
    for (std::size_t i = wallsStart[k]; i < wallsStart[k + 1]; ++i) {
      const std::uint32_t w = wallsOf[i];
      if (const std::uint64_t cube = walls[w].cubeAndEdges & ((std::uint64_t(1) << 52) - 1); cube != lastCube) {
        lastCube = cube;  // (a cube's walls are consecutive)
        m = cubeOf(walls[w]);
      }
      std::array<std::uint32_t, 3> tri;
      for (int c = 0; c < 3; ++c) {
        const int edge = edgeOf(walls[w], c);
        const auto [v, added] = vertexOf.tryEmplace(edgeKey(m, edge), std::uint32_t(b.surfels.size()));
        if (added) {
          b.surfels.push_back(surfelOf(m, edge, [&](std::uint32_t pl, std::uint32_t ph) {
            return pl == label || (ph != label && pl > ph);
          }));
          if (keepComplex) b.complexVertex.push_back((decimating ? undecimated : complex.triangles)[w][std::size_t(c)]);
        }
        tri[std::size_t(c)] = v;
      }
      if (walls[w].outside == label) std::swap(tri[1], tri[2]);
      b.triangles.push_back(tri);
    }
    return b;
  };

  // 4. Pinches split, vertices placed (midpoint mapping, then the geometry, or the smoothed
  //    complex's points), figures.
  //    The labels are independent here: in parallel on `threads`, largest first so that the
  //    last to finish are small (each label's mesh is the same for any count).
  std::vector<LabelSurface> out(selected.size());
  std::vector<std::size_t> order(selected.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return wallsStart[a + 1] - wallsStart[a] > wallsStart[b + 1] - wallsStart[b]; });
  arena.execute([&] {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
  for (std::size_t at = range.begin(); at < range.end(); ++at) {
    const std::size_t k = order[at];
    if (cancelled()) throw Cancelled("extraction cancelled");
    Building b = build(k);
    std::vector<std::array<double, 3>> doubled(b.surfels.size());  // exact: 2 x the midpoint
    for (std::size_t v = 0; v < b.surfels.size(); ++v) {
      const Voxel c = b.surfels[v].inside(), d = b.surfels[v].outside();
      doubled[v] = {double(c.x + d.x), double(c.y + d.y), double(c.z + d.z)};
    }
    PinchSplit split;
    try {
      split = splitPinches(doubled, b.triangles);
    } catch (const std::logic_error& e) {
      throw InternalError(std::string("shared walls: ") + e.what());
    }
    out[k] = labelFields(geometry, LabelValue(labels[selected[k]]), voxels[selected[k] + 1], o);
    LabelSurface& result = out[k];
    Surface& s = result.surface;
    s.surfels = std::move(b.surfels);
    for (std::uint32_t v : split.copyOf) s.surfels.push_back(s.surfels[v]);
    s.triangles = std::move(split.triangles);
    s.vertices.resize(s.surfels.size());
    for (std::size_t v = 0; v < s.surfels.size(); ++v) s.vertices[v] = geometry.toPhysical(MidpointMapping{}(s.surfels[v]));
    requirePlacedVertices(geometry, s.vertices, [&](std::size_t v) { return MidpointMapping{}(s.surfels[v]); });
    if (smoothing) {
      // A copy of a pinch is its original's complex vertex: the copies move together.
      SmoothReport report = complexReport;
      for (const ComponentFigures& c : componentFigures(s.vertices, s.triangles)) report.volumeBefore += c.volume;
      if (mirrored) report.volumeBefore = -report.volumeBefore;  // (finishScannedLabel turns the triangles)
      const std::size_t originals = s.surfels.size() - split.copyOf.size();
      for (std::size_t v = 0; v < s.vertices.size(); ++v) {
        const std::uint32_t c = b.complexVertex[v < originals ? v : split.copyOf[v - originals]];
        report.maxDisplacement = std::max(report.maxDisplacement, refine::norm(refine::sub(smoothed[c], s.vertices[v])));
        s.vertices[v] = smoothed[c];
      }
      result.smooth = report;
    }
    if (decimating) {
      // Each label triangle from its complex triangle's survivor: a corner the collapses kept
      // is the label's vertex it was (a pinch's copy included), a new one (a vertex a removed
      // one went into, never a pinch) the label's vertex of that complex vertex.
      DecimateReport report;
      report.trianglesBefore = s.triangles.size();
      if (o.decimate->reduction)
        report.targetTriangles = std::size_t(std::llround((1 - *o.decimate->reduction) * double(s.triangles.size())));
      for (const ComponentFigures& c : componentFigures(s.vertices, s.triangles)) report.volumeBefore += c.volume;
      if (mirrored) report.volumeBefore = -report.volumeBefore;
      std::unordered_map<std::uint32_t, std::uint32_t> vertexOfComplex;
      const std::size_t originals = s.surfels.size() - split.copyOf.size();
      for (std::size_t v = 0; v < originals; ++v) vertexOfComplex.emplace(b.complexVertex[v], std::uint32_t(v));
      std::vector<std::array<std::uint32_t, 3>> kept;
      kept.reserve(s.triangles.size());
      for (std::size_t i = 0; i < s.triangles.size(); ++i) {
        const std::uint32_t c = wallsOf[wallsStart[k] + i];
        if (removed[c]) continue;
        const bool reversed = walls[c].outside == std::uint32_t(selected[k] + 1);
        const auto& was = undecimated[c];
        const auto& now = complex.triangles[c];
        std::array<std::uint32_t, 3> t;
        for (std::size_t corner = 0; corner < 3; ++corner) {
          const auto at = std::find(was.begin(), was.end(), now[corner]);
          if (at != was.end()) {
            int j = int(at - was.begin());
            if (reversed && j) j = 3 - j;  // (the label's triangle is the complex's with corners 1, 2 swapped)
            t[corner] = s.triangles[i][std::size_t(j)];
          } else {
            const auto v = vertexOfComplex.find(now[corner]);
            if (v == vertexOfComplex.end()) throw InternalError("shared walls: a decimated wall's vertex is not its label's");
            t[corner] = v->second;
          }
        }
        if (reversed) std::swap(t[1], t[2]);
        kept.push_back(t);
      }
      // The vertices removed dropped, the others renumbered in order.
      std::vector<std::uint32_t> renumber(s.vertices.size(), ~0u);
      for (const auto& t : kept)
        for (std::uint32_t v : t) renumber[v] = 0;
      std::uint32_t next = 0;
      for (std::size_t v = 0; v < renumber.size(); ++v)
        if (renumber[v] == 0) {
          renumber[v] = next;
          s.vertices[next] = s.vertices[v];
          s.surfels[next] = s.surfels[v];
          ++next;
        }
      s.vertices.resize(next);
      s.surfels.resize(next);
      for (auto& t : kept)
        for (std::uint32_t& v : t) v = renumber[v];
      s.triangles = std::move(kept);
      report.trianglesAfter = s.triangles.size();
      result.decimate = report;
    }
    result.pinchCopies = split.copyOf.size();
    result.pinchedEdges = split.pinchedEdges;
    result.joinedEdges = split.joinedEdges;
    result.unsplitEdges = split.unsplitEdges;
    if (!split.copyOf.empty() || split.pinchedEdges)
      s.warnings.push_back("label " + result.label.text() + " touches itself: " + std::to_string(split.copyOf.size()) +
                           " vertex copies, " + std::to_string(split.pinchedEdges) + " pinched edges (" +
                           std::to_string(split.joinedEdges) + " taken as joined, " + std::to_string(split.unsplitEdges) +
                           " left with four triangles or more; docs/theory.md §12, pinches)");
    finishScannedLabel(s, mirrored, o);
    if (smoothing || decimating) {
      double after = 0;
      if (o.figures)
        for (const ComponentFigures& c : s.components) after += c.volume;
      else
        for (const ComponentFigures& c : componentFigures(s.vertices, s.triangles)) after += c.volume;
      if (smoothing) result.smooth->volumeAfter = decimating ? result.decimate->volumeBefore : after;
      if (decimating) result.decimate->volumeAfter = after;
    }
  }
  });
  });
  return out;
}

}  // namespace surftrack
