// The test image of the Figure 9 protocol (paper §5.3; docs/figure9.md, 'Protocol'): a
// gray-level sphere with salt-and-pepper noise, and the protocol's seed surfel. Shared by the
// scanning and Figure 9 benchmarks.
//  - unsigned 8-bit, side q, centre c = ((q-1)/2, (q-1)/2, (q-1)/2), R = 0.4 q,
//    f(x) = clamp(round(128 + 20 (R - |x - c|)), 0, 255), iso-value s = 127.5;
//  - noise p: the voxels are visited in buffer order (x fastest); for each one a 64-bit word r
//    is drawn from std::mt19937_64(seed); the voxel is hit when (r >> 11) * 2^-53 < p and is
//    then set to 255 if r is odd, to 0 if r is even. p = 0 draws nothing.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "Image.h"
#include "Surfel.h"

namespace surftrack::bench {

inline constexpr double kSphereIsoValue = 127.5;
inline constexpr std::uint64_t kDefaultNoiseSeed = 20240601;

struct NoisySphere {
  int q = 0;
  double radius = 0;                 ///< R = 0.4 q
  double centre = 0;                 ///< each coordinate of c, (q - 1) / 2
  DenseImage<std::uint8_t> image;    ///< the gray image, noise included
  std::vector<std::uint8_t> hit;     ///< 1 where noise set the voxel (buffer order); empty if p = 0

  /// True when the noise process set voxel v (even to the value it already had). Voxels outside
  /// the domain are never changed.
  bool changed(Voxel v) const {
    return !hit.empty() && image.dims().contains(v) && hit[image.index(v.x, v.y, v.z)];
  }
  /// The binary image of the protocol, f > 127.5.
  ThresholdImage<std::uint8_t> binary() const { return ThresholdImage<std::uint8_t>(image, kSphereIsoValue); }
};

inline NoisySphere makeNoisySphere(int q, double noise, std::uint64_t seed = kDefaultNoiseSeed) {
  if (q <= 0) throw std::invalid_argument("makeNoisySphere: q must be positive");
  if (!(noise >= 0.0 && noise <= 1.0)) throw std::invalid_argument("makeNoisySphere: noise must be in [0, 1]");
  NoisySphere s;
  s.q = q;
  s.radius = 0.4 * q;
  s.centre = (q - 1) / 2.0;
  s.image = DenseImage<std::uint8_t>(Dims{q, q, q});
  std::uint8_t* data = s.image.data().data();
  // The value only depends on (y - c)^2 + (z - c)^2 per row: one square root per voxel remains.
  for (int z = 0; z < q; ++z)
    for (int y = 0; y < q; ++y) {
      const double dyz = (y - s.centre) * (y - s.centre) + (z - s.centre) * (z - s.centre);
      std::uint8_t* row = data + s.image.index(0, y, z);
      for (int x = 0; x < q; ++x) {
        const double d = std::sqrt((x - s.centre) * (x - s.centre) + dyz);
        row[x] = std::uint8_t(std::clamp(std::round(128.0 + 20.0 * (s.radius - d)), 0.0, 255.0));
      }
    }
  if (noise > 0) {
    s.hit.assign(s.image.dims().count(), 0);
    std::mt19937_64 rng(seed);
    const std::size_t n = s.hit.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t r = rng();
      if (double(r >> 11) * 0x1p-53 < noise) {
        data[i] = (r & 1) ? 255 : 0;
        s.hit[i] = 1;
      }
    }
  }
  return s;
}

/// The protocol's seed: among the boundary surfels of the binary image on the +x ray from the
/// centre (the row y = z = q / 2, which is c rounded up for even q, past x = c), the one whose
/// midpoint is nearest to distance R from c, among those whose two voxels noise did not hit.
/// With strong noise both voxels of the sphere's crossing of that row may have been hit (about
/// one image in ten at 5 %); the search then moves to the parallel rows y = q/2 + 1, q/2 - 1,
/// q/2 + 2, ... (z = q / 2), and takes the first row that has such a surfel.
/// Throws std::runtime_error if there is none within q / 4 rows.
inline Surfel protocolSeed(const NoisySphere& s) {
  const auto image = s.binary();
  const int q = s.q, z = q / 2;
  for (int k = 0; k <= 2 * (q / 4); ++k) {
    const int y = q / 2 + ((k & 1) ? (k + 1) / 2 : -(k / 2));  // q/2, +1, -1, +2, -2, ...
    if (y < 0 || y >= q) continue;
    const double dyz = (y - s.centre) * (y - s.centre) + (z - s.centre) * (z - s.centre);
    double best = std::numeric_limits<double>::infinity();
    Surfel seed{};
    // Surfels between voxels x and x + 1 with x + 0.5 > c (x = q is outside the domain, 0).
    for (int x = int(std::floor(s.centre)); x < q; ++x) {
      const Voxel a{x, y, z}, b{x + 1, y, z};
      const bool va = image(a), vb = image(b);
      if (va == vb || s.changed(a) || s.changed(b) || x + 0.5 <= s.centre) continue;
      const double mx = x + 0.5 - s.centre;
      const double distance = std::abs(std::sqrt(mx * mx + dyz) - s.radius);
      if (distance < best) {
        best = distance;
        seed = va ? Surfel{a, 0} : Surfel{b, 1};
      }
    }
    if (best < std::numeric_limits<double>::infinity()) return seed;
  }
  throw std::runtime_error("protocolSeed: no boundary surfel untouched by noise near the +x ray");
}

/// As above; q must be the side of the sphere (kept for callers that pass it explicitly).
inline Surfel protocolSeed(const NoisySphere& s, int q) {
  if (q != s.q) throw std::invalid_argument("protocolSeed: q does not match the sphere");
  return protocolSeed(s);
}

}  // namespace surftrack::bench
