// A lazily binarised, bricked cache of a binary image near the tracked surface. Tracking reads
// each voxel near the surface many times, in an order that jumps across z-slices of a dense
// volume (or calls an expensive predicate of an implicit one). Here each 8x8x8 brick is
// binarised once, on first use, into BinaryBricks (with its one-voxel apron). Only bricks the
// surface passes through are ever created: memory and time stay proportional to the surface,
// not the volume. A brick remembers its neighbours once looked up (linkedBrick), so the
// tracker hashes a brick position about once per brick face the surface crosses, not once per
// surfel.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "BinaryBricks.h"
#include "HugePages.h"
#include "Voxel.h"

namespace surftrack {

template <class BinaryImage>
class BinaryBrickCache {
 public:
  explicit BinaryBrickCache(const BinaryImage& image) : image_(&image) {}

  /// The bricks binarised so far.
  const BinaryBricks& bricks() const { return bricks_; }
  /// Hands the bricks over (to the surface graph); the cache is empty afterwards.
  BinaryBricks release() && { return std::move(bricks_); }

  /// BinaryBricks::neighbourhoodSlices, for forEachBetaNeighbour (which tests drive with a
  /// fixed neighbourhood instead of a cache).
  NeighbourhoodSlices neighbourhoodSlices(std::uint32_t brick, int voxel) const {
    return bricks_.neighbourhoodSlices(brick, voxel);
  }

  /// The brick next to brick b at offset (sx-1, sy-1, sz-1), selector s = sx + 3 sy + 9 sz in
  /// [0, 27) (13 is b itself); created on first use. Links are remembered both ways, so the
  /// tracker hashes a brick key about once per brick face it crosses.
  std::uint32_t linkedBrick(std::uint32_t b, int s) {
    std::uint32_t l = links_[b][s];
    if (l != kNoLink) return l;
    const Voxel o = bricks_.brickOrigin(b);
    l = brickIndex((o.x >> 3) + s % 3 - 1, (o.y >> 3) + (s / 3) % 3 - 1, (o.z >> 3) + s / 9 - 1);
    links_[b][s] = l;
    links_[l][26 - s] = b;
    return l;
  }

  /// linkedBrick(b, s) for a link made before: reads only, so it may be called from several
  /// threads at once (the tracker's second pass follows the links of its first).
  std::uint32_t knownLink(std::uint32_t b, int s) const { return links_[b][s]; }

  /// The index of the brick that contains voxel v.
  std::uint32_t brickOf(Voxel v) { return brickIndex(v.x >> 3, v.y >> 3, v.z >> 3); }

  /// The index (in creation order) of the brick of voxels 8 (bx, by, bz) + [0, 8)^3, created
  /// and binarised on first use.
  std::uint32_t brickIndex(int bx, int by, int bz) {
    const std::uint64_t key = BinaryBricks::keyOf(bx, by, bz);
    // A direct-mapped memo of recent bricks: the 4x4x4 bricks around the traversal front.
    Recent& recent = recent_[(bx & 3) | (by & 3) << 2 | (bz & 3) << 4];
    if (recent.key == key) return recent.brick;
    std::uint32_t b = bricks_.find(key);
    if (b == BinaryBricks::kMissing) {
      b = bricks_.insert(binariseBrick(*image_, bx, by, bz));
      if (links_.size() == links_.capacity()) reserveHugePages(links_, 2 * links_.size() + 64);
      links_.emplace_back().fill(kNoLink);
      links_.back()[13] = b;
    }
    recent = {key, b};
    return b;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  static constexpr std::uint32_t kNoLink = ~std::uint32_t(0);
  struct Recent {
    std::uint64_t key = kEmpty;
    std::uint32_t brick = 0;
  };

  const BinaryImage* image_;
  BinaryBricks bricks_;
  std::vector<std::array<std::uint32_t, 27>> links_;  // linkedBrick, kNoLink until first use
  std::array<Recent, 64> recent_;
};

}  // namespace surftrack
