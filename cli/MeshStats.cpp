#include "MeshStats.h"

#include <algorithm>
#include <limits>

namespace surftrack::cli {

MeshStats meshStats(const Surface& surface) {
  MeshStats s;
  s.vertices = surface.vertices.size();
  s.triangles = surface.triangles.size();
  s.edges = 3 * s.triangles / 2;
  s.euler = (long long)s.vertices - (long long)s.edges + (long long)s.triangles;
  s.components = surface.components;
  s.closed = s.manifold = true;  // requireClosedOrientedManifold's checks (SurfaceMesh.h)

  const double inf = std::numeric_limits<double>::infinity();
  s.min = {inf, inf, inf};
  s.max = {-inf, -inf, -inf};
  for (const auto& p : surface.vertices)
    for (int a = 0; a < 3; ++a) {
      s.min[a] = std::min(s.min[a], p[a]);
      s.max[a] = std::max(s.max[a], p[a]);
    }
  if (s.vertices == 0) s.min = s.max = {0, 0, 0};
  return s;
}

}  // namespace surftrack::cli
