// A Decimater module (OpenMesh) that keeps the decimated surface within `tolerance` of the
// original one, both ways, for every point, proven by TriangleCover.h's cuts rather than sampled
// (docs/theory.md §12, "Decimating the complex"; DistanceGuard.h is the sampled bound of §10):
//  - original -> decimated: the original surface is cut into *pieces*, each assigned to a
//    current triangle that it lies within the tolerance of, whole (at the start, every face is
//    its own piece); a collapse must find such a triangle, among those it creates or the others
//    nearby, for every piece of the triangles it removes or replaces (cutting a piece in four
//    where no one triangle takes it whole);
//  - decimated -> original: every triangle a collapse creates lies within the tolerance of the
//    original triangles, whole.
// The complex's decimation uses it: its collapses along junction lines move the borders of
// several walls at once, and there the samples of §10 missed points 4-14 % beyond the bound.
// It refuses more collapses than the sampled bound (those it cannot prove), and on one surface
// it made decimate() about 2.3x slower (docs/theory.md §10), so decimate() keeps DistanceGuard.h.
// Nearby triangles come from uniform grids (TriangleGrid.h), so this is not limited to a
// one-ring.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

#include "MeshTriangles.h"
#include "TriangleCover.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

/// How many times a triangle or a piece is cut in four before the distance bound gives up on
/// proving it (TriangleCover.h): up to 4^3 pieces.
inline constexpr int kDistanceCuts = 3;

