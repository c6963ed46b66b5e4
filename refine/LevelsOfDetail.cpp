// Levels of detail on an octree grid (LevelsOfDetail.h).
#include "LevelsOfDetail.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "SurfaceMesh.h"
#include "TopologySafeDecimation.h"

namespace surftrack::refine {

OctreeGrid gridFor(const std::vector<std::array<double, 3>>& vertices, int lods) {
  OctreeGrid g;
  g.lods = lods;
  for (int a = 0; a < 3; ++a) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& p : vertices) lo = std::min(lo, p[std::size_t(a)]), hi = std::max(hi, p[std::size_t(a)]);
    if (vertices.empty()) lo = hi = 0;
    double origin = std::floor(lo) - 0.25;
    float f = float(origin);  // the manifest's float32, below the mesh
    while (double(f) >= lo) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    origin = double(f);
    const double cells = std::ldexp(1.0, lods - 1);
    double chunk = std::max(8.0, std::ceil((hi - origin) / cells));
    while (origin + chunk * cells <= hi) chunk += 1;  // the mesh strictly inside the top cell
    g.origin[std::size_t(a)] = origin;
    g.chunk[std::size_t(a)] = double(float(chunk));
  }
  return g;
}

std::vector<GridMesh> levelsOfDetail(const GridMesh& mesh, const OctreeGrid& grid, const LevelsOfDetailOptions& o) {
  std::vector<GridMesh> levels;
  std::array<double, 3> snap{};
  for (int a = 0; a < 3; ++a) snap[std::size_t(a)] = grid.chunk[std::size_t(a)] / (std::ldexp(1.0, o.quantizationBits) - 1);
  levels.push_back(cutOnGrid(mesh, grid, snap));
  for (int k = 1; k < grid.lods; ++k) {
    const GridMesh& finer = levels.back();
    SurfaceMesh m;
    try {
      m = toSurfaceMesh(TriangleMesh{std::vector<Surfel>(finer.vertices.size()), finer.triangles}, finer.vertices);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("levels of detail need a closed oriented manifold: ") + e.what());
    }
    DecimationParameters p;
    p.maxError = o.firstError * std::ldexp(1.0, k - 1);
    p.maxNormalDeviation = o.maxNormalDeviation;
    p.cancel = o.cancel;
    p.grid = grid;
    p.gridLevel = k - 1;
    decimateSafely(m, p);
    GridMesh level;
    level.vertices.reserve(m.n_vertices());
    for (auto vh : m.vertices()) {
      const auto& q = m.point(vh);
      level.vertices.push_back({q[0], q[1], q[2]});
    }
    level.triangles.reserve(m.n_faces());
    for (auto fh : m.faces()) {
      std::array<std::uint32_t, 3> t{};
      int i = 0;
      for (auto vh : m.fv_range(fh)) t[std::size_t(i++)] = std::uint32_t(vh.idx());
      level.triangles.push_back(t);
    }
    levels.push_back(std::move(level));
  }
  return levels;
}

}  // namespace surftrack::refine
