// Cancellation of the engine's long loops (docs/api.md, "Errors"): the caller raises a flag from
// another thread (a signal handler's watcher, a GUI) and the loop stops at its next check by
// throwing Cancelled. Here, below the front door, so that the tracker, the converter and refine/
// throw the same exception the front door documents (core's Errors.h re-exports it).
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>

namespace surftrack {

/// The caller's cancellation flag was raised during an extraction, a smoothing, a decimation or
/// a write.
class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws Cancelled("<what> cancelled") if `flag` is set and raised; a relaxed load, cheap
/// enough for every pass of a loop.
inline void throwIfCancelled(const std::atomic<bool>* flag, const char* what) {
  if (flag && flag->load(std::memory_order_relaxed)) throw Cancelled(std::string(what) + " cancelled");
}

}  // namespace surftrack
