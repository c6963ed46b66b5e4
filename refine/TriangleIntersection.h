// Conservative intersection tests between the triangles of a mesh (docs/theory.md, section 8,
// "The fold check"): two triangles of one mesh may share nothing, one vertex or one edge, and
// they are *embedded* when they meet in exactly what they share. The tests are in floating
// point with an absolute tolerance: a pair closer than about `tolerance` to meeting improperly
// counts as meeting, so a "no" is reliable up to rounding while a "yes" may be a near miss.
#pragma once

#include <array>
#include <cmath>
#include <span>

namespace surftrack::refine {

using Point3 = std::array<double, 3>;
using Triangle3 = std::array<Point3, 3>;

/// True when the closed segment [a, b] meets the closed triangle t, or comes within about
/// `tolerance` of it (coplanar segments are tested in the triangle's plane).
/// \pre t is not degenerate (callers reject degenerate triangles first).
bool segmentMeetsTriangle(const Point3& a, const Point3& b, const Triangle3& t, double tolerance);

/// True when triangles t and u, whose shared vertices are given by their indices, meet
/// anywhere other than in their shared vertices and the edge they span (or come within about
/// `tolerance` of doing so).
/// \param shared the number of shared vertices (0, 1 or 2); they are t[0] = u[0] for 1, and
///        t[0] = u[0], t[1] = u[1] (as points; orientation aside) for 2.
/// \pre neither triangle is degenerate.
bool trianglesMeetImproperly(const Triangle3& t, const Triangle3& u, int shared, double tolerance);

/// True when triangles t and u meet anywhere other than in the vertices they share and the
/// edge those span (or come within about `tolerance` of doing so). `shared` lists the shared
/// vertices, 0 to 2 of them, as a * 3 + b for t[a] = u[b]; three shared vertices are the same
/// triangle twice, which counts as meeting.
bool trianglesMeetOutsideShared(const Triangle3& t, const Triangle3& u, std::span<const int> shared,
                                double tolerance);

/// The squared distance from p to the closed triangle t (the closest point by Voronoi regions,
/// after Ericson, "Real-Time Collision Detection", 5.1.5).
double squaredDistanceToTriangle(const Point3& p, const Triangle3& t);

inline Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Point3& a) { return std::sqrt(dot(a, a)); }

/// (b - a) x (c - a): twice the area, along the right-hand-rule normal.
inline Point3 triangleNormal(const Triangle3& t) { return cross(sub(t[1], t[0]), sub(t[2], t[0])); }

}  // namespace surftrack::refine