template <class MeshT>
class ModProvenDistanceT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModProvenDistanceT, MeshT, ProvenDistance);
  using FaceHandle = typename MeshT::FaceHandle;
  using VertexHandle = typename MeshT::VertexHandle;

  explicit ModProvenDistanceT(MeshT& mesh) : Base(mesh, true) {}
  ~ModProvenDistanceT() override {
    if (piecesOf_.is_valid()) Base::mesh().remove_property(piecesOf_);
  }

  void set_tolerance(double tolerance) { tolerance_ = tolerance; }

  /// For a mesh decimated before (a wall of a complex, DecimatedComplex.h): the surface it is
  /// measured against is `original` instead of its faces at initialize(), and face f answers
  /// for the pieces `pieces[f]` (of `original`, within the tolerance of f) instead of itself.
  void set_history(std::vector<Triangle3> original, std::vector<std::vector<Triangle3>> pieces) {
    historyOriginal_ = std::move(original);
    historyPieces_ = std::move(pieces);
    history_ = true;
  }

  /// The pieces of the original surface face f answers for now.
  const std::vector<Triangle3>& pieces(FaceHandle f) { return Base::mesh().property(piecesOf_, f); }

  void initialize() override {
    MeshT& m = Base::mesh();
    if (!piecesOf_.is_valid()) m.add_property(piecesOf_);
    original_.clear();
    originalBox_.clear();
    lastHit_ = 0;
    if (history_) {
      Box3 bounds = LiveTriangleGrid<MeshT>::boundsOf(m);
      for (const Triangle3& t : historyOriginal_) {
        const Box3 b = boxOf(t);
        for (int k = 0; k < 3; ++k) {
          bounds.lo[k] = std::min(bounds.lo[k], b.lo[k]);
          bounds.hi[k] = std::max(bounds.hi[k], b.hi[k]);
        }
      }
      originalGrid_.reset(bounds, 2 * std::max(tolerance_, meanEdgeLength(m)));
      currentGrid_.build(m, tolerance_);
      for (const Triangle3& t : historyOriginal_) {
        originalGrid_.insert(std::uint32_t(original_.size()), 0, boxOf(t));
        original_.push_back(t);
        originalBox_.push_back(boxOf(t));
      }
      if (original_.empty()) throw std::logic_error("ModProvenDistanceT: a history without its original surface");
      for (auto f : m.faces()) m.property(piecesOf_, f) = historyPieces_.at(std::size_t(f.idx()));
      return;
    }
    // Cells about twice the larger of the tolerance and the mean edge length: a triangle
    // meets a few cells, a query a few more.
    originalGrid_.reset(LiveTriangleGrid<MeshT>::boundsOf(m), 2 * std::max(tolerance_, meanEdgeLength(m)));
    currentGrid_.build(m, tolerance_);
    for (auto f : m.faces()) {
      const Triangle3 t = triangleOf(m, f);
      originalGrid_.insert(std::uint32_t(original_.size()), 0, boxOf(t));
      original_.push_back(t);
      originalBox_.push_back(boxOf(t));
      m.property(piecesOf_, f).assign(1, t);
    }
  }

  float collapse_priority(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    evaluated_ = ci.v0v1;
    created_.clear();
    createdFace_.clear();
    forEachCreatedTriangle(m, ci, [&](FaceHandle f, const auto&, const Triangle3& t) {
      created_.push_back(t);
      createdFace_.push_back(f);
    });
    // Decimated -> original: each created triangle whole.
    for (const Triangle3& t : created_)
      if (!coverTriangle<std::uint32_t>(t, tolerance_, kDistanceCuts, [&](const Box3& box, auto&& visit) {
            nearOriginal(box, visit);
          }))
        return float(Base::ILLEGAL_COLLAPSE);
    // Original -> decimated: a piece of a face that the collapse keeps (with v1 for v0) is most
    // often still near that face, so it is tried first; the face each piece is proven near is
    // kept for postprocess_collapse.
    assigned_.clear();
    for (auto f : m.vf_range(ci.v0)) {
      std::size_t own = created_.size();
      for (std::size_t i = 0; i < createdFace_.size(); ++i)
        if (createdFace_[i] == f) own = i;
      for (const Triangle3& piece : m.property(piecesOf_, f))
        if (!coverTriangle<FaceHandle>(piece, tolerance_, kDistanceCuts,
                                       [&](const Box3& box, auto&& visit) {
                                         if (own < created_.size() && visit(createdFace_[own], created_[own])) return;
                                         for (std::size_t i = 0; i < created_.size(); ++i)
                                           if (i != own && visit(createdFace_[i], created_[i])) return;
                                         nearCurrent(box, ci.v0, visit);
                                       },
                                       &assigned_))
          return float(Base::ILLEGAL_COLLAPSE);
    }
    return float(Base::LEGAL_COLLAPSE);
  }

  void preprocess_collapse(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    for (auto f : m.vf_range(ci.v0)) m.property(piecesOf_, f).clear();
    // The collapse is the one just evaluated (CheckedDecimater.h asks every module right
    // before it collapses), so the faces found there take the pieces.
    if (evaluated_ != ci.v0v1) throw std::logic_error("ModProvenDistanceT: a collapse that was not just evaluated");
  }

  void postprocess_collapse(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    for (const auto& [piece, f] : assigned_) m.property(piecesOf_, f).push_back(piece);
    currentGrid_.collapsed(m, ci.v1, ci.fl, ci.fr);
    evaluated_ = typename MeshT::HalfedgeHandle();
  }

 private:
  /// Offers the original triangles whose boxes meet `box` (the last one proven near first).
  template <class Visit>
  void nearOriginal(const Box3& box, Visit&& visit) {
    if (lastHit_ < original_.size() && originalBox_[lastHit_].meets(box) && visit(lastHit_, original_[lastHit_])) return;
    bool stop = false;
    originalGrid_.near(box, [&](std::uint32_t id, std::uint32_t) {
      if (!stop && originalBox_[id].meets(box) && visit(id, original_[id])) {
        stop = true;
        lastHit_ = id;
      }
    });
  }
  /// Offers the current triangles whose boxes meet `box` but those of `skip` (the collapsing
  /// vertex).
  template <class Visit>
  void nearCurrent(const Box3& box, VertexHandle skip, Visit&& visit) {
    MeshT& m = Base::mesh();
    bool stop = false;
    currentGrid_.near(box, [&](FaceHandle f) {
      if (stop) return;
      Triangle3 t;
      auto h = m.halfedge_handle(f);
      for (int k = 0; k < 3; ++k, h = m.next_halfedge_handle(h)) {
        const VertexHandle v = m.to_vertex_handle(h);
        if (v == skip) return;
        t[k] = pointOf(m.point(v));
      }
      stop = visit(f, t);
    });
  }

  double tolerance_ = 1;
  bool history_ = false;
  std::vector<Triangle3> historyOriginal_;
  std::vector<std::vector<Triangle3>> historyPieces_;
  std::vector<Triangle3> original_, created_;
  std::vector<Box3> originalBox_;
  std::vector<FaceHandle> createdFace_;
  std::vector<std::pair<Triangle3, FaceHandle>> assigned_;
  std::uint32_t lastHit_ = 0;
  typename MeshT::HalfedgeHandle evaluated_;
  TriangleGrid originalGrid_;
  LiveTriangleGrid<MeshT> currentGrid_;
  OpenMesh::FPropHandleT<std::vector<Triangle3>> piecesOf_;  // each face's pieces, in place
};

}  // namespace surftrack::refine
