#include "MeshStats.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>

namespace surftrack::cli {

MeshStats computeMeshStats(const SurfaceMesh& mesh) {
  MeshStats s;
  s.vertices = mesh.n_vertices();
  s.edges = mesh.n_edges();
  s.triangles = mesh.n_faces();
  s.euler = (long long)s.vertices - (long long)s.edges + (long long)s.triangles;

  // Components: union-find over the edges.
  std::vector<std::uint32_t> parent(s.vertices);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  s.closed = true;
  for (auto eh : mesh.edges()) {
    const auto h = mesh.halfedge_handle(eh, 0);
    const std::uint32_t a = find(mesh.from_vertex_handle(h).idx()), b = find(mesh.to_vertex_handle(h).idx());
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
    if (mesh.is_boundary(eh)) s.closed = false;
  }
  std::vector<std::uint32_t> label(s.vertices, ~0u);
  std::vector<ComponentStats> comps;
  for (std::uint32_t v = 0; v < s.vertices; ++v) {
    const std::uint32_t r = find(v);
    if (label[r] == ~0u) {
      label[r] = std::uint32_t(comps.size());
      comps.emplace_back();
    }
    label[v] = label[r];
    comps[label[v]].vertices++;
  }
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
