// Neuroglancer's sharded storage (ShardedFormat.h), as its sharded.md specifies it.
#include "ShardedFormat.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <zlib.h>

#include "PrecomputedDirectory.h"

namespace surftrack {

namespace {

std::uint32_t rotl32(std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }

std::uint32_t fmix32(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x85ebca6bU;
  h ^= h >> 13;
  h *= 0xc2b2ae35U;
  h ^= h >> 16;
  return h;
}

}  // namespace

std::uint64_t murmurHash3_x86_128(std::uint64_t key) {
  // Austin Appleby's MurmurHash3_x86_128 for an input of 8 bytes (no full 16-byte block): the
  // tail of k1 and k2 only, then the finalization.
  constexpr std::uint32_t c1 = 0x239b961bU, c2 = 0xab0e9789U, c3 = 0x38b34ae5U;
  std::uint32_t h1 = 0, h2 = 0, h3 = 0, h4 = 0;
  std::uint32_t k1 = std::uint32_t(key), k2 = std::uint32_t(key >> 32);
  k2 *= c2;
  k2 = rotl32(k2, 16);
  k2 *= c3;
  h2 ^= k2;
  k1 *= c1;
  k1 = rotl32(k1, 15);
  k1 *= c2;
  h1 ^= k1;
  const std::uint32_t len = 8;
  h1 ^= len, h2 ^= len, h3 ^= len, h4 ^= len;
  h1 += h2, h1 += h3, h1 += h4;
  h2 += h1, h3 += h1, h4 += h1;
  h1 = fmix32(h1), h2 = fmix32(h2), h3 = fmix32(h3), h4 = fmix32(h4);
  h1 += h2, h1 += h3, h1 += h4;
  h2 += h1;
  return std::uint64_t(h1) | (std::uint64_t(h2) << 32);
}

nlohmann::ordered_json ShardingSpec::json() const {
  return {{"@type", "neuroglancer_uint64_sharded_v1"},
          {"preshift_bits", preshiftBits},
          {"hash", hash == ShardHash::Identity ? "identity" : "murmurhash3_x86_128"},
          {"minishard_bits", minishardBits},
          {"shard_bits", shardBits},
          {"minishard_index_encoding", gzipMinishardIndex ? "gzip" : "raw"},
          {"data_encoding", gzipData ? "gzip" : "raw"}};
}

std::uint64_t ShardingSpec::hashed(std::uint64_t key) const {
  const std::uint64_t shifted = preshiftBits >= 64 ? 0 : key >> preshiftBits;
  return hash == ShardHash::Identity ? shifted : murmurHash3_x86_128(shifted);
}

namespace {
std::uint64_t lowBits(std::uint64_t x, int bits) { return bits >= 64 ? x : x & ((std::uint64_t(1) << bits) - 1); }
}  // namespace

std::uint64_t ShardingSpec::minishardOf(std::uint64_t key) const { return lowBits(hashed(key), minishardBits); }

std::uint64_t ShardingSpec::shardOf(std::uint64_t key) const {
  return minishardBits >= 64 ? 0 : lowBits(hashed(key) >> minishardBits, shardBits);
}

std::string ShardingSpec::shardFileName(std::uint64_t shard) const {
  static const char* digits = "0123456789abcdef";
  std::string hex;
  for (std::uint64_t s = shard; s != 0; s >>= 4) hex.insert(hex.begin(), digits[s & 15]);
  const std::size_t width = std::size_t((shardBits + 3) / 4);
  if (hex.size() < width) hex.insert(0, width - hex.size(), '0');
  if (hex.empty()) hex = "0";
  return hex + ".shard";
}

ShardingSpec shardingFor(std::size_t keys, ShardHash hash) {
  ShardingSpec spec;
  spec.hash = hash;
  int bits = 0;  // log2 of the minishards wanted, one per 2^8 chunks
  while ((std::size_t(1) << (bits + 8)) < keys && bits < 40) ++bits;
  spec.minishardBits = std::min(bits, 6);
  spec.shardBits = bits - spec.minishardBits;
  return spec;
}

std::string gzipBytes(const std::string& bytes) {
  z_stream z{};
  if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("zlib cannot start a gzip stream");
  std::string out(deflateBound(&z, uLong(bytes.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = uInt(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  const int rc = deflate(&z, Z_FINISH);
  const std::size_t n = z.total_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("zlib cannot gzip " + std::to_string(bytes.size()) + " bytes");
  out.resize(n);
  return out;
}

std::vector<std::pair<std::string, std::string>> buildShards(const ShardingSpec& spec, std::vector<ShardChunk> chunks) {
  // Shard -> minishard -> chunks by increasing key (the ids' deltas are then nonnegative).
  std::map<std::uint64_t, std::map<std::uint64_t, std::vector<const ShardChunk*>>> shards;
  std::sort(chunks.begin(), chunks.end(), [](const ShardChunk& a, const ShardChunk& b) { return a.key < b.key; });
  for (const ShardChunk& c : chunks) shards[spec.shardOf(c.key)][spec.minishardOf(c.key)].push_back(&c);

  std::vector<std::pair<std::string, std::string>> files;
  const std::uint64_t minishards = std::uint64_t(1) << spec.minishardBits;
  for (const auto& [shard, byMinishard] : shards) {
    std::string data;  // everything after the shard index; offsets are relative to its start
    std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges(minishards, {0, 0});
    std::vector<std::string> indices;
    std::vector<std::uint64_t> indexed;
    for (const auto& [minishard, list] : byMinishard) {
      std::vector<std::uint64_t> ids, starts, sizes;
      std::uint64_t previousKey = 0, previousEnd = 0;
      for (const ShardChunk* c : list) {
        data += c->prefix;
        const std::string value = spec.gzipData ? gzipBytes(c->value) : c->value;
        const std::uint64_t start = data.size();
        data += value;
        ids.push_back(c->key - previousKey);
        starts.push_back(start - previousEnd);
        sizes.push_back(value.size());
        previousKey = c->key;
        previousEnd = start + value.size();
      }
      std::string index;
      for (const auto* column : {&ids, &starts, &sizes})
        for (std::uint64_t v : *column) appendLittleEndian(index, v);
      indices.push_back(spec.gzipMinishardIndex ? gzipBytes(index) : index);
      indexed.push_back(minishard);
    }
    for (std::size_t i = 0; i < indices.size(); ++i) {
      ranges[indexed[i]] = {data.size(), data.size() + indices[i].size()};
      data += indices[i];
    }
    std::string file;
    file.reserve(16 * minishards + data.size());
    for (const auto& [start, end] : ranges) {
      appendLittleEndian(file, start);
      appendLittleEndian(file, end);
    }
    file += data;
    files.emplace_back(spec.shardFileName(shard), std::move(file));
  }
  return files;
}

}  // namespace surftrack
