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

/// The OpenMesh mesh of an indexed mesh: vertex v at positions[v] with surfel mesh.surfels[v],
/// face f the triangle mesh.triangles[f]. The half-edge structure is built directly from the
/// oriented triangles with OpenMesh's kernel (no add_face), in O(V + F): a counting sort of
/// the triangle corners by vertex, then each vertex's fan is checked and its edges paired from
/// its own corners. Edges and halfedges get the indices toSurfaceMeshByAddFace gives them
/// (edge e is the e-th edge met in face order, its halfedge 2e runs as in that first face),
/// and so do faces' halfedges; a vertex's halfedge is one of its outgoing halfedges (the mesh
/// is closed, none is a boundary halfedge). Large arrays are advised for huge pages
/// (lib/HugePages.h).
/// Throws std::invalid_argument if the sizes differ or a vertex index is out of range, and
/// std::logic_error if the triangles are not a closed, consistently oriented 2-manifold (which
/// a correct conversion never produces, paper §5.2 and docs/theory.md): a degenerate triangle,
/// an edge in one triangle or in more than two, an edge used twice in the same direction, a
/// vertex whose triangles do not form a single fan, or a vertex in no triangle.
SurfaceMesh toSurfaceMesh(const TriangleMesh& mesh,
                          const std::vector<std::array<double, 3>>& positions);

/// The checks of toSurfaceMesh without building anything: returns iff the triangles are a
/// closed, consistently oriented 2-manifold in which each of the vertices 0 .. vertexCount - 1
/// lies. \throw std::invalid_argument, std::logic_error as toSurfaceMesh.
void requireClosedOrientedManifold(std::size_t vertexCount,
                                   const std::vector<std::array<std::uint32_t, 3>>& triangles);

/// The reference construction: the same mesh built face by face with OpenMesh's add_face, whose
/// own topology checks refuse a complex edge or vertex. Several times slower than toSurfaceMesh
/// (docs/performance.md); kept as an independent check of it. Throws std::invalid_argument like
/// toSurfaceMesh, std::logic_error if OpenMesh refuses a face; unlike toSurfaceMesh it accepts
/// vertices in no triangle and open surfaces.
SurfaceMesh toSurfaceMeshByAddFace(const TriangleMesh& mesh,
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
