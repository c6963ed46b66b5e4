// A lazily binarised, bricked cache of a binary image near the tracked surface. Tracking reads
// each voxel near the surface many times, in an order that jumps across z-slices of a dense
// volume (or calls an expensive predicate of an implicit one). Here each 8x8x8 brick is
// binarised once, on first use, together with a one-voxel apron, so that the 3x3x3
// neighbourhood a surfel's beta-neighbours depend on (Definition 38 only looks at voxels within
// ±1 of c) comes from a single brick in a few bit operations. Only bricks the surface passes
// through are ever created: memory and time stay proportional to the surface, not the volume.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "Hash.h"
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
};

template <class BinaryImage>
class BinaryBrickCache {
 public:
  explicit BinaryBrickCache(const BinaryImage& image) : image_(&image) { rehash(1024); }

  /// The 3x3x3 neighbourhood of voxel u.
  Neighbourhood neighbourhood(Voxel u) { return neighbourhood(brickOf(u), u); }

  /// The same, when u's brick index is already known.
  Neighbourhood neighbourhood(std::uint32_t brick, Voxel u) const {
    const Brick& b = bricks_[brick];
    const int lx = u.x & 7, ly = u.y & 7, lz = u.z & 7;  // apron coordinates of u - (1,1,1)
    std::uint32_t bits = 0;
    int shift = 0;
    for (int z = lz; z <= lz + 2; ++z)
      for (int y = ly; y <= ly + 2; ++y, shift += 3) bits |= ((b.rows[z][y] >> lx) & 7u) << shift;
    return Neighbourhood{u, bits};
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
    bricks_.push_back(binarise(key, bx, by, bz));
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
    Brick b{key, {}};
    const int x0 = 8 * bx - 1, y0 = 8 * by - 1, z0 = 8 * bz - 1;
    for (int z = 0; z < 10; ++z)
      for (int y = 0; y < 10; ++y) {
        if constexpr (requires { image_->row(x0, y0, z0, 10); }) {
          b.rows[z][y] = std::uint16_t(image_->row(x0, y0 + y, z0 + z, 10));
        } else {
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

  const BinaryImage* image_;
  std::vector<Brick> bricks_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  std::array<Recent, 64> recent_;
};

}  // namespace surftrack
