// The exceptions of the front door (docs/api.md). Every message is one line and names the
// offending value.
#pragma once

#include <stdexcept>

#include "Cancellation.h"  // Cancelled: the caller's flag was raised

namespace surftrack {

/// Bad input: a volume, selection, seed or option the caller can correct.
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A seed voxel or point with no boundary surfel within ExtractOptions::maxSeedDistance: the
/// search stopped there, having read only the voxels within that distance (whether the
/// selection is empty is not known: finding out would read the whole image).
class SeedTooFar : public InvalidInput {
 public:
  using InvalidInput::InvalidInput;
};

/// A broken invariant inside the engine: a bug, to be reported.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace surftrack
