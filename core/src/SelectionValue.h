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

/// The label of a label selection as a T (checked by requireSelectable beforehand).
template <class T>
T selectionValue(const Selection& selection) {
  return selection.labelValue.as<T>();
}

/// Whether label L is a value of voxels of `type`.
inline bool holdsLabel(ScalarType type, const LabelValue& L) {
  return visitScalarType(type, [&](auto v) { return L.fits<decltype(v)>(); });
}

/// Throws InvalidInput unless `selection` means something for voxels of `type`.
inline void requireSelectable(ScalarType type, const Selection& selection) {
  if (!selection.isLabel() && std::isnan(selection.value)) throw InvalidInput("iso-value is NaN");
  if (selection.isLabel() && !holdsLabel(type, selection.labelValue))
    throw InvalidInput("label " + selection.labelValue.text() + " is not a value of " + toString(type) + " voxels");
}

}  // namespace surftrack
