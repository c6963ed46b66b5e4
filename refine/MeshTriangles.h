// What the decimation guards (EmbeddingGuard.h, DistanceGuard.h; docs/theory.md, section 10)
// read of an OpenMesh triangle mesh: a face's points, the mean edge length, and a grid of the
// current faces that follows the collapses.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "TriangleGrid.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

template <class P>
Point3 pointOf(const P& p) {
  return {double(p[0]), double(p[1]), double(p[2])};
}

/// The points of face f, in its orientation order.
template <class MeshT>
Triangle3 triangleOf(const MeshT& m, typename MeshT::FaceHandle f) {
  auto h = m.halfedge_handle(f);
  Triangle3 t;
  for (int k = 0; k < 3; ++k, h = m.next_halfedge_handle(h)) t[k] = pointOf(m.point(m.to_vertex_handle(h)));
  return t;
}

/// The triangles a halfedge collapse v0 -> v1 creates (docs/theory.md, section 10): v0's faces
/// but the two on the collapsing edge, with v1 (at ci.p1) for v0. Calls fn(f, vertices, points)
/// for each, f the face that becomes it.
template <class MeshT, class CollapseInfo, class Fn>
void forEachCreatedTriangle(const MeshT& m, const CollapseInfo& ci, Fn&& fn) {
  for (auto f : m.vf_range(ci.v0)) {
    if (f == ci.fl || f == ci.fr) continue;
    std::array<typename MeshT::VertexHandle, 3> vertices;
    Triangle3 points;
    auto h = m.halfedge_handle(f);
    for (int k = 0; k < 3; ++k, h = m.next_halfedge_handle(h)) {
      const auto v = m.to_vertex_handle(h);
      vertices[k] = v == ci.v0 ? ci.v1 : v;
      points[k] = pointOf(v == ci.v0 ? ci.p1 : m.point(v));
    }
    fn(f, vertices, points);
  }
}

/// The mean length of the mesh's (undeleted) edges; 1 without edges.
template <class MeshT>
double meanEdgeLength(const MeshT& m) {
  double total = 0;
  std::size_t count = 0;
  for (auto e : m.edges()) {
    total += m.calc_edge_length(e);
    ++count;
  }
  return count ? total / double(count) : 1.0;
}

/// A TriangleGrid of the current faces of a mesh under halfedge collapses: the faces a collapse
/// changes (those around the surviving vertex) are entered again after it, so every face is
/// listed in the cells of its current box, and the box of every face is kept in a flat array,
/// so that a query skips the stale ids and the faces whose boxes miss it without reading the
/// mesh. Cells are about twice the larger of `minimumCell` and the mean edge length; as the
/// collapses make the triangles larger and leave stale ids, the grid is rebuilt from the live
/// faces whenever their number has halved, so a query meets a few cells of a few ids whatever
/// the stage of the decimation.
template <class MeshT>
class LiveTriangleGrid {
 public:
  using FaceHandle = typename MeshT::FaceHandle;
  using VertexHandle = typename MeshT::VertexHandle;

  void build(const MeshT& m, double minimumCell) {
    minimumCell_ = minimumCell;
    live_ = 0;
    box_.assign(m.n_faces(), kNoBox);
    version_.resize(m.n_faces(), 0);
    for (auto f : m.faces()) {
      box_[f.idx()] = boxOf(triangleOf(m, f));
      ++live_;
    }
    builtWith_ = live_;
    grid_.reset(boundsOf(m), 2 * std::max(minimumCell_, meanEdgeLength(m)));
    for (auto f : m.faces()) grid_.insert(std::uint32_t(f.idx()), version_[f.idx()], box_[f.idx()]);
  }

  /// After the collapse of a halfedge into v1 that removed faces fl and fr.
  void collapsed(const MeshT& m, VertexHandle v1, FaceHandle fl, FaceHandle fr) {
    for (FaceHandle f : {fl, fr})
      if (f.is_valid()) {
        box_[f.idx()] = kNoBox;
        ++version_[f.idx()];
        --live_;
      }
    if (2 * live_ <= builtWith_) {
      build(m, minimumCell_);
      return;
    }
    for (auto f : m.vf_range(v1)) {
      box_[f.idx()] = boxOf(triangleOf(m, f));
      grid_.insert(std::uint32_t(f.idx()), ++version_[f.idx()], box_[f.idx()]);
    }
  }

  /// Calls visit(f) for the live faces whose boxes meet `box`, each once per cell of `box` it
  /// meets (and unlinks the stale entries it walks over).
  template <class Visit>
  void near(const Box3& box, Visit&& visit) {
    grid_.sweep(
        box, [&](std::uint32_t id, std::uint32_t version) { return version != version_[id]; },
        [&](std::uint32_t id, std::uint32_t) {
          if (box_[id].meets(box)) visit(FaceHandle(int(id)));
        });
  }

  /// The bounding box of the mesh's points (which halfedge collapses never move).
  static Box3 boundsOf(const MeshT& m) {
    Box3 b{{0, 0, 0}, {0, 0, 0}};
    bool first = true;
    for (auto v : m.vertices()) {
      const Point3 p = pointOf(m.point(v));
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = first ? p[k] : std::min(b.lo[k], p[k]);
        b.hi[k] = first ? p[k] : std::max(b.hi[k], p[k]);
      }
      first = false;
    }
    return b;
  }

 private:
  static constexpr Box3 kNoBox{{1, 1, 1}, {-1, -1, -1}};  // meets no box
  TriangleGrid grid_;
  std::vector<Box3> box_;
  std::vector<std::uint32_t> version_;
  double minimumCell_ = 0;
  std::size_t live_ = 0, builtWith_ = 0;
};

}  // namespace surftrack::refine
