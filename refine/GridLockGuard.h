// A Decimater module (OpenMesh) that keeps a mesh cut on the planes of one level of an octree
// grid (docs/theory.md, section 10, "Levels of detail on a grid"), so that a decimated level of
// detail meets its finer levels on exactly the same curves there:
//  - a vertex on such a plane is never the removed vertex v0 of a collapse (its point, and so
//    the curve the surface cuts on the plane, stays), and
//  - no collapse creates a triangle lying in such a plane (Neuroglancer could not tell on which
//    side of the plane it is drawn).
// A vertex off the planes lies inside one cell, and so do all its triangles and its neighbour
// v1: the triangles the collapse creates stay in that cell, and no triangle ever crosses a plane.
#pragma once

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

#include "MeshTriangles.h"
#include "OctreeGrid.h"

namespace surftrack::refine {

template <class MeshT>
class ModGridLockT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModGridLockT, MeshT, GridLock);
  using VertexHandle = typename MeshT::VertexHandle;

  explicit ModGridLockT(MeshT& mesh) : Base(mesh, true) {}

  /// The grid and the level whose planes stay.
  void set_grid(const OctreeGrid& grid, int level) {
    grid_ = grid;
    level_ = level;
  }

  float collapse_priority(const CollapseInfo& ci) override {
    const MeshT& m = Base::mesh();
    for (int axis = 0; axis < 3; ++axis)
      if (grid_.onPlane(axis, ci.p0[axis], level_)) return float(Base::ILLEGAL_COLLAPSE);
    bool flat = false;
    forEachCreatedTriangle(m, ci, [&](auto, const std::array<VertexHandle, 3>& ids, const auto&) {
      for (int axis = 0; axis < 3 && !flat; ++axis) {
        const double t = m.point(ids[0])[axis];
        bool all = grid_.onPlane(axis, t, level_);
        for (int k = 1; k < 3 && all; ++k) all = m.point(ids[k])[axis] == t;
        flat = all;
      }
    });
    return flat ? float(Base::ILLEGAL_COLLAPSE) : float(Base::LEGAL_COLLAPSE);
  }

 private:
  OctreeGrid grid_;
  int level_ = 0;
};

}  // namespace surftrack::refine
