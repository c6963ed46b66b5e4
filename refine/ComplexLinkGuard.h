// A Decimater module (OpenMesh) for a mesh that is one wall of a conforming complex
// (ComplexDecimation.h, docs/theory.md §12, "Decimating the complex"): a halfedge collapse
// v0 -> v1 of the wall is allowed only if
//  - v0 is free: all its triangles are of this wall and form one closed disc around it, for both
//    regions the wall separates (not a junction vertex, not a pinch, not on the wall's border),
//  - v1 is not singular: no region's triangles at v1 are other than one closed disc (a pinch),
//    so that v1 has one vertex in every label that has it, and
//  - the link condition holds in the whole complex, not only in the wall (TopologyGuard.h reads
//    the wall alone): no vertex but vl and vr is a neighbour of both v0 and v1 in the complex,
//    and the triangles (v0, vl, vr) and (v1, vl, vr) do not both exist.
// The complex's edges and triangles are named by the vertices of the complex (a vertex of the
// wall may be a copy of one, one per fan of the wall around it) and follow every collapse.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <OpenMesh/Tools/Decimater/ModBaseT.hh>

namespace surftrack::refine {

/// The edges and triangles of a complex, by the names of their vertices, as collapses change
/// them.
struct ComplexIncidence {
  struct TriangleHash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& t) const {
      return std::size_t(t[0]) * 0x9E3779B97F4A7C15ull ^ std::size_t(t[1]) * 0xC2B2AE3D27D4EB4Full ^
             std::size_t(t[2]) * 0x165667B19E3779F9ull;
    }
  };
  std::unordered_map<std::uint64_t, std::uint32_t> edges;  // edge -> its triangles
  std::unordered_set<std::array<std::uint32_t, 3>, TriangleHash> triangles;  // sorted names

  static std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    return a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
  }
  static std::array<std::uint32_t, 3> triangleKey(std::array<std::uint32_t, 3> t) {
    std::sort(t.begin(), t.end());
    return t;
  }
  bool hasEdge(std::uint32_t a, std::uint32_t b) const { return edges.count(edgeKey(a, b)) != 0; }
  bool hasTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    return triangles.count(triangleKey({a, b, c})) != 0;
  }
  void add(const std::array<std::uint32_t, 3>& t) {
    for (int k = 0; k < 3; ++k) ++edges[edgeKey(t[k], t[(k + 1) % 3])];
    triangles.insert(triangleKey(t));
  }
  void remove(const std::array<std::uint32_t, 3>& t) {
    for (int k = 0; k < 3; ++k) {
      const auto at = edges.find(edgeKey(t[k], t[(k + 1) % 3]));
      if (at != edges.end() && --at->second == 0) edges.erase(at);
    }
    triangles.erase(triangleKey(t));
  }
};

template <class MeshT>
class ModComplexLinkT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModComplexLinkT, MeshT, ComplexLink);
  using VertexHandle = typename MeshT::VertexHandle;
  using FaceHandle = typename MeshT::FaceHandle;

  explicit ModComplexLinkT(MeshT& mesh) : Base(mesh, true) {}

  /// `identity`: each vertex's name in the complex; `free` and `singular`: by vertex of the
  /// wall mesh (free: may be removed; singular: may not be kept for a removed one); `complex`:
  /// the whole complex, this wall included, kept up to date by the collapses.
  void set_complex(OpenMesh::VPropHandleT<std::uint32_t> identity, std::vector<char> free,
                   std::vector<char> singular, ComplexIncidence* complex) {
    identity_ = identity;
    free_ = std::move(free);
    singular_ = std::move(singular);
    complex_ = complex;
  }

  float collapse_priority(const CollapseInfo& ci) override {
    if (!free_[std::size_t(ci.v0.idx())] || singular_[std::size_t(ci.v1.idx())]) return float(Base::ILLEGAL_COLLAPSE);
    if (!ci.vl.is_valid() || !ci.vr.is_valid()) return float(Base::ILLEGAL_COLLAPSE);
    const std::uint32_t n0 = nameOf(ci.v0), n1 = nameOf(ci.v1), nl = nameOf(ci.vl), nr = nameOf(ci.vr);
    for (auto w : Base::mesh().vv_range(ci.v0)) {
      const std::uint32_t n = nameOf(w);
      if (n == n1 || n == nl || n == nr) continue;
      if (complex_->hasEdge(n1, n)) return float(Base::ILLEGAL_COLLAPSE);
    }
    if (complex_->hasTriangle(n0, nl, nr) && complex_->hasTriangle(n1, nl, nr)) return float(Base::ILLEGAL_COLLAPSE);
    return float(Base::LEGAL_COLLAPSE);
  }

  void preprocess_collapse(const CollapseInfo& ci) override {
    changed_.clear();
    for (auto f : Base::mesh().vf_range(ci.v0)) {
      complex_->remove(namesOf(f));
      if (f != ci.fl && f != ci.fr) changed_.push_back(f);
    }
  }

  void postprocess_collapse(const CollapseInfo&) override {
    for (FaceHandle f : changed_) complex_->add(namesOf(f));
  }

 private:
  std::uint32_t nameOf(VertexHandle v) { return Base::mesh().property(identity_, v); }
  std::array<std::uint32_t, 3> namesOf(FaceHandle f) {
    std::array<std::uint32_t, 3> t;
    int k = 0;
    for (auto v : Base::mesh().fv_range(f)) t[std::size_t(k++)] = nameOf(v);
    return t;
  }

  OpenMesh::VPropHandleT<std::uint32_t> identity_;
  std::vector<char> free_, singular_;
  ComplexIncidence* complex_ = nullptr;
  std::vector<FaceHandle> changed_;
};

}  // namespace surftrack::refine
