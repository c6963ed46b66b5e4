// A chunked store (zarr v2, N5, OME-Zarr; docs/api.md, "Chunked volumes") as a voxel source.
// The tracker reads a volume only near the surface it follows (VoxelSource.h), so a seeded
// extraction decodes only the chunks that surface crosses: a ChunkProvider decodes one chunk,
// a ChunkCache keeps a bounded number of decoded chunks, and makeChunkedSource answers the
// engine's reads from the cache. The block meshing of every label reads through the same cache.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>

#include "Geometry.h"
#include "ScalarType.h"
#include "VoxelSource.h"
#include "Voxel.h"

namespace surftrack {

/// The shape of a chunked array, in the engine's axes (x fastest, as VolumeView).
struct ChunkLayout {
  Dims dims;                ///< the whole array
  Dims chunk;               ///< one chunk; the chunks at the far edges are clipped to `dims`
  ScalarType type = ScalarType::UInt8;
  ImageGeometry geometry;   ///< spacing, origin and direction of the array

  /// The chunks along each axis: ceil(dims / chunk).
  Dims chunkCounts() const;
  /// The voxels of chunk `index` (chunk coordinates) inside the array: chunk, clipped at the far edges.
  Dims extentOf(Voxel index) const;
};

/// Decodes one chunk of a store. read() may be called from several threads at once, for
/// different chunks (ChunkCache never asks for one chunk twice at once).
class ChunkProvider {
 public:
  virtual ~ChunkProvider() = default;
  virtual const ChunkLayout& layout() const = 0;
  /// Writes chunk `index` (chunk coordinates, 0 <= index < layout().chunkCounts()) into `out`:
  /// its layout().extentOf(index) voxels, x fastest, of layout().type in the machine's byte
  /// order. A chunk the store does not hold is the store's fill value. Returns the bytes read
  /// from storage (0 for a missing chunk). Throws ReadError-like exceptions (std::runtime_error)
  /// with a one-line message naming the chunk's file for a chunk that cannot be decoded.
  virtual std::uint64_t read(Voxel index, void* out) const = 0;
};

/// What a ChunkCache did, for progress and reports.
struct ChunkCacheCounters {
  std::uint64_t chunksDecoded = 0;  ///< provider reads (a chunk evicted and read again counts twice)
  std::uint64_t bytesRead = 0;      ///< from storage, as the provider reports them
  std::uint64_t hits = 0;           ///< chunk requests answered without a read
};

/// A decoded chunk, pinned while a caller holds it.
struct DecodedChunk {
  Voxel index;     ///< chunk coordinates
  Voxel origin;    ///< its first voxel in the array
  Dims extent;     ///< its voxels (clipped at the array's far edges)
  const void* data = nullptr;  ///< extent voxels of the layout's type, x fastest
};

/// The default byte budget of a ChunkCache: 512 MiB of decoded chunks.
inline constexpr std::size_t kDefaultChunkCacheBytes = std::size_t(512) << 20;

/// A bounded cache of decoded chunks (least recently used evicted past the byte budget; a
/// chunk in use is never freed under its user). Thread-safe; a chunk is never decoded twice at
/// once (a second caller waits for the first's read).
class ChunkCache {
 public:
  /// Throws InvalidInput for a null provider, a layout with empty or oversized dims or chunks.
  /// Past `budgetBytes` of decoded chunks, the least recently used are freed down to 15/16 of
  /// it; a budget of 0 (or below one chunk) keeps nothing beyond the chunks in use.
  explicit ChunkCache(std::shared_ptr<const ChunkProvider> provider,
                      std::size_t budgetBytes = kDefaultChunkCacheBytes);
  ~ChunkCache();
  ChunkCache(const ChunkCache&) = delete;
  ChunkCache& operator=(const ChunkCache&) = delete;

  const ChunkLayout& layout() const;
  /// Chunk `index`, decoded (from the cache or the provider). Rethrows the provider's
  /// exception to every caller waiting on that read; a later call reads again. Throws
  /// InvalidInput for an index outside the chunk grid.
  std::shared_ptr<const DecodedChunk> chunk(Voxel index) const;
  ChunkCacheCounters counters() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Copies the voxels of the box [lo, lo + extent) — inside layout().dims — out of the chunks
/// that hold it into `out` (extent voxels of the layout's type, x fastest): how a block of a
/// store is read whole (the block meshing, docs/python.md "Every label by blocks, on Dask").
/// Throws InvalidInput for a box outside the array; rethrows the provider's errors.
void copyBox(const ChunkCache& cache, Voxel lo, Dims extent, void* out);

/// A source reading through `cache` (shared: its counters stay readable after extraction).
/// Voxels outside layout().dims are 0-voxels, as for every source; a chunk's edge is never the
/// domain's edge. `geometry`, when given, is the one the source reports instead of the
/// layout's: the caller's spacing, origin or frame over a store's voxels.
std::unique_ptr<VoxelSource> makeChunkedSource(std::shared_ptr<const ChunkCache> cache,
                                               std::optional<ImageGeometry> geometry = std::nullopt);

}  // namespace surftrack
