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
#include <span>
#include <vector>

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

#include "MeshTriangles.h"
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
    const MeshT& m = Base::mesh();
    tolerance_ = 1e-9 * 2 * meanEdgeLength(m);
    grid_.build(m, 0);
  }

  float collapse_priority(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    // The triangles the collapse creates: v0's faces but the two on the collapsing edge.
    created_.clear();
    forEachCreatedTriangle(m, ci, [&](FaceHandle, const std::array<VertexHandle, 3>& ids, const Triangle3& p) {
      created_.push_back({ids, p, boxOf(p, tolerance_)});
    });
    for (std::size_t i = 0; i < created_.size(); ++i) {
      for (std::size_t j = i + 1; j < created_.size(); ++j)
        if (created_[i].box.meets(created_[j].box) && meet(created_[i], created_[j])) return float(Base::ILLEGAL_COLLAPSE);
      // Old triangles near it, but those of v0 (removed or replaced): only one whose box meets
      // the created one's (enlarged by the tolerance) can meet it.
      ++stamp_;
      bool illegal = false;
      grid_.near(created_[i].box, [&](FaceHandle f) {
        if (illegal || seen(f)) return;
        Face u;
        auto h = m.halfedge_handle(f);
        for (int k = 0; k < 3; ++k, h = m.next_halfedge_handle(h)) {
          u.id[k] = m.to_vertex_handle(h);
          if (u.id[k] == ci.v0) return;
          u.p[k] = pointOf(m.point(u.id[k]));
        }
        illegal = meet(created_[i], u);
      });
      if (illegal) return float(Base::ILLEGAL_COLLAPSE);
    }
    return float(Base::LEGAL_COLLAPSE);
  }

  void postprocess_collapse(const CollapseInfo& ci) override {
    grid_.collapsed(Base::mesh(), ci.v1, ci.fl, ci.fr);
  }

 private:
  struct Face {
    std::array<VertexHandle, 3> id;
    Triangle3 p;
    Box3 box;
  };

  /// t and u meet other than in what they share (their common vertex handles).
  bool meet(const Face& t, const Face& u) const {
    int shared[3], count = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (t.id[a] == u.id[b]) shared[count++] = a * 3 + b;
    if (count == 3) return true;
    return trianglesMeetOutsideShared(t.p, u.p, std::span<const int>(shared, std::size_t(count)), tolerance_);
  }

  /// Marks f as tested for the current created triangle; true if it already was.
  bool seen(FaceHandle f) {
    if (std::size_t(f.idx()) >= mark_.size()) mark_.resize(Base::mesh().n_faces(), 0);
    if (mark_[f.idx()] == stamp_) return true;
    mark_[f.idx()] = stamp_;
    return false;
  }

  double tolerance_ = 1e-9;
  LiveTriangleGrid<MeshT> grid_;
  std::vector<Face> created_;
  std::vector<std::uint64_t> mark_;
  std::uint64_t stamp_ = 0;
};

}  // namespace surftrack::refine
