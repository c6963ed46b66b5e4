// Levels of detail of a closed surface on an octree grid, for Neuroglancer's multi-resolution
// format (docs/theory.md, section 10, "Levels of detail on a grid"): level 0 is the surface cut
// on level 0's planes (GridCut.h); level k > 0 is level k - 1 decimated topology-safely
// (TopologySafeDecimation.h) with the vertices on level k - 1's planes kept (GridLockGuard.h).
// So every level is a closed
// oriented manifold with the components and genus of the surface, cut as the format wants, and
// on every plane of level j's grid all levels 0 .. j + 1 cut the same curve: where Neuroglancer
// draws two levels side by side (always on such a plane) their meshes meet without a crack.
#pragma once

#include <atomic>
#include <vector>

#include "GridCut.h"
#include "OctreeGrid.h"

namespace surftrack::refine {

struct LevelsOfDetailOptions {
  /// The error bound of level 1's decimation, in the mesh's units; level k's is
  /// firstError * 2^(k-1), so level k lies within firstError * (2^k - 1) of level 0.
  double firstError = 0.5;
  double maxNormalDeviation = 60;  ///< degrees (TopologySafeDecimation.h)
  /// The fragments' quantization (10 or 16 bits): a vertex within a step of level 0 from a
  /// plane is snapped onto it before the cut (GridCut.h).
  int quantizationBits = 16;
  const std::atomic<bool>* cancel = nullptr;
};

/// A grid for `lods` levels of a mesh with these vertices: in the mesh's units (voxels when
/// they are voxel indices), its planes a quarter unit off the integers and half-integers where
/// the vertices of an unsmoothed surface lie (so cutting makes no needles), level lods - 1 a
/// single cell holding the mesh, cells of at least 8 units; origin and chunk exact in float32.
OctreeGrid gridFor(const std::vector<std::array<double, 3>>& vertices, int lods);

/// The grid.lods levels of `mesh` (a closed oriented 2-manifold).
/// \throw std::invalid_argument for a mesh that is not a closed oriented manifold (lods > 1),
///        Cancelled when options.cancel is raised.
std::vector<GridMesh> levelsOfDetail(const GridMesh& mesh, const OctreeGrid& grid, const LevelsOfDetailOptions& options);

}  // namespace surftrack::refine
