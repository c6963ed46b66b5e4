// writeSurface: a Surface through the converter's manifold check and OpenMesh's writers;
// writeLabelSurfaces: label surfaces as one PLY with label properties, through the same binary
// PLY writer (converter/MeshIO.h writeLabelledTriangles).
#include <cstdint>
#include <stdexcept>

#include "Errors.h"
#include "Extract.h"
#include "Labels.h"
#include "MeshIO.h"
#include "SelectionValue.h"
#include "SurfaceMesh.h"

namespace surftrack {

void writeSurface(const Surface& surface, const std::string& path, bool binary, const std::atomic<bool>* cancel) {
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
    writeTriangles(surface.vertices, surface.triangles, path, binary, cancel);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  }
}

void writeLabelSurfaces(const std::vector<LabelSurface>& surfaces, const std::string& path, bool binary) {
  std::vector<LabelledMesh> meshes;
  for (const LabelSurface& ls : surfaces)
    meshes.push_back({&ls.surface.vertices, &ls.surface.triangles, ls.label});
  try {
    writeLabelledTriangles(meshes, path, binary);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  }
}

}  // namespace surftrack
