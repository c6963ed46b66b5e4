// Fold certificates (docs/theory.md, section 8, "Certificates"): conditions of the fold check
// of a digital 3-cube that hold for *every* position of the vertices inside their segments,
// so that constrained smoothing need not test them in any pass.
//
// A triangle of a cube is given by the cube edges (0..11, lib/DigitalCube.h) its vertices lie on,
// in orientation order; in the cube's own coordinates the vertex on edge k is
// low(k) + tau * axis(k) with tau in [epsilon, 1 - epsilon]. Every quantity below is a
// determinant in points on distinct edges, hence multi-affine in their taus, so it keeps a
// strict sign over the whole box of taus exactly when it has that sign at the box's corners.
// A certificate is a strict sign, at every corner, of
//  - for one triangle: n . r, its normal against its reference normal (the normal at tau = 1/2):
//    never degenerate, never turned over;
//  - for two triangles: a plane that separates them but for what they share, among a fixed
//    family: the plane of either triangle, a coordinate plane, or a plane through an edge or a
//    shared vertex of one containing a coordinate axis direction; for two triangles sharing an
//    edge, a non-zero volume (never coplanar) or a plane through the shared edge that holds the
//    two opposite vertices on opposite sides.
// What has no certificate is tested in every pass (CubeFoldCheck.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace surftrack::refine {

/// The cube edges of a triangle's vertices, in orientation order.
using CubeEdges = std::array<std::uint8_t, 3>;

class FoldCertificates {
 public:
  /// \pre 0 < epsilon < 1/2.
  explicit FoldCertificates(double epsilon);

  /// True when triangle t is non-degenerate and keeps the side of its reference normal for
  /// every position of its vertices (taus in [epsilon, 1 - epsilon]).
  bool triangleIsCertain(const CubeEdges& t);

  /// True when triangles t and u of one cube meet only in what they share (the vertices on
  /// their common edges, and the edge those span) for every position of their vertices.
  bool pairIsCertain(const CubeEdges& t, const CubeEdges& u);

 private:
  bool computeTriangle(const CubeEdges& t) const;
  bool computePair(const CubeEdges& t, const CubeEdges& u) const;

  double epsilon_;
  std::vector<std::int8_t> triangles_, pairs_;  // memo: -1 unknown, 0 no, 1 certain
};

}  // namespace surftrack::refine
