// Finding a seed surfel for the tracker, two rules:
//  - seedAlongRay: walk a ray of voxels from a start voxel and return the first boundary surfel
//    it crosses (a 1-voxel followed by a 0-voxel, or a 0-voxel followed by a 1-voxel). The
//    walk stops one voxel outside the domain.
//  - nearestBoundarySurfel: the boundary surfel whose segment midpoint (c + d) / 2 is nearest a
//    point, in physical distance: what people mean by "the surface near here", and what VTK's
//    closest-point connectivity region gives.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "BinaryBricks.h"
#include "Geometry.h"
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

struct NearestSurfel {
  Surfel surfel;
  double distance = 0;  ///< physical distance from the point to the surfel's midpoint
};

/// The boundary surfel (c in the domain, d its 0-neighbour, possibly outside the domain) whose
/// midpoint is nearest `point` (index coordinates) in the physical metric of `geometry`; ties go
/// to the smallest Surfel::key, so the answer does not depend on the search order. The search
/// reads 8x8x8 bricks (binariseBrick) in rings of growing Chebyshev distance around the point's
/// brick and stops as soon as no unread brick can hold a nearer midpoint, or beyond
/// `maxDistance` (physical); a brick whose every midpoint is farther than the best found so
/// far or than maxDistance is not read: its cost grows with the distance to the surface, not
/// the volume, and is at most about the ball of radius maxDistance.
/// std::nullopt if there is no boundary surfel within maxDistance.
template <class BinaryImage>
std::optional<NearestSurfel> nearestBoundarySurfel(
    const BinaryImage& image, const std::array<double, 3>& point, const ImageGeometry& geometry,
    double maxDistance = std::numeric_limits<double>::infinity()) {
  const Dims& dims = image.dims();
  const double minSpacing = std::min({geometry.spacing[0], geometry.spacing[1], geometry.spacing[2]});
  const std::array<double, 3> target = geometry.toPhysical(point);
  // The bricks that hold voxels of the domain, and the point's brick clamped into them.
  const int last[3] = {(dims.nx - 1) >> 3, (dims.ny - 1) >> 3, (dims.nz - 1) >> 3};
  int centre[3];
  for (int a = 0; a < 3; ++a)
    centre[a] = int(std::clamp(std::floor(point[a] / 8.0), 0.0, double(last[a])));
  const int maxRing = std::max({centre[0], last[0] - centre[0], centre[1], last[1] - centre[1],
                                centre[2], last[2] - centre[2]});
  std::optional<NearestSurfel> best;
  auto consider = [&](const Surfel& s) {
    const Voxel c = s.inside(), d = s.outside();
    const std::array<double, 3> m =
        geometry.toPhysical({(c.x + d.x) / 2.0, (c.y + d.y) / 2.0, (c.z + d.z) / 2.0});
    const double dist = std::hypot(m[0] - target[0], m[1] - target[1], m[2] - target[2]);
    if (dist > maxDistance) return;
    if (!best || dist < best->distance || (dist == best->distance && s.key() < best->surfel.key()))
      best = NearestSurfel{s, dist};
  };
  auto scanBrick = [&](int bx, int by, int bz) {
    const BinaryBricks::Brick brick = binariseBrick(image, bx, by, bz);
    auto at = [&](int x, int y, int z) { return (brick.rows[z + 1][y + 1] >> (x + 1)) & 1u; };
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          const Voxel c{8 * bx + x, 8 * by + y, 8 * bz + z};
          if (!dims.contains(c) || !at(x, y, z)) continue;
          for (Direction n = 0; n < 6; ++n) {
            const Voxel u = unitVector(n);
            if (!at(x + u.x, y + u.y, z + u.z)) consider(Surfel{c, n});
          }
        }
  };
  // A brick of ring k >= 1 lies (k - 1) * 8 voxels (max-norm) from the centre brick, which the
  // point is `outside` voxels away from (0 inside the domain); midpoints stand up to half a
  // voxel off their brick. With an orthonormal direction, a physical distance is at least
  // minSpacing times the max-norm one: a lower bound for every midpoint of ring k.
  double outside = 0;
  for (int a = 0; a < 3; ++a)
    outside = std::max({outside, 8.0 * centre[a] - point[a], point[a] - (8.0 * centre[a] + 8.0)});
  // The same bound for one brick: the index-space distance from the point to the box of its
  // midpoints, [8b - 0.5, 8b + 7.5] on each axis, times minSpacing — shrunk by a relative 1e-9,
  // so that rounding in the physical distances never skips a brick holding the nearest.
  auto brickLowerBound = [&](int bx, int by, int bz) {
    const int b[3] = {bx, by, bz};
    double squared = 0;
    for (int a = 0; a < 3; ++a) {
      const double gap = std::max({0.0, 8.0 * b[a] - 0.5 - point[a], point[a] - (8.0 * b[a] + 7.5)});
      squared += gap * gap;
    }
    return std::sqrt(squared) * minSpacing * (1 - 1e-9);
  };
  for (int k = 0; k <= maxRing; ++k) {
    const double lowerBound = std::max(0.0, (k - 1) * 8.0 - outside - 0.5) * minSpacing;
    if (lowerBound > maxDistance || (best && best->distance < lowerBound)) break;
    for (int bz = std::max(0, centre[2] - k); bz <= std::min(last[2], centre[2] + k); ++bz)
      for (int by = std::max(0, centre[1] - k); by <= std::min(last[1], centre[1] + k); ++by)
        for (int bx = std::max(0, centre[0] - k); bx <= std::min(last[0], centre[0] + k); ++bx) {
          if (std::max({std::abs(bx - centre[0]), std::abs(by - centre[1]), std::abs(bz - centre[2])}) != k) continue;
          const double brickBound = brickLowerBound(bx, by, bz);
          if (brickBound > maxDistance || (best && best->distance < brickBound)) continue;
          scanBrick(bx, by, bz);
        }
  }
  return best;
}

}  // namespace surftrack
