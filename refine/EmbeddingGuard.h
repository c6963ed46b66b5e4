// A Decimater module (OpenMesh) that allows a halfedge collapse v0 -> v1 only when the mesh
// stays embedded (docs/theory.md, section 10): none of the triangles the collapse creates (the
// triangles of v0 other than the two it removes, with v0 replaced by v1) may meet another
// triangle of the mesh, old or new, other than in the vertices and the edge they share. The
// other triangles are found through a uniform grid of their bounding boxes, updated after every
// collapse, so the check is not limited to a topological neighbourhood: two sheets of the surface
// that lie close together are caught as well. Tests in floating point, conservative
// (TriangleIntersection.h).
// A mesh that is one wall of a larger complex (ComplexDecimation.h) also names each vertex's
// vertex of the complex (copies of one vertex then count as shared) and lists the complex's
// triangles outside the mesh, which the created triangles must not meet either.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
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

  /// The mesh is one part of a complex: `identity` holds each vertex's name in the complex.
  /// Before initialize().
  void set_complex(OpenMesh::VPropHandleT<std::uint32_t> identity) { identity_ = identity; }

  void initialize() override {
    const MeshT& m = Base::mesh();
    cell_ = 2 * meanEdgeLength(m);
    tolerance_ = 1e-9 * cell_;
    grid_.build(m, 0);
  }

  /// The complex's other triangles (`obstacles`, fixed while this mesh is decimated) and their
  /// vertices' names. After initialize(), and again whenever they change.
  void set_obstacles(std::vector<Triangle3> obstacles, std::vector<std::array<std::uint32_t, 3>> obstacleNames) {
    obstacles_ = std::move(obstacles);
    obstacleNames_ = std::move(obstacleNames);
    if (obstacles_.empty()) return;
    Box3 bounds = LiveTriangleGrid<MeshT>::boundsOf(Base::mesh());
    for (const Triangle3& t : obstacles_) {
      const Box3 b = boxOf(t);
      for (int k = 0; k < 3; ++k) {
        bounds.lo[k] = std::min(bounds.lo[k], b.lo[k]);
        bounds.hi[k] = std::max(bounds.hi[k], b.hi[k]);
      }
    }
    obstacleGrid_.reset(bounds, cell_);
    for (std::size_t i = 0; i < obstacles_.size(); ++i)
      obstacleGrid_.insert(std::uint32_t(i), 0, boxOf(obstacles_[i], tolerance_));
    obstacleMark_.assign(obstacles_.size(), 0);
  }

  float collapse_priority(const CollapseInfo& ci) override {
    MeshT& m = Base::mesh();
    // The triangles the collapse creates: v0's faces but the two on the collapsing edge.
    created_.clear();
    forEachCreatedTriangle(m, ci, [&](FaceHandle, const std::array<VertexHandle, 3>& ids, const Triangle3& p) {
      created_.push_back({{nameOf(ids[0]), nameOf(ids[1]), nameOf(ids[2])}, p, boxOf(p, tolerance_)});
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
          const VertexHandle v = m.to_vertex_handle(h);
          if (v == ci.v0) return;
          u.id[k] = nameOf(v);
          u.p[k] = pointOf(m.point(v));
        }
        illegal = meet(created_[i], u);
      });
      if (illegal) return float(Base::ILLEGAL_COLLAPSE);
      // The complex's other triangles (none but for a wall of a complex).
      if (obstacles_.empty()) continue;
      ++obstacleStamp_;
      obstacleGrid_.near(created_[i].box, [&](std::uint32_t id, std::uint32_t) {
        if (illegal || obstacleMark_[id] == obstacleStamp_) return;
        obstacleMark_[id] = obstacleStamp_;
        illegal = meet(created_[i], Face{obstacleNames_[id], obstacles_[id], {}});
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
    std::array<std::uint32_t, 3> id;  // the vertices' names (nameOf)
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

  /// A vertex's name: its vertex of the complex, or its own index.
  std::uint32_t nameOf(VertexHandle v) {
    return identity_.is_valid() ? Base::mesh().property(identity_, v) : std::uint32_t(v.idx());
  }

  /// Marks f as tested for the current created triangle; true if it already was.
  bool seen(FaceHandle f) {
    if (std::size_t(f.idx()) >= mark_.size()) mark_.resize(Base::mesh().n_faces(), 0);
    if (mark_[f.idx()] == stamp_) return true;
    mark_[f.idx()] = stamp_;
    return false;
  }

  double tolerance_ = 1e-9, cell_ = 1;
  LiveTriangleGrid<MeshT> grid_;
  std::vector<Face> created_;
  std::vector<std::uint64_t> mark_;
  std::uint64_t stamp_ = 0;
  OpenMesh::VPropHandleT<std::uint32_t> identity_;
  std::vector<Triangle3> obstacles_;
  std::vector<std::array<std::uint32_t, 3>> obstacleNames_;
  TriangleGrid obstacleGrid_;
  std::vector<std::uint64_t> obstacleMark_;
  std::uint64_t obstacleStamp_ = 0;
};

}  // namespace surftrack::refine
