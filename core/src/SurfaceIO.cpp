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

void writeSurfaceComponents(const Surface& surface, const std::vector<std::string>& paths, bool binary,
                            const std::atomic<bool>* cancel) {
  std::vector<std::uint32_t> componentOf;
  const std::size_t count = componentFigures(surface.vertices, surface.triangles, &componentOf).size();
  if (paths.size() != count)
    throw InvalidInput("the surface has " + std::to_string(count) + " components, not " +
                       std::to_string(paths.size()) + " (one file each)");
  std::vector<Surface> parts(count);
  std::vector<std::uint32_t> index(surface.vertices.size());
  for (std::size_t v = 0; v < surface.vertices.size(); ++v) {  // in the surface's order
    Surface& part = parts[componentOf[v]];
    index[v] = std::uint32_t(part.vertices.size());
    part.vertices.push_back(surface.vertices[v]);
  }
  for (const auto& t : surface.triangles)  // a triangle's corners share its component
    parts[componentOf[t[0]]].triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
  for (std::size_t k = 0; k < count; ++k) {
    writeSurface(parts[k], paths[k], binary, cancel);
    parts[k] = Surface();  // (one component held twice at most)
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
