// Neuroglancer's sharded storage, "neuroglancer_uint64_sharded_v1" (docs/cli.md, "Neuroglancer
// output"): uint64 keys hashed into 2^shard_bits files "<shard>.shard", each a fixed shard
// index of 2^minishard_bits (start, end) pairs, then the chunks, then the minishard indices
// (delta-encoded [3, n] uint64 arrays of key, start and size), so that a million segments are
// a few files rather than a million.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace surftrack {

enum class ShardHash { Identity, MurmurHash3_x86_128 };

struct ShardingSpec {
  int preshiftBits = 0;
  ShardHash hash = ShardHash::MurmurHash3_x86_128;
  int minishardBits = 0;
  int shardBits = 0;
  bool gzipMinishardIndex = true;  ///< "gzip", else "raw"
  bool gzipData = true;            ///< "gzip", else "raw": the values (not their prefixes)

  /// The "sharding" member of an info file.
  nlohmann::ordered_json json() const;
  /// The hashed key: hash(key >> preshiftBits).
  std::uint64_t hashed(std::uint64_t key) const;
  std::uint64_t shardOf(std::uint64_t key) const;
  std::uint64_t minishardOf(std::uint64_t key) const;
  /// "<shard>.shard": lowercase hexadecimal, zero-padded to ceil(shard_bits / 4) digits.
  std::string shardFileName(std::uint64_t shard) const;
};

/// A layout for `keys` chunks: about 2^8 chunks per minishard and 2^6 minishards per shard
/// before shards multiply (every shard file nonempty on average).
ShardingSpec shardingFor(std::size_t keys, ShardHash hash = ShardHash::MurmurHash3_x86_128);

/// The low 64 bits (little-endian) of MurmurHash3_x86_128 of the 8 little-endian bytes of
/// `key`, seed 0: the spec's hash.
std::uint64_t murmurHash3_x86_128(std::uint64_t key);

/// gzip (RFC 1952) of `bytes`. \throw std::runtime_error if zlib fails.
std::string gzipBytes(const std::string& bytes);

struct ShardChunk {
  std::uint64_t key = 0;
  std::string prefix;  ///< bytes stored just before the value and not indexed (a mesh's fragments)
  std::string value;   ///< the indexed value, before the data encoding
};

/// The shard files of `chunks` (distinct keys), as (file name, bytes), nonempty shards only.
std::vector<std::pair<std::string, std::string>> buildShards(const ShardingSpec& spec, std::vector<ShardChunk> chunks);

}  // namespace surftrack
