// writeSurface: a Surface through the converter's manifold check and OpenMesh's writers.
#include "Errors.h"
#include "Extract.h"
#include "MeshIO.h"
#include "SurfaceMesh.h"

namespace surftrack {

void writeSurface(const Surface& surface, const std::string& path, bool binary) {
  // No half-edge mesh is needed to write a file: the triangles are checked as toSurfaceMesh
  // would check them, then written from the list (converter/MeshIO.h).
  try {
    requireClosedOrientedManifold(surface.vertices.size(), surface.triangles);
  } catch (const std::invalid_argument& e) {  // a vertex index out of range
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {  // not a closed oriented manifold: an engine bug
    throw InternalError(e.what());
  }
  try {
    writeTriangles(surface.vertices, surface.triangles, path, binary);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  }
}

}  // namespace surftrack
