// A greedy decimater over OpenMesh's Decimater modules that checks every collapse at the moment
// it is performed (docs/theory.md, section 10). OpenMesh's own DecimaterT evaluates a candidate
// when it enters the heap and collapses it later without asking the modules again, so a
// constraint that depends on more than the candidate's one-ring (the embedding guard, the
// Hausdorff bound after nearby collapses) may no longer hold. Here a candidate enters the heap
// with its priority alone, again whenever that changes (a collapse into one of its vertices);
// the latest entry of a candidate, when it comes out, is asked of OpenMesh's is_collapse_ok and
// of every module, and collapsed only if all allow it. One that is refused waits until a
// collapse changes the faces around its from-vertex, and then goes in again.
#pragma once

#include <atomic>
#include <cstddef>

#include <OpenMesh/Tools/Decimater/BaseDecimaterT.hh>

namespace surftrack::refine {

/// The status flags OpenMesh's collapses need and the face normals the modules read, requested
/// and filled before a CheckedDecimaterT is built on `mesh`.
template <class MeshT>
void prepareForDecimation(MeshT& mesh) {
  mesh.request_vertex_status();
  mesh.request_edge_status();
  mesh.request_halfedge_status();
  mesh.request_face_status();
  mesh.request_face_normals();
  mesh.update_face_normals();
}

template <class MeshT>
class CheckedDecimaterT : public OpenMesh::Decimater::BaseDecimaterT<MeshT> {
 public:
  using Base = OpenMesh::Decimater::BaseDecimaterT<MeshT>;
  using CollapseInfo = typename Base::CollapseInfo;
  explicit CheckedDecimaterT(MeshT& mesh) : Base(mesh), mesh_(mesh) {}

  /// Collapses the best legal halfedges (lowest priority first) until at most `faces`
  /// triangles remain or no collapse is legal. A candidate enters the heap with
  /// `priority(ci)` (the priority module alone, cheap; ILLEGAL_COLLAPSE keeps it out) and is
  /// asked of OpenMesh's is_collapse_ok and every module when it comes out. Returns the number of collapses.
  /// `cancel`, if set, is checked every kCancelCheck candidates: raised, Cancelled
  /// (lib/Cancellation.h) is thrown, the mesh left partly decimated.
  /// \pre initialize() succeeded; the mesh has vertex, halfedge, edge and face status.
  template <class Priority>
  std::size_t decimateToFaces(std::size_t faces, Priority&& priority, const std::atomic<bool>* cancel = nullptr);

  /// Candidates evaluated or taken out of the heap between two checks of the cancel flag: a
  /// few milliseconds of work.
  static constexpr std::size_t kCancelCheck = 4096;

 private:
  MeshT& mesh_;
};

}  // namespace surftrack::refine

#include "CheckedDecimater_impl.h"
