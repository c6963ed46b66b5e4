// A lazily binarised, bricked cache of a binary image near the tracked surface. Tracking reads
// each voxel near the surface many times, in an order that jumps across z-slices of a dense
// volume (or calls an expensive predicate of an implicit one). Here each 8x8x8 brick is
// binarised once, on first use, together with a one-voxel apron, so that the 3x3x3
// neighbourhood a surfel's beta-neighbours depend on (Definition 38 only looks at voxels within
// ±1 of c) comes from a single brick in a few bit operations. Only bricks the surface passes
// through are ever created: memory and time stay proportional to the surface, not the volume.
// A brick remembers its neighbours once looked up (linkedBrick), so the tracker hashes a brick
// position about once per brick face the surface crosses, not once per surfel.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "Hash.h"
#include "HugePages.h"
#include "Voxel.h"

namespace surftrack {

/// The 27 voxels u + {-1,0,1}^3 of a voxel u as bits: bit (dx+1) + 3(dy+1) + 9(dz+1).
/// It is itself a binary image (valid within ±1 of u), so the reference betaNeighbours runs on it.
struct Neighbourhood {
  Voxel center;
  std::uint32_t bits = 0;

  static constexpr int bitOf(Voxel d) { return (d.x + 1) + 3 * (d.y + 1) + 9 * (d.z + 1); }
  bool operator()(Voxel v) const { return (bits >> bitOf(v - center)) & 1u; }
  bool operator()(int x, int y, int z) const { return (*this)(Voxel{x, y, z}); }

  /// The configuration byte (cube::configurationAt) of the digital 3-cube with min corner
  /// center + offset, offset in {-1, 0}^3: its corners are the bits at bitOf(offset) +
  /// {0, 1, 3, 4, 9, 10, 12, 13}, so four shifts read it.
  std::uint8_t cubeConfiguration(Voxel offset) const {
    const std::uint32_t t = bits >> bitOf(offset);
    return std::uint8_t((t & 3u) | ((t >> 3) & 3u) << 2 | ((t >> 9) & 3u) << 4 | ((t >> 12) & 3u) << 6);
  }
};

/// The 3x3x3 neighbourhood as three 9-bit z-slices, dz = -1, 0, +1.
struct NeighbourhoodSlices {
  std::uint32_t bits[3];
};

template <class BinaryImage>
class BinaryBrickCache {
 public:
  explicit BinaryBrickCache(const BinaryImage& image) : image_(&image) { rehash(1024); }

  /// The 3x3x3 neighbourhood of voxel u.
  Neighbourhood neighbourhood(Voxel u) { return neighbourhood(brickOf(u), u); }

  /// The same, when u's brick index is already known.
  Neighbourhood neighbourhood(std::uint32_t brick, Voxel u) const {
    const NeighbourhoodSlices s = neighbourhoodSlices(brick, (u.x & 7) + 8 * (u.y & 7) + 64 * (u.z & 7));
    return Neighbourhood{u, s.bits[0] | s.bits[1] << 9 | s.bits[2] << 18};
  }

  /// The neighbourhood of the voxel with index x + 8y + 64z in the brick, as its three z-slices
  /// of 9 bits (Neighbourhood::bits = s0 | s1 << 9 | s2 << 18): three 64-bit loads, each
  /// bringing the apron rows y .. y+2 of one slice.
  NeighbourhoodSlices neighbourhoodSlices(std::uint32_t brick, int voxel) const {
    const Brick& b = bricks_[brick];
    const int lx = voxel & 7, ly = (voxel >> 3) & 7, lz = voxel >> 6;
    NeighbourhoodSlices s;
    for (int dz = 0; dz < 3; ++dz) {
      std::uint64_t w;
      std::memcpy(&w, &b.rows[lz + dz][ly], sizeof w);  // rows y, y+1, y+2 (and one spare)
      const std::uint64_t t = (w >> lx) & 0x0000000700070007ull;
      s.bits[dz] = std::uint32_t((t | t >> 13 | t >> 26) & 0x1FFu);
    }
    return s;
  }

  /// The brick next to brick b at offset (sx-1, sy-1, sz-1), selector s = sx + 3 sy + 9 sz in
  /// [0, 27) (13 is b itself); created on first use. Links are remembered both ways, so the
  /// tracker hashes a brick key about once per brick face it crosses.
  std::uint32_t linkedBrick(std::uint32_t b, int s) {
    std::uint32_t l = links_[b][s];
    if (l != kNoLink) return l;
    const Voxel o = brickOrigin(b);
    l = brickIndex((o.x >> 3) + s % 3 - 1, (o.y >> 3) + (s / 3) % 3 - 1, (o.z >> 3) + s / 9 - 1);
    links_[b][s] = l;
    links_[l][26 - s] = b;
    return l;
  }

  std::size_t brickCount() const { return bricks_.size(); }

