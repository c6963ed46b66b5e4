// The tracker's visited structure: an open-addressing hash map from surfel key to vertex
// index. It grows with the surface, never with the volume (spec.md §3).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "Hash.h"
#include "Surfel.h"

namespace surftrack {

class SurfelIndexMap {
 public:
  explicit SurfelIndexMap(std::size_t expected = 1024) { rehash(capacityFor(expected)); }

  /// Returns the index stored for s, inserting `next` if s is new; `.second` tells which.
  std::pair<std::uint32_t, bool> insert(const Surfel& s, std::uint32_t next) {
    if (2 * (size_ + 1) > slots_.size()) rehash(2 * slots_.size());
    const std::uint64_t key = s.key();
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      Slot& e = slots_[i];
      if (e.key == key) return {e.index, false};
      if (e.key == kEmpty) {
        e = {key, next};
        ++size_;
        return {next, true};
      }
    }
  }

  /// The index of s, or -1 if absent.
  std::int64_t find(const Surfel& s) const {
    const std::uint64_t key = s.key();
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      const Slot& e = slots_[i];
      if (e.key == key) return e.index;
      if (e.key == kEmpty) return -1;
    }
  }

  std::size_t size() const { return size_; }
  std::size_t bytes() const { return slots_.capacity() * sizeof(Slot); }

 private:
  struct Slot {
    std::uint64_t key;
    std::uint32_t index;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);

  static std::size_t capacityFor(std::size_t n) {
    std::size_t c = 64;
    while (c < 2 * n) c *= 2;
    return c;
  }
  // Surfels of one 4x4x4 block of voxels share a 512-slot window of the table, so that the
  // traversal, which moves across the surface locally, keeps hitting the same cache lines.
  std::size_t slot(std::uint64_t key) const {
    constexpr std::uint64_t kLocal = 0x7ull | (0x3ull << 3) | (0x3ull << 23) | (0x3ull << 43);
    const std::uint64_t local = (key & 7u) | ((key >> 3) & 3u) << 3 | ((key >> 23) & 3u) << 5 |
                                ((key >> 43) & 3u) << 7;
    const std::uint64_t block = mix64(key & ~kLocal);
    return std::size_t((block << 9) | local) & mask_;
  }
  void rehash(std::size_t capacity) {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(capacity, Slot{kEmpty, 0});
    mask_ = capacity - 1;
    size_ = 0;
    for (const Slot& e : old)
      if (e.key != kEmpty) insert(Surfel::fromKey(e.key), e.index);
  }

  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace surftrack
