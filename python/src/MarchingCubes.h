// surftrack.marching_cubes' binding (MarchingCubes.cpp), registered by module.cpp.
#pragma once

#include <pybind11/pybind11.h>

namespace surftrack::binding {

/// Adds marching_cubes_array to the module.
void defineMarchingCubes(pybind11::module_& m);

}  // namespace surftrack::binding
