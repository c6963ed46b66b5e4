// CheckedDecimaterT::decimateToFaces (CheckedDecimater.h).
#pragma once

#include <cstdint>
#include <queue>
#include <vector>

namespace surftrack::refine {

template <class MeshT>
template <class Priority>
std::size_t CheckedDecimaterT<MeshT>::decimateToFaces(std::size_t faces, Priority&& priority) {
  struct Candidate {
    float priority;
    int halfedge;
    std::uint32_t stamp;  // of the halfedge's from-vertex when it was evaluated
    bool operator>(const Candidate& o) const {
      return priority != o.priority ? priority > o.priority : halfedge > o.halfedge;
    }
  };
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap;
  std::vector<std::uint32_t> stamp(mesh_.n_vertices(), 0);
  auto evaluate = [&](typename MeshT::HalfedgeHandle h) {
    if (mesh_.status(h).deleted()) return;
    CollapseInfo ci(mesh_, h);
    if (!this->is_collapse_legal(ci)) return;
    const float p = priority(ci);
    if (p == float(OpenMesh::Decimater::ModBaseT<MeshT>::ILLEGAL_COLLAPSE)) return;
    heap.push({p, h.idx(), stamp[ci.v0.idx()]});
  };
  for (auto h : mesh_.halfedges()) evaluate(h);

  std::size_t collapses = 0, nf = mesh_.n_faces();
  while (nf > faces && !heap.empty()) {
    const Candidate c = heap.top();
    heap.pop();
    const typename MeshT::HalfedgeHandle h(c.halfedge);
    if (mesh_.status(h).deleted()) continue;
    CollapseInfo ci(mesh_, h);
    if (stamp[ci.v0.idx()] != c.stamp) continue;  // re-evaluated when its vertex changed
    if (!this->is_collapse_legal(ci)) continue;
    const float p = this->collapse_priority(ci);  // every module, now
    if (p == float(OpenMesh::Decimater::ModBaseT<MeshT>::ILLEGAL_COLLAPSE)) continue;
    if (p > c.priority) {  // grown since (a module's state changed): back in its place
      heap.push({p, c.halfedge, c.stamp});
      continue;
    }
    this->preprocess_collapse(ci);
    mesh_.collapse(h);
    ++collapses;
    nf -= (mesh_.is_boundary(ci.v0v1) || mesh_.is_boundary(ci.v1v0)) ? 1 : 2;
    if (mesh_.has_face_normals())
      for (auto f : mesh_.vf_range(ci.v1)) mesh_.set_normal(f, mesh_.calc_face_normal(f));
    this->postprocess_collapse(ci);
    // The checks of a halfedge read the faces around its from-vertex: those of v1 and its
    // ring changed.
    ++stamp[ci.v1.idx()];
    for (auto w : mesh_.vv_range(ci.v1)) ++stamp[w.idx()];
    for (auto h2 : mesh_.voh_range(ci.v1)) evaluate(h2);
    for (auto w : mesh_.vv_range(ci.v1))
      for (auto h2 : mesh_.voh_range(w)) evaluate(h2);
  }
  return collapses;
}

}  // namespace surftrack::refine
