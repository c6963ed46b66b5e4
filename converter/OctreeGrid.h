// The octree grid of one segment in Neuroglancer's multi-resolution mesh format (docs/cli.md,
// "Neuroglancer output"): level g's cells are boxes of chunk * 2^g from the origin, in the
// "stored model" coordinates. Level k's mesh is cut on level k-1's planes (Neuroglancer draws
// the eight octants of a level-k cell separately, each where no finer cell is drawn), level 0's
// on its own; the rule below says which cell a triangle belongs to, the same rule Neuroglancer
// applies to a triangle that touches a plane (the lower octant along each axis).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace surftrack {

struct OctreeGrid {
  std::array<double, 3> origin{};         ///< grid_origin
  std::array<double, 3> chunk{1, 1, 1};   ///< chunk_shape: the cells of level 0
  int lods = 1;                           ///< levels of detail, 0 (finest) .. lods - 1

  /// The coordinate `t` along `axis` in units of level g's cells from the origin (exact for a
  /// point on a plane when origin and chunk are multiples of a power of two, as chosen).
  double cells(int axis, double t, int level) const {
    return (t - origin[axis]) / (chunk[axis] * std::ldexp(1.0, level));
  }
  /// Plane n of level g along `axis`.
  double plane(int axis, std::int64_t n, int level) const {
    return origin[axis] + double(n) * chunk[axis] * std::ldexp(1.0, level);
  }
  /// Whether `t` lies on a plane of level g along `axis`.
  bool onPlane(int axis, double t, int level) const {
    const double u = cells(axis, t, level);
    return u == std::floor(u);
  }

  /// The cell of level g along `axis` of a triangle whose coordinates along it span
  /// [low, high] (in cells of level g): the lowest n with high <= n + 1; the triangle lies in
  /// it when low >= n (the cut guarantees it). A triangle lying on plane n belongs to cell n - 1.
  static std::int64_t cellOfSpan(double high) { return std::int64_t(std::ceil(high)) - 1; }
};

}  // namespace surftrack
