// A 64-bit mixer for the engine's open-addressing tables (the splitmix64 finaliser): every
// input bit reaches the low output bits that index a power-of-two table.
#pragma once

#include <cstdint>

namespace surftrack {

constexpr std::uint64_t mix64(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace surftrack
