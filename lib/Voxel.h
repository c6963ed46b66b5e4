// Voxels of Z^3 and the six unit directions (paper §2.1.1, §2.1.3).
#pragma once

#include <array>
#include <cstdint>
#include <cstdlib>
#include <functional>

namespace surftrack {

struct Voxel {
  int x = 0, y = 0, z = 0;

  constexpr int operator[](int axis) const { return axis == 0 ? x : axis == 1 ? y : z; }
  constexpr int& operator[](int axis) { return axis == 0 ? x : axis == 1 ? y : z; }
  friend constexpr Voxel operator+(Voxel a, Voxel b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Voxel operator-(Voxel a, Voxel b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Voxel operator-(Voxel a) { return {-a.x, -a.y, -a.z}; }
  friend constexpr Voxel operator*(int k, Voxel a) { return {k * a.x, k * a.y, k * a.z}; }
  friend constexpr bool operator==(Voxel a, Voxel b) = default;
};

/// One of the six unit vectors of Z^3: 0:+x 1:-x 2:+y 3:-y 4:+z 5:-z.
using Direction = std::uint8_t;

constexpr int axisOf(Direction d) { return d >> 1; }
constexpr int signOf(Direction d) { return (d & 1) ? -1 : 1; }
constexpr Direction opposite(Direction d) { return d ^ 1; }
constexpr Direction directionOf(int axis, int sign) { return Direction(2 * axis + (sign < 0 ? 1 : 0)); }

constexpr Voxel unitVector(Direction d) {
  Voxel v{};
  v[axisOf(d)] = signOf(d);
  return v;
}

/// The classical voxel adjacencies of Z^3 (paper §2.1.3): 6 = omega_3, 18 = eta_3 = mu_3, 26 = alpha_3.
constexpr bool areAdjacent(int adjacency, Voxel a, Voxel b) {
  Voxel d = a - b;
  int ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  int linf = ax > ay ? (ax > az ? ax : az) : (ay > az ? ay : az);
  int l1 = ax + ay + az;
  if (linf != 1) return false;
  return adjacency == 26 || (adjacency == 18 && l1 <= 2) || (adjacency == 6 && l1 == 1);
}

}  // namespace surftrack

template <>
struct std::hash<surftrack::Voxel> {
  std::size_t operator()(const surftrack::Voxel& v) const noexcept {
    std::uint64_t h = std::uint64_t(std::uint32_t(v.x)) * 0x9E3779B97F4A7C15ull;
    h ^= std::uint64_t(std::uint32_t(v.y)) * 0xC2B2AE3D27D4EB4Full + (h >> 29);
    h ^= std::uint64_t(std::uint32_t(v.z)) * 0x165667B19E3779F9ull + (h >> 31);
    return std::size_t(h ^ (h >> 32));
  }
};
