#include "Phantom.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace surftrack::cli {

Phantom makePhantom(int q, double noise, std::uint64_t randomSeed) {
  if (q < 16) throw std::invalid_argument("the phantom needs a side of at least 16 voxels");
  const double c = (q - 1) / 2.0, R = 0.4 * q, r = 0.12 * q;
  ImageGeometry geometry;
  geometry.origin = {-c, -c, -c};
  Phantom p;
  p.image = DenseImage<std::uint8_t>(Dims{q, q, q}, 0, geometry);
  auto clean = [&](int x, int y, int z) {
    const double dx = x - c, dy = y - c, dz = z - c;
    const double d = std::min({R - std::sqrt(dx * dx + dy * dy + dz * dz), std::hypot(dy, dz) - r,
                               std::hypot(dx, dz) - r, std::hypot(dx, dy) - r});
    return std::uint8_t(std::clamp(std::lround(128 + 20 * d), 0L, 255L));
  };
  std::vector<std::uint8_t> noisy(std::size_t(q) * q * q, 0);
  std::mt19937_64 rng(randomSeed);
  const std::uint64_t threshold = std::uint64_t(std::ldexp(noise, 63));  // P(u/2 < t) = noise
  for (int z = 0; z < q; ++z)
    for (int y = 0; y < q; ++y)
      for (int x = 0; x < q; ++x) {
        std::uint8_t value = clean(x, y, z);
        const std::uint64_t u = rng();
        if ((u >> 1) < threshold) {
          value = (u & 1) ? 255 : 0;
          noisy[p.image.index(x, y, z)] = 1;
          ++p.noisyVoxels;
        }
        p.image.at(x, y, z) = value;
      }
  // The seed: from (c, c + a, c + a), a = R / 2 (inside, clear of the cylinders), walk +x to
  // the crossing of the clean image; move one row up while a noisy voxel sits on the crossing.
  const int a = int(std::lround(R / 2));
  const int cx = int(std::lround(c));
  for (int dy = 0; dy < q / 4; ++dy) {
    const int y = cx + a + dy, z = cx + a;
    for (int x = cx; x + 1 < q; ++x) {
      if (clean(x, y, z) > p.iso && clean(x + 1, y, z) <= p.iso) {
        if (noisy[p.image.index(x, y, z)] || noisy[p.image.index(x + 1, y, z)]) break;
        p.seed = Surfel{Voxel{x, y, z}, 0};
        p.rayStart = Voxel{cx, y, z};
        return p;
      }
    }
  }
  throw std::runtime_error("could not place the phantom's seed");
}

}  // namespace surftrack::cli
