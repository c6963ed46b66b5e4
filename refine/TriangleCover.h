// Whether every point of a triangle lies within a distance E of a set of triangles — proven, not
// sampled (docs/theory.md §12, "Decimating the complex"; ProvenDistanceGuard.h). The distance to one triangle is a
// convex function, so a triangle whose three corners are within E of one triangle of the set
// lies within E of it whole. Otherwise the triangle is cut into its four midpoint triangles, down
// to `depth` cuts or a radius of E / 4 (unless a corner is within E of none of them: then nothing
// can prove it); a piece still unproven there is accepted only when its centroid's distance to
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

namespace cover_detail {

template <class Id>
struct Candidate {
  Id id;
  Triangle3 triangle;
  Box3 box;
};

/// coverTriangle on a list of candidates (every triangle that may be within e of t).
template <class Id>
bool coverByList(const Triangle3& t, double e, int depth, const std::vector<Candidate<Id>>& list,
                 std::vector<std::pair<Triangle3, Id>>* pieces) {
  const double e2 = e * e;
  const Box3 box = boxOf(t, e);
  bool cornerNear[3] = {false, false, false};
  for (const Candidate<Id>& c : list) {
    if (!c.box.meets(box)) continue;
    bool all = true;
    for (int k = 0; k < 3; ++k) {
      const bool within = squaredDistanceToTriangle(t[k], c.triangle) <= e2;
      cornerNear[k] = cornerNear[k] || within;
      all = all && within;
    }
    if (all) {
      if (pieces) pieces->push_back({t, c.id});
      return true;
    }
  }
  if (!(cornerNear[0] && cornerNear[1] && cornerNear[2])) return false;
  const Point3 m{(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3,
                 (t[0][2] + t[1][2] + t[2][2]) / 3};
  double r = 0;
  for (const Point3& p : t) r = std::max(r, norm(sub(p, m)));
  // A piece is not cut below a radius of E / 4, so that the pieces handed on from collapse to
  // collapse stay few (a triangle of radius E ends in 16 pieces at most).
  if (depth == 0 || r <= e / 4) {
    if (r >= e) return false;
    for (const Candidate<Id>& c : list)
      if (squaredDistanceToTriangle(m, c.triangle) <= (e - r) * (e - r)) {
        if (pieces) pieces->push_back({t, c.id});
        return true;
      }
    return false;
  }
  const auto mid = [](const Point3& a, const Point3& b) {
    return Point3{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
  };
  const Point3 m01 = mid(t[0], t[1]), m12 = mid(t[1], t[2]), m20 = mid(t[2], t[0]);
  for (const Triangle3& piece : {Triangle3{t[0], m01, m20}, Triangle3{m01, t[1], m12}, Triangle3{m20, m12, t[2]},
                                 Triangle3{m01, m12, m20}})
    if (!coverByList<Id>(piece, e, depth - 1, list, pieces)) return false;
  return true;
}

}  // namespace cover_detail

/// True when every point of `t` is within `e` of one of the triangles `near` offers. near(box,
/// visit) calls visit(id, triangle) for the set's triangles that may meet `box` (the most likely
/// first), until visit returns true. With `pieces`, each proven piece of t is appended with the
/// id of the triangle it was proven near (on a "no", what was appended is to be discarded).
template <class Id, class Near>
bool coverTriangle(const Triangle3& t, double e, int depth, Near&& near,
                   std::vector<std::pair<Triangle3, Id>>* pieces = nullptr) {
  // Most often one triangle, among the first offered, takes t whole: that pass stops there.
  const double e2 = e * e;
  bool done = false, cornerNear[3] = {false, false, false};
  Id found{};
  near(boxOf(t, e), [&](Id id, const Triangle3& o) {
    bool all = true;
    for (int k = 0; k < 3; ++k) {
      const bool within = squaredDistanceToTriangle(t[k], o) <= e2;
      cornerNear[k] = cornerNear[k] || within;
      all = all && within;
    }
    if (all) {
      found = id;
      done = true;
    }
    return done;
  });
  if (done) {
    if (pieces) pieces->push_back({t, found});
    return true;
  }
  // A corner within E of none of them: no cut can help (most refusals end here, cheaply).
  if (!(cornerNear[0] && cornerNear[1] && cornerNear[2])) return false;
  // Else the cuts, on the candidates gathered once.
  std::vector<cover_detail::Candidate<Id>> list;
  near(boxOf(t, e), [&](Id id, const Triangle3& o) {
    list.push_back({id, o, boxOf(o)});
    return false;
  });
  return cover_detail::coverByList<Id>(t, e, depth, list, pieces);
}

}  // namespace surftrack::refine
