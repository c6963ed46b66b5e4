// The compressors of chunked stores (zarr v2 and N5, docs/api.md "Chunked stores"): one chunk's
// bytes as stored, decoded into exactly the bytes its voxels take. Blosc (every compressor and
// shuffle libblosc knows: lz4, lz4hc, zstd, zlib, blosclz; byte and bit shuffle), zstd, zlib and
// gzip; "raw" copies. Filters are not codecs: the formats' readers refuse them.
#pragma once

#include <cstddef>
#include <string>

namespace surftrack::io::detail {

/// How a store's chunks are compressed.
struct ChunkCodec {
  enum class Kind { Raw, Blosc, Zstd, Zlib, Gzip } kind = Kind::Raw;
  /// For reports: "none", "blosc (lz4, shuffle 1)", "zstd", "zlib", "gzip".
  std::string description;
};

/// Decodes the `size` bytes at `in` into out[0 .. expected): the chunk must decode to exactly
/// `expected` bytes. Throws ReadError "<context>: <why>" for a chunk that is corrupt, truncated
/// or decodes to another size. Thread-safe (each thread decodes with contexts of its own).
void decodeChunk(const ChunkCodec& codec, const unsigned char* in, std::size_t size, unsigned char* out,
                 std::size_t expected, const std::string& context);

}  // namespace surftrack::io::detail
