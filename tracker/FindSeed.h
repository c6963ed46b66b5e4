// Finding a seed surfel for the tracker: walk a ray of voxels from a start voxel and return
// the first boundary surfel it crosses (a 1-voxel followed by a 0-voxel, or a 0-voxel
// followed by a 1-voxel). The walk stops one voxel outside the domain.
#pragma once

#include <optional>

#include "Image.h"
#include "Surfel.h"

namespace surftrack {

template <class BinaryImage>
std::optional<Surfel> seedAlongRay(const BinaryImage& image, Voxel start, Direction direction) {
  const Dims& dims = image.dims();
  const Voxel step = unitVector(direction);
  auto inRange = [&](Voxel v) {
    for (int a = 0; a < 3; ++a)
      if (v[a] < -1 || v[a] > dims[a]) return false;
    return true;
  };
  Voxel v = start;
  if (!inRange(v)) return std::nullopt;
  bool value = image(v);
  for (Voxel w = v + step; inRange(w); v = w, w = w + step) {
    const bool next = image(w);
    if (value && !next) return Surfel{v, direction};
    if (!value && next) return Surfel{w, opposite(direction)};
    value = next;
  }
  return std::nullopt;
}

}  // namespace surftrack
