// The front door's SmoothOptions as refine/'s SmoothingParameters (internal to core/), for
// smooth() (Refine.cpp) and the smoothing of a label map's complex (ComplexSmoothing.h), so that
// both take and check the same options.
#pragma once

#include <string>

#include "ConstrainedSmoothing.h"
#include "Errors.h"
#include "Refine.h"

namespace surftrack {

/// The parameters of `o`; InvalidInput for more than kMaxSmoothIterations iterations (refine/
/// checks the rest). `cancel` stands in for o.cancel when that is not set.
inline refine::SmoothingParameters smoothingParameters(const SmoothOptions& o,
                                                       const std::atomic<bool>* cancel = nullptr) {
  if (o.iterations > kMaxSmoothIterations)
    throw InvalidInput("smoothing iterations " + std::to_string(o.iterations) + " is above the limit of " +
                       std::to_string(kMaxSmoothIterations));
  refine::SmoothingParameters p;
  p.iterations = o.iterations;
  p.lambda = o.lambda;
  p.mu = o.mu;
  p.epsilon = o.epsilon;
  p.threads = o.threads;
  p.cancel = o.cancel ? o.cancel : cancel;
  return p;
}

}  // namespace surftrack
