#include "SurfaceMesh.h"

#include <sstream>
#include <stdexcept>

namespace surftrack {

OpenMesh::VPropHandleT<Surfel> surfelProperty(const SurfaceMesh& mesh) {
  OpenMesh::VPropHandleT<Surfel> handle;
  if (!mesh.get_property_handle(handle, kSurfelPropertyName))
    throw std::invalid_argument(std::string("mesh has no '") + kSurfelPropertyName +
                                "' vertex property");
  return handle;
}

Surfel surfelOf(const SurfaceMesh& mesh, SurfaceMesh::VertexHandle vh) {
  return mesh.property(surfelProperty(mesh), vh);
}

SurfaceMesh toSurfaceMesh(const TriangleMesh& mesh,
                          const std::vector<std::array<double, 3>>& positions) {
  if (positions.size() != mesh.surfels.size())
    throw std::invalid_argument("toSurfaceMesh: " + std::to_string(positions.size()) +
                                " positions for " + std::to_string(mesh.surfels.size()) +
                                " vertices");
  SurfaceMesh out;
  out.reserve(mesh.surfels.size(), 3 * mesh.triangles.size() / 2, mesh.triangles.size());
  OpenMesh::VPropHandleT<Surfel> surfel;
  out.add_property(surfel, kSurfelPropertyName);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const auto& p = positions[v];
    const SurfaceMesh::VertexHandle vh = out.add_vertex(SurfaceMesh::Point(p[0], p[1], p[2]));
    out.property(surfel, vh) = mesh.surfels[v];
  }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    for (std::uint32_t v : t)
      if (v >= positions.size())
        throw std::invalid_argument("toSurfaceMesh: triangle " + std::to_string(f) +
                                    " uses vertex " + std::to_string(v) + " out of range");
    const SurfaceMesh::FaceHandle fh =
        out.add_face(out.vertex_handle(t[0]), out.vertex_handle(t[1]), out.vertex_handle(t[2]));
    if (!fh.is_valid()) {
      std::ostringstream msg;
      msg << "toSurfaceMesh: OpenMesh refused triangle " << f << " (" << t[0] << ", " << t[1]
          << ", " << t[2] << "): the triangles are not an oriented manifold";
      throw std::logic_error(msg.str());
    }
  }
  return out;
}

}  // namespace surftrack
