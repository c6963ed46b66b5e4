#include "CubeFoldCheck.h"

#include <algorithm>
#include <cmath>

#include "DigitalCube.h"

namespace surftrack::refine {

namespace {

double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Rotates `t` (cyclically, keeping its orientation) so that its vertex `id` comes first.
Triangle3 startAt(const CubeTriangle& t, std::uint32_t id) {
  int k = 0;
  while (t.vertex[k] != id) ++k;
  return {t.point[k], t.point[(k + 1) % 3], t.point[(k + 2) % 3]};
}

}  // namespace

bool cubeIsEmbedded(std::span<const CubeTriangle> triangles, double tolerance) {
  for (const CubeTriangle& t : triangles) {
    const Point3 n = triangleNormal(t.point);
    const double length = std::sqrt(dot(n, n));
    if (!(length > tolerance)) return false;                  // degenerate (section 8, point 3)
    if (!(dot(n, t.reference) > 0)) return false;             // turned over
  }
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (std::size_t j = i + 1; j < triangles.size(); ++j) {
      const CubeTriangle &t = triangles[i], &u = triangles[j];
      std::uint32_t shared[3];
      int count = 0;
      for (std::uint32_t a : t.vertex)
        if (std::find(u.vertex.begin(), u.vertex.end(), a) != u.vertex.end()) shared[count++] = a;
      if (count == 3) return false;  // the same triangle twice
      if (count == 0) {
        if (trianglesMeetImproperly(t.point, u.point, 0, tolerance)) return false;
      } else if (count == 1) {
        if (trianglesMeetImproperly(startAt(t, shared[0]), startAt(u, shared[0]), 1, tolerance)) return false;
      } else {
        // Rotate t so that its unshared vertex comes last (the shared edge first); give u the
        // same first two points and its own unshared vertex (u's orientation does not matter).
        int k = 0;
        while (t.vertex[k] == shared[0] || t.vertex[k] == shared[1]) ++k;
        const Triangle3 a{t.point[(k + 1) % 3], t.point[(k + 2) % 3], t.point[k]};
        Triangle3 b = a;
        for (int m = 0; m < 3; ++m)
          if (u.vertex[m] != shared[0] && u.vertex[m] != shared[1]) b[2] = u.point[m];
        if (trianglesMeetImproperly(a, b, 2, tolerance)) return false;
      }
    }
  return true;
}

std::optional<Voxel> cubeOfTriangle(const Surfel& a, const Surfel& b, const Surfel& c) {
  // The low end of a grid edge is min(c, d); the cube's minimum corner is the least of the
  // three low ends on every axis (three vertices never lie on one face: section 8, point 4).
  auto low = [](const Surfel& s) {
    const Voxel p = s.inside(), q = s.outside();
    return Voxel{std::min(p.x, q.x), std::min(p.y, q.y), std::min(p.z, q.z)};
  };
  const Voxel la = low(a), lb = low(b), lc = low(c);
  const Voxel m{std::min({la.x, lb.x, lc.x}), std::min({la.y, lb.y, lc.y}), std::min({la.z, lb.z, lc.z})};
  if (cube::edgeOf(m, a) < 0 || cube::edgeOf(m, b) < 0 || cube::edgeOf(m, c) < 0) return std::nullopt;
  return m;
}

}  // namespace surftrack::refine
