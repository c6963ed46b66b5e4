// Topology-safe decimation of a closed surface mesh with OpenMesh's Decimater (docs/theory.md,
// section 10): halfedge collapses ordered by the quadric error (Garland & Heckbert), each one
// allowed only if it
//  - keeps the topology (ModTopologyGuardT: the link condition),
//  - keeps the mesh embedded (ModEmbeddingGuardT: no new triangle meets another one),
//  - keeps the surface within `maxError` of the original one both ways, on samples
//    (ModSampledDistanceT), and the quadric error below maxError^2 (ModQuadricT),
//  - turns no triangle normal by more than `maxNormalDeviation` degrees (ModNormalFlippingT),
//  - if a grid is given, keeps the mesh cut on its planes (ModGridLockT, for levels of detail).
// A halfedge collapse moves no vertex: the survivors keep their points and their surfels.
#pragma once

#include <atomic>
#include <cstddef>
#include <optional>

#include "OctreeGrid.h"
#include "SurfaceMesh.h"

namespace surftrack::refine {

struct DecimationParameters {
  /// Largest distance, in the mesh's (physical) units, between the decimated and the original
  /// surface, both ways, on samples (DistanceGuard.h); nothing: no bound.
  std::optional<double> maxError;
  /// Fraction of the triangles to remove, in [0, 1[ (VTK's TargetReduction); nothing: as many
  /// as the other bounds allow.
  std::optional<double> targetReduction;
  double maxNormalDeviation = 60;  ///< degrees, in ]0, 180]
  /// If set and raised, the decimation stops within a few thousand candidates and throws
  /// Cancelled (lib/Cancellation.h); the mesh is then partly decimated.
  const std::atomic<bool>* cancel = nullptr;
  /// If set, the mesh is cut on the planes of this grid's level `gridLevel` and stays so
  /// (GridLockGuard.h): the vertices on them stay, no triangle crosses or lies in one.
  std::optional<OctreeGrid> grid;
  int gridLevel = 0;
};

struct DecimationReport {
  std::size_t trianglesBefore = 0, trianglesAfter = 0;
  std::size_t targetTriangles = 0;  ///< what targetReduction asked for (0: no target)
};

/// \throw std::invalid_argument naming the first of `parameters` out of range.
void requireDecimationParameters(const DecimationParameters& parameters);

/// Decimates `mesh` in place (a closed 2-manifold; vertex properties such as the surfels follow
/// the surviving vertices), then collects the garbage.
/// \throw std::invalid_argument for parameters out of range or a mesh with a boundary;
///        Cancelled when parameters.cancel is raised.
DecimationReport decimateSafely(SurfaceMesh& mesh, const DecimationParameters& parameters);

}  // namespace surftrack::refine
