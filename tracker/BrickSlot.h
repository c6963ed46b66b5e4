// The layout the tracker shares between its image bricks, its surfel bitmaps and its step
// table: each 8x8x8 brick has 6 x 512 surfel slots, slot = n * 512 + x + 8y + 64z for the
// surfel (c, n) whose 1-voxel c sits at (x, y, z) in the brick.
#pragma once

#include <array>
#include <cstdint>

#include "Voxel.h"

namespace surftrack::brickslot {

constexpr int kVoxels = 512;         // voxels of a brick
constexpr int kSlots = 6 * kVoxels;  // surfel slots of a brick

constexpr int voxelOf(int x, int y, int z) { return x + 8 * y + 64 * z; }
constexpr int slotOf(int voxel, Direction n) { return n * kVoxels + voxel; }

/// Bit 2a (2a+1) is set when the voxel is on the low (high) face of the brick along axis a.
inline constexpr std::array<std::uint8_t, kVoxels> kBorderFlags = [] {
  std::array<std::uint8_t, kVoxels> flags{};
  for (int v = 0; v < kVoxels; ++v) {
    const int c[3] = {v & 7, (v >> 3) & 7, v >> 6};
    for (int a = 0; a < 3; ++a)
      flags[v] |= std::uint8_t((c[a] == 0) << (2 * a) | (c[a] == 7) << (2 * a + 1));
  }
  return flags;
}();

}  // namespace surftrack::brickslot
