// The project's one generator of test images, shared by bench/, cli/ (the demo) and tests/:
//  - Ball: the digital ball |v - c|^2 <= r2 (integer centre), a predicate for ImplicitImage, and
//    paintBall, which paints it into a DenseImage;
//  - gray phantoms on q^3 uint8 voxels, f = clamp(round(128 + 20 d), 0, 255) with d the signed
//    distance (voxels, positive inside) to a solid centred at c = ((q-1)/2, (q-1)/2, (q-1)/2),
//    level 127.5, and salt-and-pepper noise from a fixed seed (docs/figure9.md, 'Protocol'):
//    makeNoisySphere (the ball of radius R = 0.4 q, paper Figure 9) with protocolSeed, and
//    makeSphereMinusCylinders (the demo's phantom after paper Figure 6 (c)).
// The images are part of what the benchmarks and the demo report: any change to a formula or to
// the order of the random draws changes the figures in docs/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "Image.h"
#include "Surfel.h"

namespace surftrack {

/// The digital ball of the voxels v with |v - centre|^2 <= radius2, exact in 64 bits.
struct Ball {
  Voxel centre;
  std::int64_t radius2 = 0;  ///< the squared radius (need not be a square)

  static Ball ofRadius(Voxel centre, int radius) { return Ball{centre, std::int64_t(radius) * radius}; }

  bool operator()(int x, int y, int z) const {
    const std::int64_t dx = x - centre.x, dy = y - centre.y, dz = z - centre.z;
    return dx * dx + dy * dy + dz * dz <= radius2;
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
};

/// Sets the voxels of `ball` that lie in the domain of `image` to `value`.
template <class T>
void paintBall(DenseImage<T>& image, const Ball& ball, T value) {
  const Dims& d = image.dims();
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x)
        if (ball(x, y, z)) image.at(x, y, z) = value;
}

/// The level of the gray phantoms: their binary image is f > 127.5.
inline constexpr double kPhantomIsoValue = 127.5;
/// The seed of the noise of the benchmarks and of the demo.
inline constexpr std::uint64_t kDefaultNoiseSeed = 20240601;

/// A gray phantom: the image, where noise set it, and the solid's centre and radius.
struct NoisyPhantom {
  int q = 0;
  double centre = 0;                 ///< each coordinate of c, (q - 1) / 2
  double radius = 0;                 ///< the ball's radius R = 0.4 q
  double iso = kPhantomIsoValue;     ///< the level of the binary image
  DenseImage<std::uint8_t> image;    ///< the gray image, noise included
  std::vector<std::uint8_t> hit;     ///< 1 where noise set the voxel (buffer order); empty if p = 0

  /// True when the noise process set voxel v (even to the value it already had). Voxels outside
  /// the domain are never changed.
  bool changed(Voxel v) const {
    return !hit.empty() && image.dims().contains(v) && hit[image.index(v.x, v.y, v.z)];
  }
  /// The binary image f > iso.
  ThresholdImage<std::uint8_t> binary() const { return ThresholdImage<std::uint8_t>(image, iso); }
};

/// The gray value at signed distance d (voxels, positive inside): clamp(round(128 + 20 d), 0, 255).
inline std::uint8_t grayAtDistance(double d) {
  return std::uint8_t(std::clamp(std::round(128.0 + 20.0 * d), 0.0, 255.0));
}

/// Signed distance to the ball of radius R centred at the origin, at offset (dx, dy, dz).
inline double ballDistance(double R, double dx, double dy, double dz) {
  return R - std::sqrt(dx * dx + dy * dy + dz * dz);
}

/// Salt-and-pepper noise of probability p: the voxels are visited in buffer order (x fastest);
/// for each one a 64-bit word r is drawn from std::mt19937_64(seed); the voxel is hit when
/// (r >> 11) * 2^-53 < p and is then set to 255 if r is odd, to 0 if r is even. p = 0 draws
/// nothing. Returns the hit mask (1 where hit, buffer order), empty if p = 0.
inline std::vector<std::uint8_t> addSaltAndPepper(DenseImage<std::uint8_t>& image, double noise,
                                                  std::uint64_t seed) {
  if (!(noise >= 0.0 && noise <= 1.0)) throw std::invalid_argument("the noise must be in [0, 1]");
  std::vector<std::uint8_t> hit;
  if (noise == 0) return hit;
  std::uint8_t* data = image.data().data();
  const std::size_t n = image.data().size();
  hit.assign(n, 0);
  std::mt19937_64 rng(seed);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t r = rng();
    if (double(r >> 11) * 0x1p-53 < noise) {
      data[i] = (r & 1) ? 255 : 0;
      hit[i] = 1;
    }
  }
  return hit;
}

