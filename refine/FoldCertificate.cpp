#include "FoldCertificate.h"

#include <algorithm>
#include <initializer_list>

#include "DigitalCube.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

namespace {

/// The least |value| a certificate accepts as a strict sign: the values are volumes and areas
/// of a unit cube, so this is far above their rounding and far below their size.
constexpr double kMargin = 1e-7;

/// The point of cube edge k at parameter tau, in the cube's coordinates.
Point3 onEdge(int k, double tau) {
  const Voxel low = cube::cornerOffset(cube::edgeLowCorner(k));
  Point3 p{double(low.x), double(low.y), double(low.z)};
  p[cube::edgeAxis(k)] += tau;
  return p;
}

double orient(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return dot(cross(sub(b, a), sub(c, a)), sub(d, a));
}

/// det(e_k, y - x, z - x): the side of z of the plane through x and y parallel to axis k.
double sideAlongAxis(int k, const Point3& x, const Point3& y, const Point3& z) {
  Point3 e{0, 0, 0};
  e[k] = 1;
  return dot(cross(e, sub(y, x)), sub(z, x));
}

/// +1 or -1 when every value of `own` has that strict sign and every value of `other` the
/// opposite one (with `own` empty: when every value of `other` has one strict sign, which is
/// returned), else 0.
int separation(std::initializer_list<double> own, std::initializer_list<double> other) {
  int sign = 0;
  for (double v : own) {
    const int s = v > kMargin ? 1 : v < -kMargin ? -1 : 0;
    if (s == 0 || (sign != 0 && s != sign)) return 0;
    sign = s;
  }
  const bool bare = sign == 0;
  for (double v : other) {
    const int s = v > kMargin ? -1 : v < -kMargin ? 1 : 0;  // opposite to own
    if (s == 0 || (sign != 0 && s != sign)) return 0;
    sign = s;
  }
  return bare ? -sign : sign;
}

int memoKey(const CubeEdges& t) { return t[0] + 12 * (t[1] + 12 * t[2]); }

}  // namespace

FoldCertificates::FoldCertificates(double epsilon)
    : epsilon_(epsilon), triangles_(12 * 12 * 12, -1), pairs_(12 * 12 * 12 * 12 * 12 * 12, -1) {}

bool FoldCertificates::triangleIsCertain(const CubeEdges& t) {
  std::int8_t& memo = triangles_[std::size_t(memoKey(t))];
  if (memo < 0) memo = computeTriangle(t);
  return memo == 1;
}

bool FoldCertificates::pairIsCertain(const CubeEdges& t, const CubeEdges& u) {
  std::int8_t& memo = pairs_[std::size_t(memoKey(t)) * 1728 + std::size_t(memoKey(u))];
  if (memo < 0) memo = computePair(t, u);
  return memo == 1;
}

bool FoldCertificates::computeTriangle(const CubeEdges& t) const {
  const Point3 reference = triangleNormal({onEdge(t[0], 0.5), onEdge(t[1], 0.5), onEdge(t[2], 0.5)});
  for (int mask = 0; mask < 8; ++mask) {
    Triangle3 p;
    for (int k = 0; k < 3; ++k) p[k] = onEdge(t[k], mask >> k & 1 ? 1 - epsilon_ : epsilon_);
    if (!(dot(triangleNormal(p), reference) > kMargin)) return false;
  }
  return true;
}

