// A map from 64-bit keys to 32-bit values, open addressing with linear probing over a
// power-of-two table (the engine's tables' scheme: lib/Hash.h): no allocation per entry, which
// is what made a std::unordered_map per label cost most of the shared walls' scan
// (docs/performance.md, "Label maps as one conforming complex"). Insert and find only.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "Hash.h"

namespace surftrack {

class FlatKeyMap {
 public:
  /// The value of `key`, inserting `value` for it if it is absent; whether it was inserted.
  /// `key` must not be ~0 (the empty slot).
  std::pair<std::uint32_t, bool> tryEmplace(std::uint64_t key, std::uint32_t value) {
    if (2 * (size_ + 1) > keys_.size()) grow(keys_.empty() ? 64 : 2 * keys_.size());
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = std::size_t(mix64(key)) & mask;; i = (i + 1) & mask) {
      if (keys_[i] == key) return {values_[i], false};
      if (keys_[i] == kEmpty) {
        keys_[i] = key;
        values_[i] = value;
        ++size_;
        return {value, true};
      }
    }
  }
  /// Room for `count` keys without growing (the table's load stays at most 1/2).
  void reserve(std::size_t count) {
    std::size_t slots = keys_.empty() ? 64 : keys_.size();
    while (slots < 2 * count) slots *= 2;
    if (slots > keys_.size()) grow(slots);
  }
  std::size_t size() const { return size_; }
  /// Frees the table.
  void clear() {
    std::vector<std::uint64_t>().swap(keys_);
    std::vector<std::uint32_t>().swap(values_);
    size_ = 0;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  void grow(std::size_t slots) {  // (a power of two)
    std::vector<std::uint64_t> keys(slots, kEmpty);
    std::vector<std::uint32_t> values(keys.size());
    const std::size_t mask = keys.size() - 1;
    for (std::size_t j = 0; j < keys_.size(); ++j)
      if (keys_[j] != kEmpty) {
        std::size_t i = std::size_t(mix64(keys_[j])) & mask;
        while (keys[i] != kEmpty) i = (i + 1) & mask;
        keys[i] = keys_[j];
        values[i] = values_[j];
      }
    keys_ = std::move(keys);
    values_ = std::move(values);
  }
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t size_ = 0;
};

}  // namespace surftrack
