// The public output of the converter: an OpenMesh triangle mesh of a kappa-lambda-boundary's
// continuous analog (paper §5.2) whose vertices are the boundary surfels, placed by a boundary
// mapping (§3.1) and then by the image geometry.
//
// Two paths:
//  - cheap: extractLoops(image, graph) -> TriangleMesh, then mapVertices(...) -> positions
//    (plain vectors, no OpenMesh);
//  - full:  toMesh(graph, image, mapping, geometry) -> SurfaceMesh (half-edge structure).
#pragma once

#include <array>
#include <vector>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "BoundaryMapping.h"
#include "Image.h"
#include "LoopExtraction.h"
#include "SurfaceGraph.h"
#include "TriangleMesh.h"

namespace surftrack {

struct SurfaceMeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};

/// Double-precision OpenMesh triangle mesh; every vertex carries its Surfel in the vertex
/// property named kSurfelPropertyName.
using SurfaceMesh = OpenMesh::TriMesh_ArrayKernelT<SurfaceMeshTraits>;

inline constexpr const char* kSurfelPropertyName = "surftrack:surfel";

/// The handle of the surfel vertex property; throws std::invalid_argument if the mesh has none.
OpenMesh::VPropHandleT<Surfel> surfelProperty(const SurfaceMesh& mesh);

/// The surfel of vertex vh.
Surfel surfelOf(const SurfaceMesh& mesh, SurfaceMesh::VertexHandle vh);

/// Each vertex's point: mapping(surfel) in index space, then geometry.toPhysical.
template <class Mapping>
std::vector<std::array<double, 3>> mapVertices(const TriangleMesh& mesh, const Mapping& mapping,
                                               const ImageGeometry& geometry = {}) {
  std::vector<std::array<double, 3>> positions;
  positions.reserve(mesh.surfels.size());
  for (const Surfel& s : mesh.surfels) positions.push_back(geometry.toPhysical(mapping(s)));
  return positions;
}

/// The OpenMesh mesh of an indexed mesh: vertex v at positions[v] with surfel mesh.surfels[v].
/// Throws std::invalid_argument if the sizes differ, std::logic_error if OpenMesh refuses a
/// face (a complex edge or vertex: the triangles are not a manifold, which a correct
/// conversion never produces).
SurfaceMesh toSurfaceMesh(const TriangleMesh& mesh,
                          const std::vector<std::array<double, 3>>& positions);

/// Track-to-mesh in one call: the continuous analog of the boundary of `graph` (extractLoops),
/// vertices placed by `mapping` and `geometry`.
template <class BinaryImage, class Mapping>
SurfaceMesh toMesh(const SurfaceGraph& graph, const BinaryImage& image, const Mapping& mapping,
                   const ImageGeometry& geometry = {}) {
  const TriangleMesh mesh = extractLoops(image, graph);
  return toSurfaceMesh(mesh, mapVertices(mesh, mapping, geometry));
}

}  // namespace surftrack
