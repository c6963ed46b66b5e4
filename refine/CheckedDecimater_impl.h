// CheckedDecimaterT::decimateToFaces (CheckedDecimater.h).
#pragma once

#include <cstdint>
#include <algorithm>
#include <functional>
#include <vector>

#include "Cancellation.h"

namespace surftrack::refine {

template <class MeshT>
template <class Priority>
std::size_t CheckedDecimaterT<MeshT>::decimateToFaces(std::size_t faces, Priority&& priority,
                                                      const std::atomic<bool>* cancel) {
  struct Candidate {
    float priority;
    int halfedge;
    std::uint32_t version;  // of the halfedge when it was evaluated
    bool operator>(const Candidate& o) const {
      return priority != o.priority ? priority > o.priority : halfedge > o.halfedge;
    }
  };
  // A min-heap (std::push_heap and std::pop_heap with std::greater) over a vector, so that the
  // first candidates of all halfedges are heaped at once.
  std::vector<Candidate> heap;
  auto push = [&](const Candidate& c) {
    heap.push_back(c);
    std::push_heap(heap.begin(), heap.end(), std::greater<Candidate>());
  };
  // A halfedge's entry is current while its version is; a halfedge found illegal when it came
  // out is `dropped` until a collapse changes the faces around its from-vertex.
  std::vector<std::uint32_t> version(mesh_.n_halfedges(), 0);
  std::vector<char> dropped(mesh_.n_halfedges(), 0);
  bool initial = true;  // the first evaluations go in unheaped
  auto evaluate = [&](typename MeshT::HalfedgeHandle h) {
    if (mesh_.status(h).deleted()) return;
    // Legality (OpenMesh's is_collapse_ok and the modules) is asked when the candidate comes
    // out: asking it of every candidate that goes in would be wasted on most of them.
    const std::uint32_t v = ++version[h.idx()];
    dropped[h.idx()] = 0;
    CollapseInfo ci(mesh_, h);
    const float p = priority(ci);
    if (p == float(OpenMesh::Decimater::ModBaseT<MeshT>::ILLEGAL_COLLAPSE)) return;
    if (initial) heap.push_back({p, h.idx(), v});
    else push({p, h.idx(), v});
  };
  heap.reserve(mesh_.n_halfedges());
  std::size_t steps = 0;  // candidates evaluated or taken out, for the cancel checks
  auto checkCancel = [&] {
    if (++steps % kCancelCheck == 0) throwIfCancelled(cancel, "decimation");
  };
  throwIfCancelled(cancel, "decimation");
  for (auto h : mesh_.halfedges()) {
    evaluate(h);
    checkCancel();
  }
  std::make_heap(heap.begin(), heap.end(), std::greater<Candidate>());
  initial = false;

  std::size_t collapses = 0, nf = mesh_.n_faces();
  // Entries of deleted halfedges and superseded ones stay in the heap until they come out;
  // when they outnumber the live halfedges (which have one current entry at most), they are
  // swept out at once.
  std::size_t liveHalfedges = mesh_.n_halfedges();
  while (nf > faces && !heap.empty()) {
    checkCancel();
    if (heap.size() > 2 * liveHalfedges + 1024) {
      heap.erase(std::remove_if(heap.begin(), heap.end(),
                                [&](const Candidate& c) {
                                  return mesh_.status(typename MeshT::HalfedgeHandle(c.halfedge)).deleted() ||
                                         version[c.halfedge] != c.version;
                                }),
                 heap.end());
      std::make_heap(heap.begin(), heap.end(), std::greater<Candidate>());
    }
    std::pop_heap(heap.begin(), heap.end(), std::greater<Candidate>());
    const Candidate c = heap.back();
    heap.pop_back();
    const typename MeshT::HalfedgeHandle h(c.halfedge);
    if (mesh_.status(h).deleted() || version[c.halfedge] != c.version) continue;
    CollapseInfo ci(mesh_, h);
    if (!this->is_collapse_legal(ci)) {
      dropped[c.halfedge] = 1;
      continue;
    }
    const float p = this->collapse_priority(ci);  // every module, now
    if (p == float(OpenMesh::Decimater::ModBaseT<MeshT>::ILLEGAL_COLLAPSE)) {
      dropped[c.halfedge] = 1;
      continue;
    }
    if (p > c.priority) {  // grown since (a module's state changed): back in its place
      push({p, c.halfedge, c.version});
      continue;
    }
    this->preprocess_collapse(ci);
    mesh_.collapse(h);
    ++collapses;
    liveHalfedges -= 6;  // the collapsing edge and one of each pair of edges it merges
    nf -= (mesh_.is_boundary(ci.v0v1) || mesh_.is_boundary(ci.v1v0)) ? 1 : 2;
    if (mesh_.has_face_normals())
      for (auto f : mesh_.vf_range(ci.v1)) mesh_.set_normal(f, mesh_.calc_face_normal(f));
    this->postprocess_collapse(ci);
    // The priority of a halfedge reads its two vertices (the quadric of v1 has changed): the
    // halfedges into and out of v1 go in again. The checks of a halfedge read the faces around
    // its from-vertex, which changed for v1 and its ring: their dropped halfedges go in again.
    for (auto h2 : mesh_.voh_range(ci.v1)) {
      evaluate(h2);
      evaluate(mesh_.opposite_halfedge_handle(h2));
    }
    for (auto w : mesh_.vv_range(ci.v1))
      for (auto h2 : mesh_.voh_range(w))
        if (dropped[h2.idx()]) evaluate(h2);
  }
  return collapses;
}

}  // namespace surftrack::refine
