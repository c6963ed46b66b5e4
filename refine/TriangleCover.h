// Whether every point of a triangle lies within a distance E of a set of triangles — proven, not
// sampled (docs/theory.md, section 10, the distance bound). The distance to one triangle is a
// convex function, so a triangle whose three corners are within E of one triangle of the set
// lies within E of it whole. Otherwise the triangle is cut into its four midpoint triangles, down
// to `depth` cuts; a piece still unproven there is accepted only when its centroid's distance to
// one triangle of the set plus the piece's radius (the farthest corner from the centroid) is
// within E, the distance being 1-Lipschitz. A "no" may be a triangle within E that the cuts did
// not prove; a "yes" is a bound on every point, up to rounding.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "TriangleGrid.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

/// True when every point of `t` is within `e` of one of the triangles `near` offers. near(box,
/// visit) calls visit(id, triangle) for the set's triangles that may meet `box` (the most likely
/// first), until visit returns true. With `pieces`, each proven piece of t is appended with the
/// id of the triangle it was proven near (on a "no", what was appended is to be discarded).
template <class Id, class Near>
bool coverTriangle(const Triangle3& t, double e, int depth, Near&& near,
                   std::vector<std::pair<Triangle3, Id>>* pieces = nullptr) {
  const double e2 = e * e;
  bool done = false;
  Id found{};
  near(boxOf(t, e), [&](Id id, const Triangle3& o) {
    if (squaredDistanceToTriangle(t[0], o) <= e2 && squaredDistanceToTriangle(t[1], o) <= e2 &&
        squaredDistanceToTriangle(t[2], o) <= e2) {
      found = id;
      done = true;
    }
    return done;
  });
  if (!done && depth == 0) {
    const Point3 c{(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3,
                   (t[0][2] + t[1][2] + t[2][2]) / 3};
    double r = 0;
    for (const Point3& p : t) r = std::max(r, norm(sub(p, c)));
    if (r < e)
      near(boxOf({c, c, c}, e - r), [&](Id id, const Triangle3& o) {
        if (squaredDistanceToTriangle(c, o) <= (e - r) * (e - r)) {
          found = id;
          done = true;
        }
        return done;
      });
  }
  if (done) {
    if (pieces) pieces->push_back({t, found});
    return true;
  }
  if (depth == 0) return false;
  const auto mid = [](const Point3& a, const Point3& b) {
    return Point3{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
  };
  const Point3 m01 = mid(t[0], t[1]), m12 = mid(t[1], t[2]), m20 = mid(t[2], t[0]);
  for (const Triangle3& piece : {Triangle3{t[0], m01, m20}, Triangle3{m01, t[1], m12}, Triangle3{m20, m12, t[2]},
                                 Triangle3{m01, m12, m20}})
    if (!coverTriangle<Id>(piece, e, depth - 1, near, pieces)) return false;
  return true;
}

}  // namespace surftrack::refine
