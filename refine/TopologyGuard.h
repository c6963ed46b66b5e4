// A Decimater module (OpenMesh) that allows a halfedge collapse v0 -> v1 only when it keeps the
// topology of a closed 2-manifold: the link condition Lk(v0) ∩ Lk(v1) = Lk(v0 v1) of Dey,
// Edelsbrunner, Guha and Nekhayev ("Topology preserving edge contraction", 1999), written for a
// closed triangle mesh (docs/theory.md, section 10):
//  - the common neighbours of v0 and v1 are exactly the two opposite vertices vl and vr, and
//  - the edge vl vr is not in both links, i.e. the triangles (v0, vl, vr) and (v1, vl, vr) do
//    not both exist (the boundary of a tetrahedron, which a collapse would flatten).
// Under it every collapse is a homeomorphism: genus and components never change, and the mesh
// stays a manifold.
#pragma once

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

namespace surftrack::refine {

template <class MeshT>
class ModTopologyGuardT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModTopologyGuardT, MeshT, TopologyGuard);

  explicit ModTopologyGuardT(MeshT& mesh) : Base(mesh, true) {}

  float collapse_priority(const CollapseInfo& ci) override {
    return linkConditionHolds(ci) ? float(Base::LEGAL_COLLAPSE) : float(Base::ILLEGAL_COLLAPSE);
  }

 private:
  bool linkConditionHolds(const CollapseInfo& ci) {
    MeshT& m = Base::mesh();
    if (!ci.vl.is_valid() || !ci.vr.is_valid() || ci.vl == ci.vr) return false;  // closed meshes only
    for (auto w : m.vv_range(ci.v0)) {
      if (w == ci.v1 || w == ci.vl || w == ci.vr) continue;
      for (auto z : m.vv_range(ci.v1))
        if (z == w) return false;
    }
    return !(hasTriangle(ci.v0, ci.vl, ci.vr) && hasTriangle(ci.v1, ci.vl, ci.vr));
  }
  bool hasTriangle(typename MeshT::VertexHandle a, typename MeshT::VertexHandle b,
                   typename MeshT::VertexHandle c) {
    MeshT& m = Base::mesh();
    for (auto f : m.vf_range(a)) {
      bool hb = false, hc = false;
      for (auto v : m.fv_range(f)) {
        hb = hb || v == b;
        hc = hc || v == c;
      }
      if (hb && hc) return true;
    }
    return false;
  }
};

}  // namespace surftrack::refine
