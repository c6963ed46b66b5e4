// LabelOptions::smooth on shared walls (docs/theory.md §12, "Smoothing the complex"): the
// front door's side of refine::smoothComplexOnSegments, as smooth() (Refine.cpp) is of
// smoothOnSegments: the options checked and passed on, the errors translated.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ConstrainedSmoothing.h"
#include "Errors.h"
#include "Refine.h"
#include "SmoothingParameters.h"

namespace surftrack {

/// Smooths the complex of shared walls `triangles` (each wall once) over the vertices `points`
/// (physical, placed by the midpoint mapping) and `surfels` in place; the report's counts are
/// the complex's (its volumes and maxDisplacement are left to each label).
inline SmoothReport smoothComplex(std::vector<refine::Point3>& points, const std::vector<Surfel>& surfels,
                                  const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                  const ImageGeometry& geometry, const SmoothOptions& o,
                                  const std::atomic<bool>* extractionCancel) {
  const refine::SmoothingParameters p = smoothingParameters(o, extractionCancel);
  refine::SmoothingReport r;
  // As smooth(): a bad argument is the caller's, a broken invariant the engine's (the order of
  // the handlers matters: std::invalid_argument is a std::logic_error).
  try {
    r = refine::smoothComplexOnSegments(points, surfels, triangles, geometry, p);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {
    throw InternalError(std::string("smoothing the shared walls: ") + e.what());
  }
  SmoothReport report;
  report.iterations = o.iterations;
  report.cubes = r.cubes;
  report.unguardedCubes = r.unguardedCubes;
  report.checkedCubes = r.checkedCubes;
  report.stepsBack = r.stepsBack;
  return report;
}

}  // namespace surftrack
