// LabelOptions::decimate on shared walls (docs/theory.md §12, "Decimating the complex"): the
// front door's side of refine::decimateComplex, as decimate() (Refine.cpp) is of
// decimateSafely: the options checked and passed on, the errors translated.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ComplexDecimation.h"
#include "Errors.h"
#include "Refine.h"

namespace surftrack {

/// Decimates the complex of shared walls `triangles` (each wall once, between the regions
/// sides[t]) over `points` (physical) in place; removed[t] then says whether triangle t is gone.
/// Region 0 is the background (SharedWallLabels.h's priorities): no surface, no target.
inline refine::ComplexDecimationReport decimateWalls(const std::vector<refine::Point3>& points,
                                                     std::vector<std::array<std::uint32_t, 3>>& triangles,
                                                     const std::vector<std::array<std::uint32_t, 2>>& sides,
                                                     std::vector<char>& removed, const DecimateOptions& o,
                                                     const std::atomic<bool>* extractionCancel) {
  if (!o.maxError && !o.reduction) throw InvalidInput("decimation needs a max error, a reduction or both");
  refine::DecimationParameters p;
  p.maxError = o.maxError;
  p.targetReduction = o.reduction;
  p.maxNormalDeviation = o.maxNormalDeviation;
  p.cancel = o.cancel ? o.cancel : extractionCancel;
  // As decimate(): a bad argument is the caller's, a broken invariant the engine's (the order of
  // the handlers matters: std::invalid_argument is a std::logic_error).
  try {
    return refine::decimateComplex(points, triangles, sides, removed, p, 0);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {
    throw InternalError(std::string("decimating the shared walls: ") + e.what());
  }
}

}  // namespace surftrack
