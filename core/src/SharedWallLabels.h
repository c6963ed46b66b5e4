// extractLabels with LabelWalls::Shared (docs/theory.md, "Shared walls"): every label's surface
// as a part of one conforming complex. One scan of the digital 3-cubes gives each cube's walls
// (converter/NestedWalls.h: the nested analogs of the labels in priority order, the background
// lowest, then by increasing label); each wall triangle goes to the two labels it separates,
// as it is to the one inside and reversed to the one outside. A vertex is a grid edge between
// two voxels of different labels (a surfel), numbered per label at its first use; where a label
// touches itself at a vertex or an edge the pinch is split (converter/PinchSplit.h) and counted.
// With LabelOptions::smooth the scan also keeps the complex itself (every wall once, over one
// vertex per surfel), which is smoothed as a whole (ComplexSmoothing.h); each label's vertex
// then takes its complex vertex's point, so a vertex has one point in every label. With
// LabelOptions::decimate the complex (smoothed or not) is decimated wall by wall
// (WallDecimation.h), and each label's triangles are its walls' survivors, over its own vertices
// (a pinch's copies kept where they were: the decimation never touches a pinch).
// One thread for the scan, the labels' meshes then finished in parallel; the same for any
// `threads`.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <numeric>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "BoundaryMapping.h"
#include "ComplexSmoothing.h"
#include "DigitalCube.h"
#include "FlatKeyMap.h"
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
  // 1. Priorities: the background (and every voxel outside the domain) 0, the labels 1, 2, ...
  //    by increasing value.
  std::vector<T> labels;
  labels.reserve(std::size_t(dims.nx) * std::size_t(dims.ny) * std::size_t(dims.nz));
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x)
        if (image.at(x, y, z) != background) labels.push_back(image.at(x, y, z));
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  const std::vector<std::size_t> selected = select(labels);
  std::vector<std::uint32_t> priority(std::size_t(dims.nx) * std::size_t(dims.ny) * std::size_t(dims.nz));
  std::vector<std::uint64_t> voxels(labels.size() + 1, 0);
  for (int z = 0, i = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x, ++i) {
        const T v = image.at(x, y, z);
        const auto p = v == background
                           ? 0u
                           : std::uint32_t(std::lower_bound(labels.begin(), labels.end(), v) - labels.begin()) + 1;
        priority[std::size_t(i)] = p;
        ++voxels[p];
      }
  auto priorityAt = [&](const Voxel& v) -> std::uint32_t {
    if (!dims.contains(v)) return 0;
    return priority[std::size_t(v.x) + std::size_t(dims.nx) * (std::size_t(v.y) + std::size_t(dims.ny) * std::size_t(v.z))];
  };

  // 2. Each selected label's mesh, in grid edges.
  struct Building {
    FlatKeyMap vertexOf;  // grid edge key -> vertex
    std::vector<Surfel> surfels;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::uint32_t> complexVertex;  // with smoothing or decimation: each vertex's in the complex
    std::vector<std::uint32_t> complexTriangle;  // with decimation: each triangle's in the complex
    std::vector<char> reversed;                  // ... and whether it is that one reversed
  };
  // The complex, with smoothing only: every wall once, as the cube gives it (from its higher
  // priority to its lower), over one vertex per grid edge, its surfel oriented from its voxel of
  // higher priority; the walls of every label, selected or not, so that the smoothed points do
  // not depend on the selection.
  const bool smoothing = o.smooth.has_value(), decimating = o.decimate.has_value();
  const bool keepComplex = smoothing || decimating;
  struct Complex {
    FlatKeyMap vertexOf;
    std::vector<Surfel> surfels;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::array<std::uint32_t, 2>> sides;  // each triangle's (inside, outside) priorities
  } complex;
  // The vertex of cube m's edge in a vertex map keyed by grid edge, and whether it is new; a new
  // one gets its surfel from its low voxel where fromLow(priority low, priority high) says so,
  // else from its high voxel.
  auto vertexOfEdge = [&](FlatKeyMap& vertexOf, std::vector<Surfel>& surfels,
                          const Voxel& m, int edge, auto&& fromLow) {
    const Voxel lo = m + cube::cornerOffset(cube::edgeLowCorner(edge));
    const Voxel hi = m + cube::cornerOffset(cube::edgeHighCorner(edge));
    const int axis = cube::edgeAxis(edge);
    const auto [v, added] = vertexOf.tryEmplace(Surfel{lo, directionOf(axis, +1)}.key(), std::uint32_t(surfels.size()));
    if (added)
      surfels.push_back(fromLow(priorityAt(lo), priorityAt(hi)) ? Surfel{lo, directionOf(axis, +1)}
                                                                : Surfel{hi, directionOf(axis, -1)});
    return std::pair<std::uint32_t, bool>{v, added};
  };
  auto complexVertex = [&](const Voxel& m, int edge) {
    return vertexOfEdge(complex.vertexOf, complex.surfels, m, edge,
                        [](std::uint32_t pl, std::uint32_t ph) { return pl > ph; }).first;
  };
  std::vector<int> slot(labels.size() + 1, -1);  // priority -> index into building, -1 if not selected
  std::vector<Building> building(selected.size());
  for (std::size_t k = 0; k < selected.size(); ++k) slot[selected[k] + 1] = int(k);
  std::unordered_map<std::uint32_t, CubeWalls> cache;  // by the corners' local ranks, 3 bits each
  auto vertex = [&](Building& b, std::uint32_t label, const Voxel& m, int edge) {
    // The label's own surfel has its voxel inside; a vertex of two other labels (a junction) is
    // oriented from the one of higher priority.
    const auto [v, added] = vertexOfEdge(b.vertexOf, b.surfels, m, edge, [&](std::uint32_t pl, std::uint32_t ph) {
      return pl == label || (ph != label && pl > ph);
    });
    if (added && keepComplex) b.complexVertex.push_back(complexVertex(m, edge));
    return v;
  };
  for (int z = -1; z < dims.nz; ++z)
    for (int y = -1; y < dims.ny; ++y)
      for (int x = -1; x < dims.nx; ++x) {
        const Voxel m{x, y, z};
        std::array<std::uint32_t, 8> p;
        for (int i = 0; i < 8; ++i) p[std::size_t(i)] = priorityAt(m + cube::cornerOffset(i));
        std::array<std::uint32_t, 8> distinct = p;
        std::sort(distinct.begin(), distinct.end());
        const auto end = std::unique(distinct.begin(), distinct.end());
        if (end - distinct.begin() == 1) continue;
        std::array<std::uint8_t, 8> local;
        std::uint32_t key = 0;
        for (int i = 0; i < 8; ++i) {
          local[std::size_t(i)] = std::uint8_t(std::lower_bound(distinct.begin(), end, p[std::size_t(i)]) - distinct.begin());
          key |= std::uint32_t(local[std::size_t(i)]) << (3 * i);
        }
        auto at = cache.find(key);
        if (at == cache.end()) at = cache.emplace(key, cubeWalls(local, o.pair)).first;
        const CubeWalls& walls = at->second;
        for (int w = 0; w < walls.count; ++w) {
          const WallTriangle& t = walls.triangles[std::size_t(w)];
          if (keepComplex) {
            complex.triangles.push_back(
                {complexVertex(m, t.edges[0]), complexVertex(m, t.edges[1]), complexVertex(m, t.edges[2])});
            complex.sides.push_back({distinct[t.inside], distinct[t.outside]});
          }
          for (const bool reversed : {false, true}) {
            const std::uint32_t label = distinct[reversed ? t.outside : t.inside];
            if (slot[label] < 0) continue;
            Building& b = building[std::size_t(slot[label])];
            std::array<std::uint32_t, 3> tri{vertex(b, label, m, t.edges[0]), vertex(b, label, m, t.edges[1]),
                                             vertex(b, label, m, t.edges[2])};
            if (reversed) std::swap(tri[1], tri[2]);
            b.triangles.push_back(tri);
            if (decimating) {
              b.complexTriangle.push_back(std::uint32_t(complex.triangles.size() - 1));
              b.reversed.push_back(char(reversed));
            }
          }
        }
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
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
    complexReport = smoothComplex(smoothed, complex.surfels, complex.triangles, geometry, *o.smooth, o.cancel);
  }
  std::vector<std::array<std::uint32_t, 3>> undecimated;  // the complex's triangles before
  std::vector<char> removed;
  if (decimating) {
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
    undecimated = complex.triangles;
    decimateWalls(smoothed, complex.triangles, complex.sides, removed, *o.decimate, o.cancel);
  }

  // 4. Pinches split, vertices placed (midpoint mapping, then the geometry, or the smoothed
  //    complex's points), figures.
  //    The labels are independent here: in parallel on `threads`, largest first so that the
  //    last to finish are small (each label's mesh is the same for any count).
  std::vector<LabelSurface> out(selected.size());
  std::vector<std::size_t> order(selected.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return building[a].triangles.size() > building[b].triangles.size(); });
  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  arena.execute([&] {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
  for (std::size_t at = range.begin(); at < range.end(); ++at) {
    const std::size_t k = order[at];
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
    Building& b = building[k];
    b.vertexOf.clear();  // done with it
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
        const std::uint32_t c = b.complexTriangle[i];
        if (removed[c]) continue;
        const auto& was = undecimated[c];
        const auto& now = complex.triangles[c];
        std::array<std::uint32_t, 3> t;
        for (int k = 0; k < 3; ++k) {
          const auto at = std::find(was.begin(), was.end(), now[std::size_t(k)]);
          if (at != was.end()) {
            int j = int(at - was.begin());
            if (b.reversed[i] && j) j = 3 - j;  // (the label's triangle is the complex's with corners 1, 2 swapped)
            t[std::size_t(k)] = s.triangles[i][std::size_t(j)];
          } else {
            const auto v = vertexOfComplex.find(now[std::size_t(k)]);
            if (v == vertexOfComplex.end()) throw InternalError("shared walls: a decimated wall's vertex is not its label's");
            t[std::size_t(k)] = v->second;
          }
        }
        if (b.reversed[i]) std::swap(t[1], t[2]);
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
