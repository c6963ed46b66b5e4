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
#include <vector>

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

#include "TriangleGrid.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

template <class MeshT>
class ModSampledDistanceT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModSampledDistanceT, MeshT, SampledDistance);
  using FaceHandle = typename MeshT::FaceHandle;

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
    lastHit_ = 0;
    samples_.clear();
    // Cells about twice the larger of the tolerance and the mean edge length: a triangle
    // meets a few cells, a query a few more.
    double edges = 0;
    for (auto e : m.edges()) edges += m.calc_edge_length(e);
    const double cell = 2 * std::max(tolerance_, m.n_edges() ? edges / double(m.n_edges()) : 1.0);
    originalGrid_.clear(cell);
    currentGrid_.clear(cell);
    for (auto f : m.faces()) {
      const Triangle3 t = triangleOf(f);
      originalGrid_.insert(std::uint32_t(original_.size()), t);
      currentGrid_.insert(std::uint32_t(f.idx()), t);
      original_.push_back(t);
      auto& list = m.property(samplesOf_, f);
      list.clear();
      addSample(list, {(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3,
                       (t[0][2] + t[1][2] + t[2][2]) / 3});
    }
    for (auto e : m.edges()) {
      const auto h = m.halfedge_handle(e, 0);
      const auto a = m.point(m.from_vertex_handle(h)), b = m.point(m.to_vertex_handle(h));
      addSample(m.property(samplesOf_, m.face_handle(h)), {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
    }
    for (auto v : m.vertices()) {
      const auto p = m.point(v);
      addSample(m.property(samplesOf_, *m.vf_range(v).begin()), {p[0], p[1], p[2]});
    }
  }

  float collapse_priority(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    created_.clear();
    for (auto f : m.vf_range(ci.v0)) {
      if (f == ci.fl || f == ci.fr) continue;
      Triangle3 t;
      int k = 0;
      for (auto v : m.fv_range(f)) t[k++] = v == ci.v0 ? pointOf(ci.p1) : pointOf(m.point(v));
      created_.push_back(t);
    }
    const double e2 = tolerance_ * tolerance_;
    // Decimated -> original.
    for (const Triangle3& t : created_)
      for (int i = 0; i <= kSteps; ++i)
        for (int j = 0; i + j <= kSteps; ++j) {
          const double a = double(i) / kSteps, b = double(j) / kSteps, c = 1 - a - b;
          const Point3 p{a * t[0][0] + b * t[1][0] + c * t[2][0], a * t[0][1] + b * t[1][1] + c * t[2][1],
                         a * t[0][2] + b * t[1][2] + c * t[2][2]};
          if (!nearOriginal(p, e2)) return float(Base::ILLEGAL_COLLAPSE);
        }
    // Original -> decimated.
    for (auto f : m.vf_range(ci.v0))
      for (std::uint32_t s : m.property(samplesOf_, f))
        if (!nearCurrent(samples_[s], e2, ci.v0, nullptr)) return float(Base::ILLEGAL_COLLAPSE);
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
  }

  void postprocess_collapse(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    created_.clear();
    for (auto f : m.vf_range(ci.v1)) currentGrid_.insert(std::uint32_t(f.idx()), triangleOf(f));
    const double e2 = tolerance_ * tolerance_;
    for (std::uint32_t s : pending_) {
      // The nearest of v1's triangles if one is within the tolerance, else the nearest nearby.
      FaceHandle best;
      double bestD = e2;
      for (auto f : m.vf_range(ci.v1)) {
        const double d = squaredDistanceToTriangle(samples_[s], triangleOf(f));
        if (d <= bestD) {
          bestD = d;
          best = f;
        }
      }
      if (!best.is_valid()) nearCurrent(samples_[s], e2, typename MeshT::VertexHandle(), &best);
      if (!best.is_valid()) best = *m.vf_range(ci.v1).begin();  // (the check found one; rounding)
      m.property(samplesOf_, best).push_back(s);
    }
  }

 private:
  template <class P>
  static Point3 pointOf(const P& p) { return {double(p[0]), double(p[1]), double(p[2])}; }
  Triangle3 triangleOf(FaceHandle f) {
    Triangle3 t;
    int k = 0;
    for (auto v : Base::mesh().fv_range(f)) t[k++] = pointOf(Base::mesh().point(v));
    return t;
  }
  void addSample(std::vector<std::uint32_t>& list, const Point3& p) {
    list.push_back(std::uint32_t(samples_.size()));
    samples_.push_back(p);
  }
  bool nearOriginal(const Point3& p, double e2) {
    // Neighbouring samples are most often near the same original triangle: try it first.
    if (squaredDistanceToTriangle(p, original_[lastHit_]) <= e2) return true;
    bool found = false;
    originalGrid_.near({p, p, p}, tolerance_, [&](std::uint32_t id) {
      if (!found && squaredDistanceToTriangle(p, original_[id]) <= e2) {
        found = true;
        lastHit_ = id;
      }
    });
    return found;
  }
  /// A current triangle within the tolerance of p: one of created_, or one without `skip`
  /// (the collapsing vertex); the nearest one into *best if asked.
  bool nearCurrent(const Point3& p, double e2, typename MeshT::VertexHandle skip, FaceHandle* best) {
    for (const Triangle3& t : created_)
      if (squaredDistanceToTriangle(p, t) <= e2) return true;
    MeshT& m = Base::mesh();
    double bestD = e2;
    bool found = false;
    currentGrid_.near({p, p, p}, tolerance_, [&](std::uint32_t id) {
      if (found && !best) return;
      const FaceHandle f{int(id)};
      if (m.status(f).deleted()) return;
      Triangle3 t;
      int k = 0;
      bool hasSkip = false;
      for (auto v : m.fv_range(f)) {
        hasSkip = hasSkip || v == skip;
        t[k++] = pointOf(m.point(v));
      }
      if (hasSkip) return;
      const double d = squaredDistanceToTriangle(p, t);
      if (d <= bestD) {
        found = true;
        bestD = d;
        if (best) *best = f;
      }
    });
    return found;
  }

  double tolerance_ = 1;
  std::vector<Triangle3> original_, created_;
  std::vector<Point3> samples_;
  std::vector<std::uint32_t> pending_;
  std::uint32_t lastHit_ = 0;
  TriangleGrid originalGrid_, currentGrid_;
  OpenMesh::FPropHandleT<std::vector<std::uint32_t>> samplesOf_;
};

}  // namespace surftrack::refine
