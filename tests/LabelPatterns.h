// Label images for the tests of shared walls (tests/test_shared_walls.cpp,
// tests/test_complex_smoothing.cpp): every priority pattern of one digital 3-cube, and random
// label images of dense noise or blobs from a fixed generator.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "Geometry.h"
#include "Voxel.h"

namespace surftrack::testing {

using Ranks = std::array<std::uint8_t, 8>;

/// Every map of the 8 corners onto 0..k-1 (k = 1..8): set partitions by restricted growth
/// strings, then every order of their parts.
inline std::vector<Ranks> allPriorityPatterns() {
  std::vector<Ranks> out;
  std::array<int, 8> block{};
  auto emit = [&](int parts) {
    std::vector<std::uint8_t> order(static_cast<std::size_t>(parts));
    std::iota(order.begin(), order.end(), std::uint8_t(0));
    do {
      Ranks r;
      for (int i = 0; i < 8; ++i) r[std::size_t(i)] = order[std::size_t(block[std::size_t(i)])];
      out.push_back(r);
    } while (std::next_permutation(order.begin(), order.end()));
  };
  auto grow = [&](auto&& self, int i, int parts) -> void {
    if (i == 8) return emit(parts);
    for (int b = 0; b <= parts && b < 8; ++b) {
      block[std::size_t(i)] = b;
      self(self, i + 1, std::max(parts, b + 1));
    }
  };
  grow(grow, 0, 0);
  return out;
}

/// A random image of `count` distinct labels (the first 0 if withBackground): dense noise, or
/// in half the images blobs.
inline std::vector<std::uint16_t> randomLabels(std::mt19937_64& rng, Dims dims, int count, bool withBackground) {
  std::vector<std::uint16_t> palette;
  std::uniform_int_distribution<int> value(1, 5000);
  while (int(palette.size()) < count) {
    const auto v = std::uint16_t(value(rng));
    if (std::find(palette.begin(), palette.end(), v) == palette.end()) palette.push_back(v);
  }
  if (withBackground) palette[0] = 0;
  std::vector<std::uint16_t> data(std::size_t(dims.nx) * std::size_t(dims.ny) * std::size_t(dims.nz));
  // Half the images: blobs (each voxel copies a neighbour now and then) rather than pure noise.
  const bool blobs = rng() % 2;
  std::uniform_int_distribution<int> pick(0, count - 1);
  for (std::size_t i = 0; i < data.size(); ++i) {
    data[i] = palette[std::size_t(pick(rng))];
    if (blobs && i > 0 && rng() % 3) data[i] = data[i - 1 - std::size_t(rng() % std::min<std::size_t>(i, 30))];
  }
  return data;
}

}  // namespace surftrack::testing