bool FoldCertificates::computePair(const CubeEdges& t0, const CubeEdges& u0) const {
  // Rotate both (keeping their orientations, which no certificate needs) so that the shared
  // vertices come first, in the same order.
  CubeEdges t = t0, u = u0;
  int shared = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (t0[a] == u0[b]) ++shared;
  if (shared == 3) return false;
  auto rotate = [](CubeEdges& x, int first) { x = {x[first], x[(first + 1) % 3], x[(first + 2) % 3]}; };
  auto inU = [&](std::uint8_t e) { return e == u0[0] || e == u0[1] || e == u0[2]; };
  if (shared == 1) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (t0[i] == u0[j]) {
          rotate(t, i);
          rotate(u, j);
        }
  } else if (shared == 2) {
    int i = 0;
    while (!(inU(t0[i]) && inU(t0[(i + 1) % 3]))) ++i;
    rotate(t, i);
    std::uint8_t other = 0;
    for (std::uint8_t e : u0)
      if (e != t[0] && e != t[1]) other = e;
    u = {t[0], t[1], other};  // the shared edge first (u's orientation does not matter)
  }
  // The distinct edges and, for each of the six vertex slots, its edge's index among them.
  std::array<std::uint8_t, 6> edges{};
  std::array<int, 6> slot{};
  int n = 0;
  for (int i = 0; i < 6; ++i) {
    const std::uint8_t e = i < 3 ? t[i] : u[i - 3];
    int k = 0;
    while (k < n && edges[k] != e) ++k;
    if (k == n) edges[n++] = e;
    slot[i] = k;
  }
  constexpr int kMaxCandidates = 23;
  std::array<int, kMaxCandidates> sign;
  sign.fill(2);  // 2: no corner yet; 0: failed
  for (int mask = 0; mask < (1 << n); ++mask) {
    std::array<Point3, 6> q;
    for (int k = 0; k < n; ++k) q[k] = onEdge(edges[k], mask >> k & 1 ? 1 - epsilon_ : epsilon_);
    const Point3 &a = q[slot[0]], &b = q[slot[1]], &c = q[slot[2]];
    const Point3 &d = q[slot[3]], &e = q[slot[4]], &f = q[slot[5]];
    int count = 0;
    std::array<int, kMaxCandidates> s;
    if (shared == 0) {  // t = (a, b, c), u = (d, e, f)
      s[count++] = separation({}, {orient(a, b, c, d), orient(a, b, c, e), orient(a, b, c, f)});
      s[count++] = separation({}, {orient(d, e, f, a), orient(d, e, f, b), orient(d, e, f, c)});
      for (int k = 0; k < 3; ++k) {
        const double lo = std::min({a[k], b[k], c[k]}), hi = std::max({a[k], b[k], c[k]});
        const double ulo = std::min({d[k], e[k], f[k]}), uhi = std::max({d[k], e[k], f[k]});
        s[count++] = ulo - hi > kMargin ? 1 : lo - uhi > kMargin ? -1 : 0;
        const Point3* tp[3] = {&a, &b, &c};
        const Point3* up[3] = {&d, &e, &f};
        for (int i = 0; i < 3; ++i) {
          const Point3 &x = *tp[i], &y = *tp[(i + 1) % 3], &w = *tp[(i + 2) % 3];
          s[count++] = separation({sideAlongAxis(k, x, y, w)},
                                  {sideAlongAxis(k, x, y, d), sideAlongAxis(k, x, y, e), sideAlongAxis(k, x, y, f)});
          const Point3 &xu = *up[i], &yu = *up[(i + 1) % 3], &wu = *up[(i + 2) % 3];
          s[count++] = separation({sideAlongAxis(k, xu, yu, wu)}, {sideAlongAxis(k, xu, yu, a),
                                                                    sideAlongAxis(k, xu, yu, b),
                                                                    sideAlongAxis(k, xu, yu, c)});
        }
      }
    } else if (shared == 1) {  // t = (p, b, c), u = (p, e, f), p = a = d
      const Point3& p = a;
      s[count++] = separation({orient(p, e, f, b), orient(p, e, f, c)}, {});
      s[count++] = separation({orient(p, b, c, e), orient(p, b, c, f)}, {});
      for (int k = 0; k < 3; ++k) {
        s[count++] = separation({b[k] - p[k], c[k] - p[k]}, {e[k] - p[k], f[k] - p[k]});
        s[count++] = separation({sideAlongAxis(k, p, b, c)}, {sideAlongAxis(k, p, b, e), sideAlongAxis(k, p, b, f)});
        s[count++] = separation({sideAlongAxis(k, p, c, b)}, {sideAlongAxis(k, p, c, e), sideAlongAxis(k, p, c, f)});
        s[count++] = separation({sideAlongAxis(k, p, e, f)}, {sideAlongAxis(k, p, e, b), sideAlongAxis(k, p, e, c)});
        s[count++] = separation({sideAlongAxis(k, p, f, e)}, {sideAlongAxis(k, p, f, b), sideAlongAxis(k, p, f, c)});
      }
    } else {  // t = (a, b, c), u = (a, b, f)
      s[count++] = separation({orient(a, b, c, f)}, {});
      for (int k = 0; k < 3; ++k) s[count++] = separation({sideAlongAxis(k, b, a, c)}, {sideAlongAxis(k, b, a, f)});
    }
    bool alive = false;
    for (int i = 0; i < count; ++i) {
      if (sign[i] == 0) continue;
      if (s[i] == 0 || (sign[i] != 2 && s[i] != sign[i])) sign[i] = 0;
      else {
        sign[i] = s[i];
        alive = true;
      }
    }
    if (!alive) return false;
  }
  return true;
}

}  // namespace surftrack::refine
