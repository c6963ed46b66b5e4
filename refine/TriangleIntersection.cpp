#include "TriangleIntersection.h"

#include <cmath>

namespace surftrack::refine {

namespace {

using Point2 = std::array<double, 2>;

/// Twice the signed area of (a, b, c), divided by |b - a|: the signed distance of c to line ab.
double sideOf(const Point2& a, const Point2& b, const Point2& c) {
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double len = std::sqrt(ux * ux + uy * uy);  // (no overflow here: std::hypot is slow)
  const double area = ux * (c[1] - a[1]) - uy * (c[0] - a[0]);
  if (len > 0) return area / len;
  const double vx = c[0] - a[0], vy = c[1] - a[1];
  return std::sqrt(vx * vx + vy * vy);
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

/// Every point of `points` lies farther than `tol` from t's plane, all on the same side: then
/// the convex hull of those points (and of any point of the plane) meets t's plane at most in
/// that point.
template <std::size_t N>
bool strictlyOnOneSide(const Triangle3& t, const std::array<Point3, N>& points, double tol) {
  const Point3 n = triangleNormal(t);
  const double len = norm(n);
  if (!(len > 0)) return false;
  int side = 0;
  for (const Point3& q : points) {
    const double d = dot(n, sub(q, t[0])) / len;
    const int s = d > tol ? 1 : d < -tol ? -1 : 0;
    if (s == 0 || (side != 0 && s != side)) return false;
    side = s;
  }
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
    // Sharing vertex p = t0 = u0: when t1 and t2 lie strictly on one side of u's plane (or u1,
    // u2 of t's), the triangles meet in p alone. Otherwise they meet elsewhere iff an opposite
    // edge meets the other triangle (docs/theory.md, section 8).
    if (strictlyOnOneSide(u, std::array<Point3, 2>{t[1], t[2]}, tol) ||
        strictlyOnOneSide(t, std::array<Point3, 2>{u[1], u[2]}, tol))
      return false;
    return segmentMeetsTriangle(t[1], t[2], u, tol) || segmentMeetsTriangle(u[1], u[2], t, tol);
  }
  // Sharing nothing: apart when one lies strictly on one side of the other's plane; otherwise
  // they meet iff an edge of one meets the other.
  if (strictlyOnOneSide(t, u, tol) || strictlyOnOneSide(u, t, tol)) return false;
  for (int k = 0; k < 3; ++k)
    if (segmentMeetsTriangle(t[k], t[(k + 1) % 3], u, tol) || segmentMeetsTriangle(u[k], u[(k + 1) % 3], t, tol))
      return true;
  return false;
}

bool trianglesMeetOutsideShared(const Triangle3& t, const Triangle3& u, std::span<const int> shared, double tol) {
  if (shared.size() >= 3) return true;
  if (shared.empty()) return trianglesMeetImproperly(t, u, 0, tol);
  if (shared.size() == 1) {
    const int a = shared[0] / 3, b = shared[0] % 3;
    return trianglesMeetImproperly({t[a], t[(a + 1) % 3], t[(a + 2) % 3]}, {u[b], u[(b + 1) % 3], u[(b + 2) % 3]}, 1,
                                   tol);
  }
  // Two shared: rotate t so that its unshared vertex comes last (the shared edge first), and
  // give u the same first two points and its own unshared vertex (u's orientation does not
  // matter).
  const int ta = shared[0] / 3, tb = shared[1] / 3, ua = shared[0] % 3, ub = shared[1] % 3;
  const int tc = 3 - ta - tb, uc = 3 - ua - ub;
  const Triangle3 a{t[(tc + 1) % 3], t[(tc + 2) % 3], t[tc]};
  return trianglesMeetImproperly(a, {a[0], a[1], u[uc]}, 2, tol);
}

}  // namespace surftrack::refine
