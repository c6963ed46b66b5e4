// A volume the caller owns, seen without a copy (docs/api.md, "Volumes"): a pointer to voxels
// of one of the ten scalar types, the domain, strides in elements and the physical geometry.
// Views over numpy arrays, ITK buffers and memory-mapped files are all this one type.
#pragma once

#include <array>
#include <cstddef>

#include "Geometry.h"
#include "ScalarType.h"

namespace surftrack {

struct VolumeView {
  const void* data = nullptr;
  ScalarType type = ScalarType::UInt8;
  Dims dims;
  /// Voxel (x, y, z) is element x strides[0] + y strides[1] + z strides[2] from data.
  std::array<std::ptrdiff_t, 3> strides{1, 0, 0};
  ImageGeometry geometry;

  /// The view of a dense buffer with x fastest, then y, then z.
  template <class T>
  static VolumeView of(const T* data, Dims dims, const ImageGeometry& geometry = {}) {
    return VolumeView{data, scalarTypeOf<T>(), dims,
                      {1, std::ptrdiff_t(dims.nx), std::ptrdiff_t(dims.nx) * dims.ny}, geometry};
  }
  /// The view of a strided buffer (strides in elements, any sign).
  template <class T>
  static VolumeView strided(const T* data, Dims dims, std::array<std::ptrdiff_t, 3> strides,
                            const ImageGeometry& geometry = {}) {
    return VolumeView{data, scalarTypeOf<T>(), dims, strides, geometry};
  }
};

}  // namespace surftrack
