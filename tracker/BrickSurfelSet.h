// The tracker's visited structure: for each brick of the image cache (8x8x8 voxels), one bit
// per surfel slot (BrickSlot.h) — 6 x 512 bits, 384 bytes — so marking a surfel touches the same few
// cache lines as reading its neighbourhood. Once the traversal is over, a prefix count per
// 64-bit word turns every bit into a dense vertex index (brick order, then bit order) in O(1),
// with no hashing of surfels at all.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include "BrickSlot.h"
#include "HugePages.h"

namespace surftrack {

class BrickSurfelSet {
 public:
  static constexpr int kWords = brickslot::kSlots / 64;

  /// Makes room for bricks [0, count).
  void resize(std::size_t count) {
    if (count > words_.size()) resizeHugePages(words_, count);
  }

  /// Marks the surfel of a brick made room for; false if it was already marked. Without a
  /// branch: the tracker calls it on every arc, and whether a surfel is new is unpredictable.
  bool insert(std::uint32_t brick, int bit) {
    std::uint64_t& w = words_[brick][bit >> 6];
    const std::uint64_t m = std::uint64_t(1) << (bit & 63);
    const bool fresh = !(w & m);
    w |= m;
    return fresh;
  }

  /// Freezes the set and numbers its surfels, brick by brick in the given order (every brick
  /// that holds a surfel must appear once); returns their number.
  std::uint32_t number(std::vector<std::uint32_t> brickOrder) {
    resizeHugePages(prefix_, words_.size());
    order_ = std::move(brickOrder);
    std::uint32_t count = 0;
    for (std::uint32_t b : order_)
      for (int w = 0; w < kWords; ++w) {
        prefix_[b][w] = count;
        count += std::uint32_t(std::popcount(words_[b][w]));
      }
    return count;
  }

  /// The vertex index of a marked surfel (after number()).
  std::uint32_t index(std::uint32_t brick, int bit) const {
    const std::uint64_t below = (std::uint64_t(1) << (bit & 63)) - 1;
    return prefix_[brick][bit >> 6] + std::uint32_t(std::popcount(words_[brick][bit >> 6] & below));
  }

  /// The bricks in numbering order (after number()).
  const std::vector<std::uint32_t>& order() const { return order_; }
  /// The vertex index of the first marked surfel of a brick (after number()).
  std::uint32_t firstIndex(std::uint32_t brick) const { return prefix_[brick][0]; }

  /// Calls f(brick, bit) for every marked surfel of one brick, in index order.
  template <class F>
  void forEachIn(std::uint32_t b, F&& f) const {
    for (int w = 0; w < kWords; ++w)
      for (std::uint64_t bits = words_[b][w]; bits; bits &= bits - 1) f(b, w * 64 + std::countr_zero(bits));
  }

  /// Calls f(brick, bit) for every marked surfel, in index order (after number()).
  template <class F>
  void forEach(F&& f) const {
    for (std::uint32_t b : order_) forEachIn(b, f);
  }

 private:
  using Words = std::array<std::uint64_t, kWords>;
  using Prefix = std::array<std::uint32_t, kWords>;
  std::vector<Words> words_;
  std::vector<std::uint32_t> order_;
  std::vector<Prefix> prefix_;
};

}  // namespace surftrack
