// The checksum of a fragment file's bytes (internal to core/; LabelBlockFiles.h, docs/api.md,
// "Fragment files"), computed in one call or chunk by chunk, so that the streamed writer of a
// label's mesh (LabelMeshStream.cpp) checks a label's data as it reads them, never holding them.
#pragma once

#include <cstdint>
#include <cstring>

#include "Hash.h"

namespace surftrack {

/// Every 8 bytes mixed in turn (Hash.h), the tail zero-padded, the length mixed in last. Fed in
/// pieces whose sizes are multiples of 8 but the last, it gives the one-call value.
class FragmentChecksum {
 public:
  static constexpr std::uint64_t kSeed = 0x5354465241470001ull;
  explicit FragmentChecksum(std::uint64_t seed = kSeed) : h_(seed) {}

  void add(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::size_t i = 0;
    for (; i + 8 <= bytes; i += 8, at_ += 8) {
      std::uint64_t w;
      std::memcpy(&w, p + i, 8);
      h_ = mix64(h_ ^ w) + at_;
    }
    if (bytes > i) {  // the tail: only in the last piece
      std::memcpy(&tail_, p + i, bytes - i);  // (an empty vector's data may be null)
      at_ += bytes - i;
    }
  }

  std::uint64_t finish() const { return mix64(h_ ^ tail_ ^ (at_ << 56)); }

 private:
  std::uint64_t h_, at_ = 0, tail_ = 0;
};

/// The checksum of `bytes` bytes in one call.
inline std::uint64_t fragmentChecksum(const void* data, std::size_t bytes,
                                      std::uint64_t seed = FragmentChecksum::kSeed) {
  FragmentChecksum sum(seed);
  sum.add(data, bytes);
  return sum.finish();
}

}  // namespace surftrack