  /// All bricks, ordered along a Z-order (Morton) curve of their positions: bricks near each
  /// other in space come near each other in the list.
  std::vector<std::uint32_t> bricksInSpaceOrder() const {
    auto spread = [](std::uint64_t v) {  // 21 bits to every third bit of 63
      v &= 0x1FFFFF;
      v = (v | v << 32) & 0x1F00000000FFFFull;
      v = (v | v << 16) & 0x1F0000FF0000FFull;
      v = (v | v << 8) & 0x100F00F00F00F00Full;
      v = (v | v << 4) & 0x10C30C30C30C30C3ull;
      v = (v | v << 2) & 0x1249249249249249ull;
      return v;
    };
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(bricks_.size());
    for (std::uint32_t b = 0; b < bricks_.size(); ++b) {
      const std::uint64_t key = bricks_[b].key;  // 21 bits per axis, x lowest
      keyed[b] = {spread(key) | spread(key >> 21) << 1 | spread(key >> 42) << 2, b};
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<std::uint32_t> order(bricks_.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
    return order;
  }

  /// The index of the brick that contains voxel v.
  std::uint32_t brickOf(Voxel v) { return brickIndex(v.x >> 3, v.y >> 3, v.z >> 3); }

  /// The index (in creation order) of the brick of voxels 8 (bx, by, bz) + [0, 8)^3, created
  /// and binarised on first use.
  std::uint32_t brickIndex(int bx, int by, int bz) {
    const std::uint64_t key = brickKey(bx, by, bz);
    // A direct-mapped memo of recent bricks: the 4x4x4 bricks around the traversal front.
    Recent& recent = recent_[(bx & 3) | (by & 3) << 2 | (bz & 3) << 4];
    if (recent.key == key) return recent.brick;
    std::size_t i = mix64(key) & mask_;
    for (; slots_[i].key != kEmpty; i = (i + 1) & mask_)
      if (slots_[i].key == key) return remember(recent, key, slots_[i].brick);
    if (2 * (bricks_.size() + 1) > slots_.size()) {
      rehash(2 * slots_.size());
      return brickIndex(bx, by, bz);
    }
    slots_[i] = {key, std::uint32_t(bricks_.size())};
    if (bricks_.size() == bricks_.capacity()) {
      reserveHugePages(bricks_, 2 * bricks_.size() + 64);
      reserveHugePages(links_, bricks_.capacity());
    }
    bricks_.push_back(binarise(key, bx, by, bz));
    links_.emplace_back().fill(kNoLink);
    links_.back()[13] = std::uint32_t(bricks_.size() - 1);
    return remember(recent, key, std::uint32_t(bricks_.size() - 1));
  }

  /// The voxel 8 (bx, by, bz) of brick b.
  Voxel brickOrigin(std::uint32_t b) const {
    const std::uint64_t key = bricks_[b].key;
    auto g = [](std::uint64_t v) { return 8 * (int(v & 0x1FFFFFu) - (1 << 20)); };
    return Voxel{g(key), g(key >> 21), g(key >> 42)};
  }

 private:
  // Voxels 8b-1 .. 8b+8 on each axis: rows[z][y] bit x is voxel (8bx-1+x, 8by-1+y, 8bz-1+z).
  struct Brick {
    std::uint64_t key;
    std::array<std::array<std::uint16_t, 10>, 10> rows;
    std::uint16_t spare[3];  // read, never used, by neighbourhoodSlices' last 64-bit load
  };
  struct Slot {
    std::uint64_t key;
    std::uint32_t brick;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  struct Recent {
    std::uint64_t key = kEmpty;
    std::uint32_t brick = 0;
  };

  static std::uint64_t brickKey(int bx, int by, int bz) {
    auto f = [](int v) { return std::uint64_t(v + (1 << 20)) & 0x1FFFFFu; };
    return (f(bz) << 42) | (f(by) << 21) | f(bx);
  }

  static std::uint32_t remember(Recent& recent, std::uint64_t key, std::uint32_t b) {
    recent = {key, b};
    return b;
  }

  Brick binarise(std::uint64_t key, int bx, int by, int bz) const {
    Brick b{key, {}, {}};
    const int x0 = 8 * bx - 1, y0 = 8 * by - 1, z0 = 8 * bz - 1;
    if constexpr (requires { image_->rows(x0, y0, z0, 10, 10, 10, &b.rows[0][0]); }) {
      image_->rows(x0, y0, z0, 10, 10, 10, &b.rows[0][0]);
    } else {
      for (int z = 0; z < 10; ++z)
        for (int y = 0; y < 10; ++y) {
          std::uint16_t row = 0;
          for (int x = 0; x < 10; ++x) row |= std::uint16_t((*image_)(x0 + x, y0 + y, z0 + z) << x);
          b.rows[z][y] = row;
        }
    }
    return b;
  }

  void rehash(std::size_t capacity) {
    slots_.assign(capacity, Slot{kEmpty, 0});
    mask_ = capacity - 1;
    for (std::uint32_t b = 0; b < bricks_.size(); ++b) {
      std::size_t i = mix64(bricks_[b].key) & mask_;
      while (slots_[i].key != kEmpty) i = (i + 1) & mask_;
      slots_[i] = {bricks_[b].key, b};
    }
  }

  static constexpr std::uint32_t kNoLink = ~std::uint32_t(0);

  const BinaryImage* image_;
  std::vector<Brick> bricks_;
  std::vector<std::array<std::uint32_t, 27>> links_;  // linkedBrick, kNoLink until first use
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  std::array<Recent, 64> recent_;
};

}  // namespace surftrack
