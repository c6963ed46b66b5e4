// Post-processing of an extracted Surface (docs/api.md, "Smoothing and decimation"): smoothing
// that keeps every vertex on its surfel's segment, and decimation that never changes the
// topology. Both keep a Surface closed, oriented and manifold, with the same components and
// Euler characteristic; docs/theory.md, sections 8 and 10, says why.
//
//   surftrack::Surface s = surftrack::extract(view, options);
//   surftrack::smooth(s, {});                               // 20 Taubin lambda|mu iterations
//   surftrack::DecimateOptions d;  d.maxError = 0.5;  d.reduction = 0.9;
//   surftrack::decimate(s, d);
//   // or both, as the CLI and Python do:
//   surftrack::refineSurface(s, {surftrack::SmoothOptions{}, d});
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>

#include "Extract.h"

namespace surftrack {

/// The most smoothing iterations smooth() takes (the CLI's --smooth and Python's smooth= have
/// the same limit): the smoothing has long settled on the segments by then, and a larger count
/// is a typo that would keep the machine busy for hours.
inline constexpr int kMaxSmoothIterations = 100000;

/// The smoothing iterations of a label map's complex when none are given (the CLI's `labels
/// --smooth` without N): on the binary sphere of radius 11.3 they cut the RMS distance to the
/// sphere 3.2x with the volume within 0.5 % (20 iterations, smooth()'s default: 2.6x;
/// tests/test_complex_smoothing.cpp, docs/theory.md §12).
inline constexpr int kLabelSmoothIterations = 50;

struct SmoothOptions {
  int iterations = 20;    ///< Taubin lambda|mu pairs of passes, in [0, kMaxSmoothIterations] (0: nothing moves)
  double lambda = 0.7;    ///< the strength: the shrinking pass's factor, in ]0, 1]
  double mu = -0.73;      ///< the inflating pass's factor, mu < -lambda, mu >= -1
  double epsilon = 1e-3;  ///< each vertex stays at t in [epsilon, 1 - epsilon] of its segment
  int threads = 0;        ///< threads for the passes (0: all cores); the same result for any number
  /// If set and raised, smooth() stops before its next pass and throws Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

struct SmoothReport {
  int iterations = 0;
  std::size_t cubes = 0;           ///< digital 3-cubes holding triangles
  std::size_t unguardedCubes = 0;  ///< cubes not embedded before smoothing (left unchecked)
  std::size_t checkedCubes = 0;    ///< cubes tested in the passes (the others have certificates)
  std::size_t stepsBack = 0;       ///< vertex moves halved or undone by the fold check
  double maxDisplacement = 0;      ///< physical units
  double volumeBefore = 0, volumeAfter = 0;  ///< signed enclosed volume, physical units^3
};

struct DecimateOptions {
  /// Largest distance (physical units) of a removed vertex to the decimated surface.
  std::optional<double> maxError;
  /// Fraction of the triangles to remove, in [0, 1[ (as VTK's TargetReduction).
  std::optional<double> reduction;
  double maxNormalDeviation = 60;  ///< degrees: no collapse turns a triangle normal more (OpenMesh's normal-flip guard, per collapse)
  /// If set and raised, decimate() stops within a few thousand collapse candidates and throws
  /// Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

struct DecimateReport {
  std::size_t trianglesBefore = 0, trianglesAfter = 0;
  std::size_t targetTriangles = 0;  ///< (1 - reduction) * trianglesBefore; 0 without a reduction
  double volumeBefore = 0, volumeAfter = 0;
};

/// Smooths `surface` in place: Taubin lambda|mu smoothing in physical space with every vertex
/// kept on its surfel's segment ]c, d[ (at t in [epsilon, 1 - epsilon], mapped through
/// surface.geometry) and a fold check per digital 3-cube. Vertices, triangles and surfels keep
/// their indices; the figures are recomputed.
/// \pre surface is as extract() returns it (not decimated).
/// \throw InvalidInput for options out of range (more than kMaxSmoothIterations among them),
///        or a surface that is not a continuous analog (a decimated one, or vertices moved off
///        their segments); Cancelled when options.cancel is raised (the surface is then
///        unchanged).
SmoothReport smooth(Surface& surface, const SmoothOptions& options = {});

/// Decimates `surface` in place by halfedge collapses (OpenMesh's Decimater) under the link
/// condition, a normal-flip guard and the error bound, up to the reduction if one is given.
/// Surviving vertices keep their points and surfels; vertex indices are renumbered. The figures
/// are recomputed.
/// \throw InvalidInput for options out of range, or neither a maxError nor a reduction;
///        Cancelled when options.cancel is raised (the surface is then unchanged).
DecimateReport decimate(Surface& surface, const DecimateOptions& options);

/// Smoothing, then decimation, each if asked (the CLI's --smooth, --max-error, --reduce and
/// Python's smooth=, max_error=, reduce=).
struct RefineOptions {
  std::optional<SmoothOptions> smooth;      ///< nothing: no smoothing
  std::optional<DecimateOptions> decimate;  ///< nothing: no decimation
  /// Called before each step: stage "smooth" or "decimate", index among the steps asked.
  std::function<void(const ProgressEvent&)> progress;
};

struct RefineReport {
  std::optional<SmoothReport> smooth;
  std::optional<DecimateReport> decimate;
  double volumeBefore = 0, volumeAfter = 0;  ///< before the first step, after the last
};

/// smooth() then decimate() of `surface` as `options` asks (nothing asked: nothing changes).
/// \throw InvalidInput and Cancelled as smooth() and decimate() do.
RefineReport refineSurface(Surface& surface, const RefineOptions& options);

}  // namespace surftrack
