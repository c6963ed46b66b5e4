// writeSurface: a Surface through the converter's OpenMesh mesh and its atomic writer.
#include "Errors.h"
#include "Extract.h"
#include "MeshIO.h"
#include "SurfaceMesh.h"

namespace surftrack {

void writeSurface(const Surface& surface, const std::string& path, bool binary) {
  TriangleMesh mesh;
  mesh.surfels = surface.surfels;
  mesh.triangles = surface.triangles;
  SurfaceMesh m;
  try {
    m = toSurfaceMesh(mesh, surface.vertices);
  } catch (const std::logic_error& e) {
    throw InternalError(e.what());
  }
  try {
    writeMesh(m, path, binary);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  }
}

}  // namespace surftrack
