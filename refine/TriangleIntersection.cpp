#include "TriangleIntersection.h"

#include <cmath>

namespace surftrack::refine {

namespace {

Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Point3& a) { return std::sqrt(dot(a, a)); }

using Point2 = std::array<double, 2>;

/// Twice the signed area of (a, b, c), divided by |b - a|: the signed distance of c to line ab.
double sideOf(const Point2& a, const Point2& b, const Point2& c) {
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double len = std::hypot(ux, uy);
  const double area = ux * (c[1] - a[1]) - uy * (c[0] - a[0]);
  return len > 0 ? area / len : std::hypot(c[0] - a[0], c[1] - a[1]);
}

/// Segments [a, b] and [c, d] of a plane meet or come within about `tol`.
bool segmentsMeet2(const Point2& a, const Point2& b, const Point2& c, const Point2& d, double tol) {
  const double o1 = sideOf(a, b, c), o2 = sideOf(a, b, d);
  if ((o1 > tol && o2 > tol) || (o1 < -tol && o2 < -tol)) return false;
  const double o3 = sideOf(c, d, a), o4 = sideOf(c, d, b);
  if ((o3 > tol && o4 > tol) || (o3 < -tol && o4 < -tol)) return false;
  return true;  // crossing, touching, or collinear (conservatively)
}

/// Point p lies in the counter-clockwise or clockwise triangle t of a plane, up to `tol`.
bool pointInTriangle2(const Point2& p, const std::array<Point2, 3>& t, double tol) {
  const double s = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
  const double sign = s >= 0 ? 1.0 : -1.0;
  for (int i = 0; i < 3; ++i)
    if (sign * sideOf(t[i], t[(i + 1) % 3], p) < -tol) return false;
  return true;
}

}  // namespace

double squaredDistanceToTriangle(const Point3& p, const Triangle3& t) {
  const Point3 &a = t[0], &b = t[1], &c = t[2];
  const Point3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  auto at = [&](double v, double w) {  // a + v ab + w ac
    const Point3 q{a[0] + v * ab[0] + w * ac[0], a[1] + v * ab[1] + w * ac[1], a[2] + v * ab[2] + w * ac[2]};
    const Point3 d = sub(p, q);
    return dot(d, d);
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return at(0, 0);
  const Point3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(d1 / (d1 - d3), 0);
  const Point3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(0, d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return at(1 - w, w);
  }
  const double denom = 1 / (va + vb + vc);
  return at(vb * denom, vc * denom);
}

Point3 triangleNormal(const Triangle3& t) { return cross(sub(t[1], t[0]), sub(t[2], t[0])); }

bool segmentMeetsTriangle(const Point3& a, const Point3& b, const Triangle3& t, double tol) {
  const Point3 n = triangleNormal(t);
  const double len = norm(n);
  if (!(len > 0)) return true;
  const Point3 u{n[0] / len, n[1] / len, n[2] / len};
  const double da = dot(u, sub(a, t[0])), db = dot(u, sub(b, t[0]));
  if ((da > tol && db > tol) || (da < -tol && db < -tol)) return false;
  if (std::abs(da) <= tol && std::abs(db) <= tol) {
    // Coplanar: drop the dominant axis of the normal and test in that plane.
    int drop = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(u[k]) > std::abs(u[drop])) drop = k;
    const int i = (drop + 1) % 3, j = (drop + 2) % 3;
    auto flat = [&](const Point3& p) { return Point2{p[i], p[j]}; };
    const std::array<Point2, 3> tt{flat(t[0]), flat(t[1]), flat(t[2])};
    const Point2 a2 = flat(a), b2 = flat(b);
    if (pointInTriangle2(a2, tt, tol) || pointInTriangle2(b2, tt, tol)) return true;
    for (int k = 0; k < 3; ++k)
      if (segmentsMeet2(a2, b2, tt[k], tt[(k + 1) % 3], tol)) return true;
    return false;
  }
  // The point where the segment crosses the plane (or the endpoint nearest it).
  const double s = std::abs(da - db) > 0 ? da / (da - db) : 0.0;
  const double sc = s < 0 ? 0.0 : s > 1 ? 1.0 : s;
  const Point3 x{a[0] + sc * (b[0] - a[0]), a[1] + sc * (b[1] - a[1]), a[2] + sc * (b[2] - a[2])};
  for (int k = 0; k < 3; ++k) {
    const Point3 e = sub(t[(k + 1) % 3], t[k]);
    // Signed distance of x to the edge's line, within the plane, positive inside.
    const double side = dot(cross(e, sub(x, t[k])), u) / norm(e);
    if (side < -tol) return false;
  }
  return true;
}

bool trianglesMeetImproperly(const Triangle3& t, const Triangle3& u, int shared, double tol) {
  if (shared == 2) {
    // Sharing the edge t0 t1: if u's third vertex is off t's plane, the planes meet along the
    // edge's line only, and so do the triangles. If it is in the plane, they overlap exactly
    // when it lies on the side of t2 (a fold onto each other).
    const Point3 nt = triangleNormal(t);
    const double lt = norm(nt);
    const Point3 ut{nt[0] / lt, nt[1] / lt, nt[2] / lt};
    if (std::abs(dot(ut, sub(u[2], t[0]))) > tol) return false;
    const Point3 e = sub(t[1], t[0]);
    // (e x (t2 - t0)) . ut = |nt| > 0: t2 is on the positive side.
    return dot(cross(e, sub(u[2], t[0])), ut) / norm(e) > -tol;
  }
  if (shared == 1) {
    // Sharing vertex p = t0 = u0: they meet elsewhere iff an opposite edge meets the other
    // triangle (docs/theory.md, section 8).
    return segmentMeetsTriangle(t[1], t[2], u, tol) || segmentMeetsTriangle(u[1], u[2], t, tol);
  }
  for (int k = 0; k < 3; ++k)
    if (segmentMeetsTriangle(t[k], t[(k + 1) % 3], u, tol) || segmentMeetsTriangle(u[k], u[(k + 1) % 3], t, tol))
      return true;
  return false;
}

}  // namespace surftrack::refine
