// A Decimater module (OpenMesh) that keeps the decimated surface within `tolerance` of the
// original one, both ways, on samples (docs/theory.md, section 10):
//  - original -> decimated: every original vertex, edge midpoint and triangle centroid is
//    assigned to a current triangle within the tolerance (as OpenMesh's ModHausdorffT does for
//    the vertices alone); a collapse must find such a triangle, among those it creates or the
//    others nearby, for every sample of the triangles it removes or replaces;
//  - decimated -> original: the points of barycentric coordinates (i, j, k) / 4 of every
//    triangle a collapse creates lie within the tolerance of an original triangle.
// Nearby triangles come from uniform grids (TriangleGrid.h), so this is not limited to a
// one-ring.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

#include "MeshTriangles.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

template <class MeshT>
class ModSampledDistanceT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModSampledDistanceT, MeshT, SampledDistance);
  using FaceHandle = typename MeshT::FaceHandle;
  using VertexHandle = typename MeshT::VertexHandle;

  explicit ModSampledDistanceT(MeshT& mesh) : Base(mesh, true) {}
  ~ModSampledDistanceT() override {
    if (samplesOf_.is_valid()) Base::mesh().remove_property(samplesOf_);
  }

  /// The barycentric step of the samples of a created triangle: 1 / kSteps.
  static constexpr int kSteps = 4;

  void set_tolerance(double tolerance) { tolerance_ = tolerance; }

  void initialize() override {
    MeshT& m = Base::mesh();
    if (!samplesOf_.is_valid()) m.add_property(samplesOf_);
    original_.clear();
    originalBox_.clear();
    lastHit_ = 0;
    // Cells about twice the larger of the tolerance and the mean edge length: a triangle
    // meets a few cells, a query a few more.
    originalGrid_.reset(LiveTriangleGrid<MeshT>::boundsOf(m), 2 * std::max(tolerance_, meanEdgeLength(m)));
    currentGrid_.build(m, tolerance_);
    for (auto f : m.faces()) {
      const Triangle3 t = triangleOf(m, f);
      originalGrid_.insert(std::uint32_t(original_.size()), 0, boxOf(t));
      original_.push_back(t);
      originalBox_.push_back(boxOf(t));
      auto& list = m.property(samplesOf_, f);
      list.clear();
      list.push_back({(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3,
                      (t[0][2] + t[1][2] + t[2][2]) / 3});
    }
    for (auto e : m.edges()) {
      const auto h = m.halfedge_handle(e, 0);
      const auto a = m.point(m.from_vertex_handle(h)), b = m.point(m.to_vertex_handle(h));
      m.property(samplesOf_, m.face_handle(h)).push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
    }
    for (auto v : m.vertices()) {
      const auto p = m.point(v);
      m.property(samplesOf_, *m.vf_range(v).begin()).push_back(pointOf(p));
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
    const double e2 = tolerance_ * tolerance_;
    // Decimated -> original. The distance to a triangle is a convex function, so when the
    // three corners of a created triangle are within the tolerance of one original triangle,
    // so is every point of it (its samples need no test).
    for (const Triangle3& t : created_) {
      std::uint32_t hit = 0;
      if (!nearOriginal(t[0], e2, &hit)) return float(Base::ILLEGAL_COLLAPSE);
      if (squaredDistanceToTriangle(t[1], original_[hit]) <= e2 &&
          squaredDistanceToTriangle(t[2], original_[hit]) <= e2)
        continue;
      for (int i = 0; i <= kSteps; ++i)
        for (int j = 0; i + j <= kSteps; ++j) {
          const double a = double(i) / kSteps, b = double(j) / kSteps, c = 1 - a - b;
          const Point3 p{a * t[0][0] + b * t[1][0] + c * t[2][0], a * t[0][1] + b * t[1][1] + c * t[2][1],
                         a * t[0][2] + b * t[1][2] + c * t[2][2]};
          if (!nearOriginal(p, e2, nullptr)) return float(Base::ILLEGAL_COLLAPSE);
        }
    }
    // Original -> decimated: a sample of a face that the collapse keeps (with v1 for v0) is
    // most often still near that face, so it is tried first; the face each sample is found
    // near is kept for postprocess_collapse.
    assigned_.clear();
    for (auto f : m.vf_range(ci.v0)) {
      std::size_t own = created_.size();
      for (std::size_t i = 0; i < createdFace_.size(); ++i)
        if (createdFace_[i] == f) own = i;
      for (const Point3& p : m.property(samplesOf_, f)) {
        FaceHandle found;
        if (own < created_.size() && squaredDistanceToTriangle(p, created_[own]) <= e2) found = f;
        for (std::size_t i = 0; i < created_.size() && !found.is_valid(); ++i)
          if (squaredDistanceToTriangle(p, created_[i]) <= e2) found = createdFace_[i];
        if (!found.is_valid()) found = nearCurrent(p, e2, ci.v0);
        if (!found.is_valid()) return float(Base::ILLEGAL_COLLAPSE);
        assigned_.push_back(found);
      }
    }
    return float(Base::LEGAL_COLLAPSE);
  }

  void preprocess_collapse(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    pending_.clear();
    for (auto f : m.vf_range(ci.v0)) {
      auto& list = m.property(samplesOf_, f);
      pending_.insert(pending_.end(), list.begin(), list.end());
      list.clear();
    }
    // The collapse is the one just evaluated (CheckedDecimater.h asks every module right
    // before it collapses), so the faces found there take the samples.
    if (evaluated_ != ci.v0v1 || assigned_.size() != pending_.size())
      throw std::logic_error("ModSampledDistanceT: a collapse that was not just evaluated");
  }

  void postprocess_collapse(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    for (std::size_t k = 0; k < pending_.size(); ++k) m.property(samplesOf_, assigned_[k]).push_back(pending_[k]);
    currentGrid_.collapsed(m, ci.v1, ci.fl, ci.fr);
    evaluated_ = typename MeshT::HalfedgeHandle();
  }

 private:
  /// p is within the tolerance of an original triangle (its index into *hit if asked).
  bool nearOriginal(const Point3& p, double e2, std::uint32_t* hit) {
    // Neighbouring samples are most often near the same original triangle: try it first.
    if (squaredDistanceToTriangle(p, original_[lastHit_]) <= e2) {
      if (hit) *hit = lastHit_;
      return true;
    }
    bool found = false;
    const Box3 query = boxOf({p, p, p}, tolerance_);
    originalGrid_.near(query, [&](std::uint32_t id, std::uint32_t) {
      // Only a triangle whose box meets the query box can be within the tolerance.
      if (!found && originalBox_[id].meets(query) && squaredDistanceToTriangle(p, original_[id]) <= e2) {
        found = true;
        lastHit_ = id;
      }
    });
    if (found && hit) *hit = lastHit_;
    return found;
  }
  /// A current triangle within the tolerance of p that does not have `skip` (the collapsing
  /// vertex), or an invalid handle.
  FaceHandle nearCurrent(const Point3& p, double e2, VertexHandle skip) {
    MeshT& m = Base::mesh();
    FaceHandle found;
    currentGrid_.near(boxOf({p, p, p}, tolerance_), [&](FaceHandle f) {
      if (found.is_valid()) return;
      Triangle3 t;
      auto h = m.halfedge_handle(f);
      for (int k = 0; k < 3; ++k, h = m.next_halfedge_handle(h)) {
        const VertexHandle v = m.to_vertex_handle(h);
        if (v == skip) return;
        t[k] = pointOf(m.point(v));
      }
      if (squaredDistanceToTriangle(p, t) <= e2) found = f;
    });
    return found;
  }

  double tolerance_ = 1;
  std::vector<Triangle3> original_, created_;
  std::vector<Box3> originalBox_;
  std::vector<FaceHandle> createdFace_, assigned_;
  std::vector<Point3> pending_;
  std::uint32_t lastHit_ = 0;
  typename MeshT::HalfedgeHandle evaluated_;
  TriangleGrid originalGrid_;
  LiveTriangleGrid<MeshT> currentGrid_;
  OpenMesh::FPropHandleT<std::vector<Point3>> samplesOf_;  // each face's samples, in place
};

}  // namespace surftrack::refine
