// surftrack_mesh_check MESH...: the independent figures of each mesh file (CgalMeshChecks.h: CGAL
// and counts by hand) as one JSON line each: triangles, closed and oriented, manifold, Euler
// characteristic, components, genus (one component), self-intersecting triangle pairs. For
// bench/bench_refine_vtk.py, which checks VTK's output and surftrack's with the same tool.
#include <cstdio>
#include <iostream>
#include <string>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "CgalMeshChecks.h"

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::cout << "usage: surftrack_mesh_check MESH...  (PLY, OBJ, OFF, STL; one JSON line per mesh)\n";
    return argc < 2 ? 2 : 0;
  }
  for (int i = 1; i < argc; ++i) {
    OpenMesh::TriMesh_ArrayKernelT<> mesh;
    if (!OpenMesh::IO::read_mesh(mesh, argv[i])) {
      std::cerr << "surftrack_mesh_check: cannot read " << argv[i] << "\n";
      return 1;
    }
    surftrack::checks::Points points;
    surftrack::checks::Triangles triangles;
    for (auto v : mesh.vertices()) {
      const auto p = mesh.point(v);
      points.push_back({p[0], p[1], p[2]});
    }
    for (auto f : mesh.faces()) {
      std::array<std::uint32_t, 3> t{};
      int k = 0;
      for (auto v : mesh.fv_range(f)) t[k++] = std::uint32_t(v.idx());
      triangles.push_back(t);
    }
    const auto topology = surftrack::checks::topologyOf(points.size(), triangles);
    const std::size_t pairs = surftrack::checks::selfIntersections(points, triangles);
    std::printf("{\"path\": \"%s\", \"triangles\": %zu, \"closed_oriented\": %s, \"manifold\": %s, \"euler\": %lld, "
                "\"components\": %zu, \"genus\": %s, \"self_intersecting_pairs\": %zu}\n",
                argv[i], triangles.size(), topology.closedOriented ? "true" : "false",
                topology.manifoldVertices ? "true" : "false", topology.euler, topology.components,
                topology.components == 1 ? std::to_string((2 - topology.euler) / 2.0).c_str() : "null", pairs);
  }
  return 0;
}
