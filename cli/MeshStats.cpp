#include "MeshStats.h"

#include "MeshComponents.h"

#include <algorithm>
#include <cstdint>
#include <limits>

namespace surftrack::cli {

MeshStats computeMeshStats(const SurfaceMesh& mesh) {
  MeshStats s;
  s.vertices = mesh.n_vertices();
  s.edges = mesh.n_edges();
  s.triangles = mesh.n_faces();
  s.euler = (long long)s.vertices - (long long)s.edges + (long long)s.triangles;

  // Components through the triangles (every vertex of these meshes is on a triangle).
  std::vector<std::array<std::uint32_t, 3>> triangles;
  triangles.reserve(s.triangles);
  for (auto fh : mesh.faces()) {
    auto fv = mesh.cfv_iter(fh);
    const std::uint32_t a = fv->idx(), b = (++fv)->idx(), c = (++fv)->idx();
    triangles.push_back({a, b, c});
  }
  std::size_t count = 0;
  const std::vector<std::uint32_t> label = triangleComponents(s.vertices, triangles, count);
  std::vector<ComponentStats> comps(count);
  for (std::uint32_t c : label) comps[c].vertices++;
  s.closed = true;
  for (auto eh : mesh.edges())
    if (mesh.is_boundary(eh)) s.closed = false;
  for (auto eh : mesh.edges()) comps[label[mesh.from_vertex_handle(mesh.halfedge_handle(eh, 0)).idx()]].edges++;
  for (auto fh : mesh.faces()) comps[label[mesh.to_vertex_handle(mesh.halfedge_handle(fh)).idx()]].triangles++;
  for (auto& c : comps) c.euler = (long long)c.vertices - (long long)c.edges + (long long)c.triangles;
  std::stable_sort(comps.begin(), comps.end(),
                   [](const ComponentStats& a, const ComponentStats& b) { return a.vertices > b.vertices; });
  s.components = std::move(comps);

  s.manifold = true;
  for (auto vh : mesh.vertices())
    if (!mesh.is_manifold(vh) || mesh.is_isolated(vh)) {
      s.manifold = false;
      break;
    }

  const double inf = std::numeric_limits<double>::infinity();
  s.min = {inf, inf, inf};
  s.max = {-inf, -inf, -inf};
  for (auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    for (int a = 0; a < 3; ++a) {
      s.min[a] = std::min(s.min[a], double(p[a]));
      s.max[a] = std::max(s.max[a], double(p[a]));
    }
  }
  if (s.vertices == 0) s.min = s.max = {0, 0, 0};
  return s;
}

}  // namespace surftrack::cli
