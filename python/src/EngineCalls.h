// What the binding's files share (python/src/): numpy arrays as the engine's VolumeViews, the
// engine run on a thread of its own while the caller watches for Ctrl-C, and the engine's
// errors with their voxels in the caller's axes (docs/python.md).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <surftrack/Extract.h>

namespace surftrack::binding {

namespace py = pybind11;

/// The ScalarType of a numpy dtype; throws TypeError for anything but the ten types.
ScalarType scalarTypeOfDtype(const py::dtype& dtype);

/// The largest volume dimension the engine takes (core/src/ViewSource.cpp: surfel keys hold 20
/// bits per coordinate, with a voxel of margin on each side).
inline constexpr int kMaxDimension = Surfel::kCoordinateLimit - 3;

/// The view of `volume` whose engine axes x, y, z are the array axes order[0..2], with its
/// geometry given in array axes.
VolumeView viewOfArray(const py::array& volume, std::array<int, 3> order, std::array<double, 3> spacing,
                       std::array<double, 3> origin, std::array<std::array<double, 3>, 3> direction);

/// An engine message with its voxel coordinates in the caller's axes: the engine's x, y, z are
/// the array axes order[0..2] (surftrack/__init__.py), and its messages print a voxel as
/// "(x,y,z)" after "voxel ", "voxel index " or, in a surfel, "c=" and "d=", and a domain as
/// "[0,nx)x[0,ny)x[0,nz)" (core/src/Extract.cpp, core/src/Labels.cpp). Physical points are in
/// the caller's frame already and are left alone.
std::string inArrayAxes(const std::string& message, std::array<int, 3> order);

/// Runs `work` (engine code that touches no Python object without taking the GIL) on a worker
/// thread while the calling thread watches for Ctrl-C: Python runs its signal handlers on the
/// main thread only, between bytecodes, and the engine's long loops (tracking, scanning,
/// smoothing, decimation, writing) check `cancel` instead. Every 50 ms the caller takes the GIL
/// and runs the pending handlers (PyErr_CheckSignals); one that raises (KeyboardInterrupt for
/// SIGINT) raises `cancel`, and once the work has stopped at its next check that exception is
/// raised here. Otherwise the work's own exception, if any, is rethrown here.
template <class Work>
void runWatchingSignals(std::atomic<bool>& cancel, Work&& work) {
  std::future<void> done = std::async(std::launch::async, std::forward<Work>(work));
  for (;;) {
    bool finished;
    {
      py::gil_scoped_release release;
      finished = done.wait_for(std::chrono::milliseconds(50)) == std::future_status::ready;
    }
    if (finished) break;
    if (PyErr_CheckSignals() != 0) {
      py::error_already_set interrupt;  // the handler's exception, fetched
      cancel = true;
      {
        py::gil_scoped_release release;
        done.wait();
      }
      try {
        done.get();
      } catch (...) {  // Cancelled, or whatever came first: the interrupt is what the caller asked
      }
      throw interrupt;
    }
  }
  done.get();
}

/// runWatchingSignals for the engine's extractions: their errors' voxels in the caller's axes.
template <class Work>
void runEngine(std::array<int, 3> order, std::atomic<bool>& cancel, Work&& work) {
  try {
    runWatchingSignals(cancel, std::forward<Work>(work));
  } catch (const InvalidInput& e) {
    throw InvalidInput(inArrayAxes(e.what(), order));
  } catch (const InternalError& e) {
    throw InternalError(inArrayAxes(e.what(), order));
  }
}

/// A numpy array over `data` (shape `shape`), owned by the heap object `owner`: no copy.
template <class T, class Owner>
py::array_t<T> viewOf(T* data, std::vector<py::ssize_t> shape, std::shared_ptr<Owner> owner) {
  auto* keep = new std::shared_ptr<Owner>(std::move(owner));
  py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<Owner>*>(p); });
  return py::array_t<T>(shape, data, base);
}

}  // namespace surftrack::binding
