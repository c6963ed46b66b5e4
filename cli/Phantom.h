// The demo's built-in phantom, after the paper's Figure 6 (c): a gray-level sphere minus three
// orthogonal cylinders through its centre, with salt-and-pepper noise (Figure 9's protocol).
#pragma once

#include <cstddef>
#include <cstdint>

#include "Image.h"
#include "Surfel.h"

namespace surftrack::cli {

struct Phantom {
  /// q^3 uint8 voxels, f = clamp(round(128 + 20 d), 0, 255) with d the signed distance (voxels,
  /// positive inside) to the solid "ball of radius R = 0.4 q minus the three cylinders of radius
  /// r = 0.12 q along the axes through the centre"; spacing 1, origin so that the centre of the
  /// ball is the physical origin.
  DenseImage<std::uint8_t> image;
  double iso = 127.5;
  /// The seed: the first crossing of level `iso` along +x from `rayStart` (inside the solid,
  /// between the cylinders) whose two voxels were left alone by the noise.
  Surfel seed;
  Voxel rayStart;
  std::size_t noisyVoxels = 0;
};

/// Deterministic for given arguments (its own 64-bit generator, no library distribution).
Phantom makePhantom(int q, double noise, std::uint64_t randomSeed = 20240601);

}  // namespace surftrack::cli
