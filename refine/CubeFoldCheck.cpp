#include "CubeFoldCheck.h"

#include <algorithm>

#include "DigitalCube.h"

namespace surftrack::refine {

bool triangleKeepsItsSide(const CubeTriangle& t, double tolerance) {
  const Point3 n = triangleNormal(t.point);
  if (!(norm(n) > tolerance)) return false;      // degenerate (section 8, point 3)
  return dot(n, t.reference) > 0;                // not turned over
}

bool trianglesAreEmbedded(const CubeTriangle& t, const CubeTriangle& u, double tolerance) {
  int shared[3], count = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (t.vertex[a] == u.vertex[b]) shared[count++] = a * 3 + b;
  return !trianglesMeetOutsideShared(t.point, u.point, std::span<const int>(shared, std::size_t(count)), tolerance);
}

bool cubeIsEmbedded(std::span<const CubeTriangle> triangles, double tolerance) {
  for (const CubeTriangle& t : triangles)
    if (!triangleKeepsItsSide(t, tolerance)) return false;
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (std::size_t j = i + 1; j < triangles.size(); ++j)
      if (!trianglesAreEmbedded(triangles[i], triangles[j], tolerance)) return false;
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