/// The gray phantom of the solid whose signed distance at offset (dx, dy, dz) from c is
/// distance(dx, dy, dz), with salt-and-pepper noise of probability `noise` (addSaltAndPepper).
template <class SignedDistance>
NoisyPhantom makeNoisyPhantom(int q, double noise, std::uint64_t seed, SignedDistance distance) {
  if (q <= 0) throw std::invalid_argument("the phantom's side must be positive");
  NoisyPhantom p;
  p.q = q;
  p.centre = (q - 1) / 2.0;
  p.radius = 0.4 * q;
  p.image = DenseImage<std::uint8_t>(Dims{q, q, q});
  const double c = p.centre;
  for (int z = 0; z < q; ++z)
    for (int y = 0; y < q; ++y) {
      std::uint8_t* row = &p.image.at(0, y, z);
      for (int x = 0; x < q; ++x) row[x] = grayAtDistance(distance(x - c, y - c, z - c));
    }
  p.hit = addSaltAndPepper(p.image, noise, seed);
  return p;
}

/// The noisy sphere of the Figure 9 protocol (docs/figure9.md): the ball of radius R = 0.4 q.
inline NoisyPhantom makeNoisySphere(int q, double noise, std::uint64_t seed = kDefaultNoiseSeed) {
  const double R = 0.4 * q;
  return makeNoisyPhantom(q, noise, seed, [R](double dx, double dy, double dz) { return ballDistance(R, dx, dy, dz); });
}

/// The protocol's seed: among the boundary surfels of the binary image on the +x ray from the
/// centre (the row y = z = q / 2, which is c rounded up for even q, past x = c), the one whose
/// midpoint is nearest to distance R from c, among those whose two voxels noise did not hit.
/// With strong noise both voxels of the sphere's crossing of that row may have been hit (about
/// one image in ten at 5 %); the search then moves to the parallel rows y = q/2 + 1, q/2 - 1,
/// q/2 + 2, ... (z = q / 2), and takes the first row that has such a surfel.
/// Throws std::runtime_error if there is none within q / 4 rows.
inline Surfel protocolSeed(const NoisyPhantom& s) {
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

/// The demo's phantom, after paper Figure 6 (c): the ball of radius R = 0.4 q minus the three
/// cylinders of radius r = 0.12 q along the axes through its centre, with salt-and-pepper noise;
/// spacing 1 and the origin at -c, so that the centre of the ball is the physical origin.
struct SphereMinusCylinders : NoisyPhantom {
  /// The seed: the first crossing of level `iso` along +x from `rayStart` (inside the solid,
  /// between the cylinders) whose two voxels were left alone by the noise.
  Surfel seed;
  Voxel rayStart;
};

/// Deterministic for given arguments (q >= 16). Throws std::runtime_error if noise leaves no seed.
inline SphereMinusCylinders makeSphereMinusCylinders(int q, double noise, std::uint64_t seed = kDefaultNoiseSeed) {
  if (q < 16) throw std::invalid_argument("the phantom needs a side of at least 16 voxels");
  const double R = 0.4 * q, r = 0.12 * q;
  auto distance = [R, r](double dx, double dy, double dz) {
    return std::min({ballDistance(R, dx, dy, dz), std::hypot(dy, dz) - r, std::hypot(dx, dz) - r,
                     std::hypot(dx, dy) - r});
  };
  SphereMinusCylinders p{makeNoisyPhantom(q, noise, seed, distance), {}, {}};
  const double c = p.centre;
  p.image.geometry().origin = {-c, -c, -c};
  auto clean = [&](int x, int y, int z) { return grayAtDistance(distance(x - c, y - c, z - c)); };
  // The seed: from (c, c + a, c + a), a = R / 2 (inside, clear of the cylinders), walk +x to
  // the crossing of the clean image; move one row up while a noisy voxel sits on the crossing.
  const int a = int(std::lround(R / 2));
  const int cx = int(std::lround(c));
  for (int dy = 0; dy < q / 4; ++dy) {
    const int y = cx + a + dy, z = cx + a;
    for (int x = cx; x + 1 < q; ++x) {
      if (clean(x, y, z) > p.iso && clean(x + 1, y, z) <= p.iso) {
        if (p.changed({x, y, z}) || p.changed({x + 1, y, z})) break;
        p.seed = Surfel{Voxel{x, y, z}, 0};
        p.rayStart = Voxel{cx, y, z};
        return p;
      }
    }
  }
  throw std::runtime_error("could not place the phantom's seed");
}

}  // namespace surftrack
