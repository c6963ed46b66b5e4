// A selection's value as a voxel value (internal to core/).
#pragma once

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

#include "Errors.h"
#include "ScalarType.h"
#include "VoxelSource.h"

namespace surftrack {

/// A number in messages: `precision` significant digits, no trailing zeros.
inline std::string numberText(double v, int precision = 17) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

/// Whether `value` is exactly a value of T (integers: in range and integral; floats: finite).
template <class T>
bool holdsValue(double value) {
  if constexpr (std::is_integral_v<T>)
    // max + 1 is a power of two, exact as a double (max itself may not be: 2^64 - 1).
    return value == std::floor(value) && value >= double(std::numeric_limits<T>::lowest()) &&
           value < std::ldexp(1.0, std::numeric_limits<T>::digits);
  else
    return std::isfinite(value);
}

/// The label of a label selection as a T (checked by requireSelectable beforehand).
template <class T>
T selectionValue(const Selection& selection) {
  return T(selection.value);
}

/// Throws InvalidInput unless `selection` means something for voxels of `type`.
inline void requireSelectable(ScalarType type, const Selection& selection) {
  if (std::isnan(selection.value))
    throw InvalidInput(std::string(selection.isLabel() ? "label" : "iso-value") + " is NaN");
  if (selection.isLabel() &&
      !visitScalarType(type, [&](auto v) { return holdsValue<decltype(v)>(selection.value); }))
    throw InvalidInput("label " + numberText(selection.value) + " is not a value of " + toString(type) +
                       " voxels");
}

}  // namespace surftrack
