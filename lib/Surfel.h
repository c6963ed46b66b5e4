// Surfels (paper §2.1.4): an ordered pair (c, d) of 6-adjacent voxels, c a 1-voxel and
// d a 0-voxel. Stored as c plus the direction of the normal n = d - c.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>

#include "Voxel.h"

namespace surftrack {

struct Surfel {
  Voxel c;          ///< the 1-voxel (inside)
  Direction n = 0;  ///< direction from c to d

  constexpr Voxel inside() const { return c; }
  constexpr Voxel outside() const { return c + unitVector(n); }

  friend constexpr bool operator==(const Surfel&, const Surfel&) = default;

  /// Coordinates must lie in [-2^19, 2^19): the key packs 20 bits per coordinate + 3 bits.
  static constexpr int kCoordinateLimit = 1 << 19;

  /// A 63-bit key, unique per surfel, ordered so that surfels of nearby voxels get nearby keys
  /// in their low bits (the direction is the lowest field).
  constexpr std::uint64_t key() const {
    auto f = [](int v) { return std::uint64_t(v + kCoordinateLimit) & 0xFFFFFu; };
    return (f(c.z) << 43) | (f(c.y) << 23) | (f(c.x) << 3) | n;
  }
  static constexpr Surfel fromKey(std::uint64_t k) {
    auto g = [](std::uint64_t v) { return int(v & 0xFFFFFu) - kCoordinateLimit; };
    return Surfel{Voxel{g(k >> 3), g(k >> 23), g(k >> 43)}, Direction(k & 7u)};
  }
};

inline std::ostream& operator<<(std::ostream& os, const Voxel& v) {
  return os << '(' << v.x << ',' << v.y << ',' << v.z << ')';
}
inline std::ostream& operator<<(std::ostream& os, const Surfel& s) {
  return os << "surfel[c=" << s.inside() << " d=" << s.outside() << ']';
}

}  // namespace surftrack

template <>
struct std::hash<surftrack::Surfel> {
  std::size_t operator()(const surftrack::Surfel& s) const noexcept {
    std::uint64_t h = s.key() * 0x9E3779B97F4A7C15ull;
    return std::size_t(h ^ (h >> 31));
  }
};
