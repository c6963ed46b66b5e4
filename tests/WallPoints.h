// Exact comparisons of the points and triangles of the complex of shared walls (docs/theory.md,
// "Shared walls"): its guarantees are about bit-identical coordinates, so the tests compare
// bits, not distances. Shared by test_complex_smoothing and test_complex_decimation.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#include "Surfel.h"

namespace surftrack::testing {

/// A point's exact bits, so that "the same point" means bit-identical coordinates.
using Bits = std::array<std::uint64_t, 3>;
inline Bits bitsOf(const std::array<double, 3>& p) {
  Bits b;
  for (int i = 0; i < 3; ++i) std::memcpy(&b[std::size_t(i)], &p[std::size_t(i)], sizeof(double));
  return b;
}

/// A triangle as its corners' bits, rotated so that the least point comes first: a triangle and
/// its reversed twin (a, c, b) are then found by exact lookup.
using DirectedTriangle = std::array<Bits, 3>;
inline DirectedTriangle directed(Bits a, Bits b, Bits c) {
  DirectedTriangle t{a, b, c};
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

/// The grid edge of a surfel, whichever way it is oriented: its low voxel and axis.
inline std::array<int, 4> gridEdge(const Surfel& s) {
  const Voxel c = s.inside(), d = s.outside();
  const Voxel lo{std::min(c.x, d.x), std::min(c.y, d.y), std::min(c.z, d.z)};
  return {lo.x, lo.y, lo.z, c.x != d.x ? 0 : c.y != d.y ? 1 : 2};
}

}  // namespace surftrack::testing
