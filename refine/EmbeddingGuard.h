// A Decimater module (OpenMesh) that allows a halfedge collapse v0 -> v1 only when the mesh
// stays embedded (docs/theory.md, section 10): none of the triangles the collapse creates (the
// triangles of v0 other than the two it removes, with v0 replaced by v1) may meet another
// triangle of the mesh, old or new, other than in the vertices and the edge they share. The
// other triangles are found through a uniform grid of their bounding boxes, updated after every
// collapse, so the check is not limited to a topological neighbourhood: two sheets of the surface
// that lie close together are caught as well. Tests in floating point, conservative
// (TriangleIntersection.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

#include "TriangleGrid.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

template <class MeshT>
class ModEmbeddingGuardT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModEmbeddingGuardT, MeshT, EmbeddingGuard);
  using VertexHandle = typename MeshT::VertexHandle;
  using FaceHandle = typename MeshT::FaceHandle;

  explicit ModEmbeddingGuardT(MeshT& mesh) : Base(mesh, true) {}

  void initialize() override {
    MeshT& m = Base::mesh();
    double total = 0;
    std::size_t count = 0;
    for (auto e : m.edges()) {
      total += m.calc_edge_length(e);
      ++count;
    }
    cell_ = count ? 2 * total / double(count) : 1.0;
    tolerance_ = 1e-9 * cell_;
    grid_.clear(cell_);
    for (auto f : m.faces()) enter(f);
  }

  float collapse_priority(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    // The triangles the collapse creates: v0's faces but the two on the collapsing edge.
    created_.clear();
    for (auto f : m.vf_range(ci.v0)) {
      if (f == ci.fl || f == ci.fr) continue;
      Face t;
      int k = 0;
      for (auto v : m.fv_range(f)) {
        t.id[k] = v == ci.v0 ? ci.v1 : v;
        t.p[k] = pointOf(v == ci.v0 ? ci.p1 : m.point(v));
        ++k;
      }
      created_.push_back(t);
    }
    for (std::size_t i = 0; i < created_.size(); ++i) {
      for (std::size_t j = i + 1; j < created_.size(); ++j)
        if (meet(created_[i], created_[j])) return float(Base::ILLEGAL_COLLAPSE);
      // Old triangles near it, but those of v0 (removed or replaced).
      ++stamp_;
      bool illegal = false;
      grid_.near(created_[i].p, tolerance_, [&](std::uint32_t id) {
        const FaceHandle f{int(id)};
        if (illegal || m.status(f).deleted() || seen(f)) return;
        Face u;
        int k = 0;
        bool ofV0 = false;
        for (auto v : m.fv_range(f)) {
          ofV0 = ofV0 || v == ci.v0;
          u.id[k] = v;
          u.p[k] = pointOf(m.point(v));
          ++k;
        }
        illegal = !ofV0 && meet(created_[i], u);
      });
      if (illegal) return float(Base::ILLEGAL_COLLAPSE);
    }
    return float(Base::LEGAL_COLLAPSE);
  }

  void postprocess_collapse(const CollapseInfo& ci) override {
    for (auto f : Base::mesh().vf_range(ci.v1)) enter(f);
  }

 private:
  struct Face {
    std::array<VertexHandle, 3> id;
    Triangle3 p;
  };

  template <class P>
  static Point3 pointOf(const P& p) { return {double(p[0]), double(p[1]), double(p[2])}; }

  /// t and u meet other than in what they share (their common vertex handles).
  bool meet(const Face& t, const Face& u) const {
    int shared[3], count = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (t.id[a] == u.id[b]) shared[count++] = a * 3 + b;
    if (count == 3) return true;
    if (count == 0) return trianglesMeetImproperly(t.p, u.p, 0, tolerance_);
    if (count == 1) {
      const int a = shared[0] / 3, b = shared[0] % 3;
      return trianglesMeetImproperly({t.p[a], t.p[(a + 1) % 3], t.p[(a + 2) % 3]},
                                     {u.p[b], u.p[(b + 1) % 3], u.p[(b + 2) % 3]}, 1, tolerance_);
    }
    // Two shared: rotate t so that its unshared vertex is last, give u the same first two.
    const int ta = shared[0] / 3, tb = shared[1] / 3, ua = shared[0] % 3, ub = shared[1] % 3;
    const int tc = 3 - ta - tb, uc = 3 - ua - ub;
    const Triangle3 a{t.p[(tc + 1) % 3], t.p[(tc + 2) % 3], t.p[tc]};
    return trianglesMeetImproperly(a, {a[0], a[1], u.p[uc]}, 2, tolerance_);
  }

  void enter(FaceHandle f) {
    MeshT& m = Base::mesh();
    Triangle3 p;
    int k = 0;
    for (auto v : m.fv_range(f)) p[k++] = pointOf(m.point(v));
    grid_.insert(std::uint32_t(f.idx()), p);
  }
  /// Marks f as tested for the current created triangle; true if it already was.
  bool seen(FaceHandle f) {
    if (std::size_t(f.idx()) >= mark_.size()) mark_.resize(Base::mesh().n_faces(), 0);
    if (mark_[f.idx()] == stamp_) return true;
    mark_[f.idx()] = stamp_;
    return false;
  }

  double cell_ = 1, tolerance_ = 1e-9;
  TriangleGrid grid_;
  std::vector<Face> created_;
  std::vector<std::uint64_t> mark_;
  std::uint64_t stamp_ = 0;
};

}  // namespace surftrack::refine
