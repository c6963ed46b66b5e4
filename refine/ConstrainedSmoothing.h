// Constrained smoothing of a continuous analog (docs/theory.md, section 8, "Smoothing inside
// the segments"): Taubin's lambda|mu smoothing, in physical space, of a mesh whose every vertex
// stays on its own surfel's segment ]c, d[ (paper §3.1), at a parameter t in
// [epsilon, 1 - epsilon], with a fold check per digital 3-cube and a step back where a cube
// would fold. The connectivity is not touched, so the topology is the input's; every voxel
// centre keeps its side (section 8), and no cube that was embedded stops being so.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "Geometry.h"
#include "Surfel.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

struct SmoothingParameters {
  int iterations = 20;    ///< lambda|mu pairs of passes
  double lambda = 0.7;    ///< the shrinking pass's factor, in ]0, 1]
  double mu = -0.73;      ///< the inflating pass's factor, with mu < -lambda < 0
  double epsilon = 1e-3;  ///< t stays in [epsilon, 1 - epsilon], epsilon in ]0, 0.5[
  int halvings = 4;       ///< step-back halvings of a vertex's move before it stays put
  int threads = 0;        ///< threads for the passes (0: all cores); the result is the same for any
  /// If set and raised, the smoothing stops before its next pass and throws Cancelled
  /// (lib/Cancellation.h); the points are then left as they were.
  const std::atomic<bool>* cancel = nullptr;
};

struct SmoothingReport {
  std::size_t cubes = 0;           ///< digital 3-cubes holding triangles
  std::size_t unguardedCubes = 0;  ///< cubes not embedded in the input, left unchecked
  std::size_t checkedCubes = 0;    ///< guarded cubes with a test left after the certificates
  std::size_t stepsBack = 0;       ///< vertex moves halved or undone by the fold check
  double maxDisplacement = 0;      ///< largest vertex move, physical units
};

/// Smooths the mesh of `points`, `surfels` and `triangles` in place: vertex v at points[v]
/// (physical, `geometry` applied to index space) is the surfel surfels[v] and lies on its
/// segment; only the points change. The one-rings come from the triangles, with no half-edge
/// mesh.
/// \pre the mesh is a continuous analog as the converter builds it: a closed, oriented
///      2-manifold every triangle of which has its vertices on edges of one digital 3-cube.
/// \throw std::invalid_argument for parameters out of range, sizes that differ, a vertex index
///        out of range, a surfel direction outside 0-5, a vertex off its segment, or a triangle whose vertices lie in no single
///        cube (e.g. a decimated mesh); std::logic_error (requireClosedOrientedManifold,
///        converter/SurfaceMesh.h) for triangles that are no closed, oriented 2-manifold;
///        Cancelled when parameters.cancel is raised.
SmoothingReport smoothOnSegments(std::vector<Point3>& points, const std::vector<Surfel>& surfels,
                                 const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                 const ImageGeometry& geometry, const SmoothingParameters& parameters = {});

/// The same smoothing on a conforming complex (docs/theory.md §12, "Smoothing the complex"):
/// `triangles` are the walls of a label map, each once, on the shared vertices `points` and
/// `surfels` (every vertex a surfel between two labels, one vertex per surfel). The vertex graph
/// is the triangles' (the umbrella Laplacian over a vertex's distinct neighbours, the normal
/// summed over its triangles), and the fold check tests every cube's walls together, whichever
/// labels they separate; any number of triangles may share an edge. The segments, the clamp,
/// the certificates and the fold check are smoothOnSegments'.
/// \pre every triangle has its vertices on edges of one digital 3-cube, and the walls of a cube
///      meet only in what they share (converter/NestedWalls.h).
/// \throw as smoothOnSegments, but for the manifold check.
SmoothingReport smoothComplexOnSegments(std::vector<Point3>& points, const std::vector<Surfel>& surfels,
                                        const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                        const ImageGeometry& geometry, const SmoothingParameters& parameters = {});

}  // namespace surftrack::refine
