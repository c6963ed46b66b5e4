// The domain of an image and its physical placement (paper §2.1.1): a box [0, nx) x [0, ny) x
// [0, nz) of voxels of Z^3, and the affine map from voxel indices to physical coordinates.
// Part of the public API (docs/api.md), so it depends on nothing but the standard library.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "Voxel.h"

namespace surftrack {

/// Size of a domain [0, nx) x [0, ny) x [0, nz).
struct Dims {
  int nx = 0, ny = 0, nz = 0;
  constexpr int operator[](int axis) const { return axis == 0 ? nx : axis == 1 ? ny : nz; }
  constexpr bool contains(int x, int y, int z) const {
    return unsigned(x) < unsigned(nx) && unsigned(y) < unsigned(ny) && unsigned(z) < unsigned(nz);
  }
  constexpr bool contains(Voxel v) const { return contains(v.x, v.y, v.z); }
  constexpr std::size_t count() const { return std::size_t(nx) * std::size_t(ny) * std::size_t(nz); }
  constexpr bool empty() const { return nx <= 0 || ny <= 0 || nz <= 0; }
  friend constexpr bool operator==(const Dims&, const Dims&) = default;
};

/// Physical placement of voxel indices: x_phys = origin + direction * (spacing ⊙ index).
struct ImageGeometry {
  std::array<double, 3> spacing{1.0, 1.0, 1.0};
  std::array<double, 3> origin{0.0, 0.0, 0.0};
  std::array<std::array<double, 3>, 3> direction{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

  /// Maps a (continuous) index-space point to physical space.
  std::array<double, 3> toPhysical(const std::array<double, 3>& index) const {
    std::array<double, 3> p = origin;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p[r] += direction[r][c] * spacing[c] * index[c];
    return p;
  }

  /// Maps an index-space displacement to physical space: the linear part of toPhysical,
  /// toPhysical(i + offset) - toPhysical(i) without the rounding of the difference.
  std::array<double, 3> toPhysicalOffset(const std::array<double, 3>& offset) const {
    std::array<double, 3> p{0, 0, 0};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p[r] += direction[r][c] * spacing[c] * offset[c];
    return p;
  }

  /// The inverse of toPhysical: the continuous index of a physical point. Throws
  /// std::invalid_argument if direction * diag(spacing) is singular.
  std::array<double, 3> toIndex(const std::array<double, 3>& point) const {
    // Solve (direction * diag(spacing)) * index = point - origin with Cramer's rule.
    double m[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[r][c] = direction[r][c] * spacing[c];
    const double det = det3(m);
    if (!(std::abs(det) > 1e-300)) throw std::invalid_argument("the image geometry is singular");
    std::array<double, 3> b{};
    for (int r = 0; r < 3; ++r) b[r] = point[r] - origin[r];
    std::array<double, 3> x{};
    for (int c = 0; c < 3; ++c) {
      double mc[3][3];
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) mc[r][k] = k == c ? b[r] : m[r][k];
      x[c] = det3(mc) / det;
    }
    return x;
  }

  /// The determinant * diag(spacing): negative when the map from index space to
  /// physical space reverses orientation (a mirrored scanner frame), which the front door
  /// compensates so that triangle normals point outwards in physical space.
  double handedness() const {
    double m[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[r][c] = direction[r][c];
    return det3(m) * spacing[0] * spacing[1] * spacing[2];
  }

 private:
  static double det3(const double a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  }
};

}  // namespace surftrack
