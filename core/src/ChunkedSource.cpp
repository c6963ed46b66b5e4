// A chunked store as a voxel source (ChunkedSource.h; docs/api.md, "Chunked volumes"). The
// source binarises each chunk a block or row overlaps with the very row functions a view uses
// (lib/Image.h's ThresholdImage and LabelImage on a chunk-local VolumeRef), so it answers
// exactly as makeViewSource over the same voxels: chunks partition the domain, and a chunk-local
// image returns 0 for every voxel outside its chunk, so the rows of the chunks OR together into
// the row of the whole array.
#include <algorithm>
#include <cstring>
#include <atomic>
#include <cmath>
#include <exception>
#include <future>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ChunkedSource.h"
#include "Errors.h"
#include "Image.h"
#include "SelectionValue.h"
#include "Surfel.h"

namespace surftrack {

Dims ChunkLayout::chunkCounts() const {
  // An empty side (refused by ChunkCache) counts no chunks rather than dividing by zero.
  auto count = [](int n, int c) { return c <= 0 || n <= 0 ? 0 : int((std::int64_t(n) + c - 1) / c); };
  return {count(dims.nx, chunk.nx), count(dims.ny, chunk.ny), count(dims.nz, chunk.nz)};
}

Dims ChunkLayout::extentOf(Voxel index) const {
  auto extent = [](int n, int c, int i) {
    const std::int64_t first = std::int64_t(i) * c;
    return int(std::min<std::int64_t>(c, n - first));
  };
  return {extent(dims.nx, chunk.nx, index.x), extent(dims.ny, chunk.ny, index.y),
          extent(dims.nz, chunk.nz, index.z)};
}

namespace {

std::string dimsText(Dims d) {
  std::ostringstream s;
  s << d.nx << "x" << d.ny << "x" << d.nz;
  return s.str();
}

/// The checks of ChunkCache's constructor: the domain a view accepts (ViewSource.cpp's
/// requireDomain: surfel keys hold 20 bits per axis, Surfel.h) and a chunk of at least a voxel.
void requireLayout(const ChunkLayout& layout) {
  for (int a = 0; a < 3; ++a)
    if (layout.dims[a] <= 0 || layout.dims[a] >= Surfel::kCoordinateLimit - 2)
      throw InvalidInput("chunked volume dimensions " + dimsText(layout.dims) +
                         " are not supported: each must be in [1, " +
                         std::to_string(Surfel::kCoordinateLimit - 3) + "]");
  for (int a = 0; a < 3; ++a)
    if (layout.chunk[a] <= 0)
      throw InvalidInput("chunk shape " + dimsText(layout.chunk) + " is empty: each side must be at least 1");
  if (int(layout.type) < int(ScalarType::UInt8) || int(layout.type) > int(ScalarType::Float64))
    throw InvalidInput("chunked volume has an unknown scalar type (" + std::to_string(int(layout.type)) + ")");
}

/// A decoded chunk and its storage (8-byte aligned: every scalar type reads aligned).
struct OwnedChunk {
  DecodedChunk chunk;
  std::unique_ptr<std::uint64_t[]> storage;
};

using ChunkPtr = std::shared_ptr<const DecodedChunk>;

}  // namespace

// The cache: 16 shards, each a mutex over a map chunk key -> entry. An entry holds a
// shared_future, so that the first caller of a chunk decodes it outside every lock while later
// callers wait on the future (a chunk is never decoded twice at once, ChunkProvider's
// contract). Recency is a global tick stamped on every use; past the budget, the least recently
// used decoded entries are dropped down to 15/16 of it in one scan, so the scan's cost is
// shared by the chunks decoded until the budget is reached again. Dropping an entry drops only
// the cache's reference: a caller holding the shared_ptr keeps its chunk.
struct ChunkCache::State {
  static constexpr int kShards = 16;

  struct Entry {
    std::shared_future<ChunkPtr> future;
    std::uint64_t serial = 0;    // tells a retried entry from the failed one it replaced
    std::uint64_t lastUse = 0;   // tick of the latest request
    std::size_t bytes = 0;       // decoded bytes, 0 while in flight
    bool ready = false;
  };
  struct Shard {
    std::mutex mutex;
    std::unordered_map<std::uint64_t, Entry> entries;
  };

  std::shared_ptr<const ChunkProvider> provider;
  ChunkLayout layout;
  Dims counts;
  std::size_t budget = 0;
  std::size_t voxelBytes = 0;
  Shard shards[kShards];
  std::mutex evictMutex;  // one eviction scan at a time
  std::atomic<std::uint64_t> tick{0}, serial{0};
  std::atomic<std::size_t> bytesHeld{0};
  std::atomic<std::uint64_t> chunksDecoded{0}, bytesRead{0}, hits{0};

  std::uint64_t keyOf(Voxel index) const {
    return (std::uint64_t(index.z) * std::uint64_t(counts.ny) + std::uint64_t(index.y)) *
               std::uint64_t(counts.nx) + std::uint64_t(index.x);
  }
  Shard& shardOf(std::uint64_t key) {
    return shards[(key * 0x9E3779B97F4A7C15ull) >> 60];  // top 4 bits: kShards = 16
  }

  ChunkPtr get(Voxel index) {
    if (!counts.contains(index)) {
      std::ostringstream msg;
      msg << "chunk (" << index.x << ", " << index.y << ", " << index.z << ") is outside the chunk grid "
          << dimsText(counts);
      throw InvalidInput(msg.str());
    }
    const std::uint64_t key = keyOf(index);
    Shard& shard = shardOf(key);
    std::promise<ChunkPtr> promise;
    std::uint64_t mySerial = 0;
    std::shared_future<ChunkPtr> known;
    {
      std::lock_guard lock(shard.mutex);
      auto [it, inserted] = shard.entries.try_emplace(key);
      it->second.lastUse = ++tick;
      if (inserted) {
        mySerial = it->second.serial = ++serial;
        it->second.future = promise.get_future().share();
      } else {
        known = it->second.future;
      }
    }
    if (known.valid()) {
      hits.fetch_add(1, std::memory_order_relaxed);
      // Waits, outside the lock, for a chunk in flight; rethrows its reader's exception.
      return known.get();
    }
    ChunkPtr chunk;
    std::size_t bytes = 0;
    try {
      auto owned = std::make_shared<OwnedChunk>();
      const Dims extent = layout.extentOf(index);
      bytes = extent.count() * voxelBytes;
      owned->storage.reset(new std::uint64_t[(bytes + 7) / 8]);
      owned->chunk = DecodedChunk{index,
                                  Voxel{index.x * layout.chunk.nx, index.y * layout.chunk.ny,
                                        index.z * layout.chunk.nz},
                                  extent, owned->storage.get()};
      const std::uint64_t read = provider->read(index, owned->storage.get());
      chunksDecoded.fetch_add(1, std::memory_order_relaxed);
      bytesRead.fetch_add(read, std::memory_order_relaxed);
      chunk = ChunkPtr(owned, &owned->chunk);
    } catch (...) {
      // The failed entry goes before its waiters wake, so that a later request reads again.
      {
        std::lock_guard lock(shard.mutex);
        auto it = shard.entries.find(key);
        if (it != shard.entries.end() && it->second.serial == mySerial) shard.entries.erase(it);
      }
      promise.set_exception(std::current_exception());
      throw;
    }
    {
      std::lock_guard lock(shard.mutex);
      auto it = shard.entries.find(key);
      if (it != shard.entries.end() && it->second.serial == mySerial) {
        it->second.ready = true;
        it->second.bytes = bytes;
        bytesHeld.fetch_add(bytes);
      }
    }
    promise.set_value(chunk);
    if (bytesHeld.load() > budget) evict();
    return chunk;
  }

  /// Drops the least recently used decoded entries until the cache holds 15/16 of the budget.
  void evict() {
    std::lock_guard evicting(evictMutex);
    if (bytesHeld.load() <= budget) return;
    struct Candidate {
      std::uint64_t lastUse, key;
      int shard;
    };
    std::vector<Candidate> candidates;
    for (int s = 0; s < kShards; ++s) {
      std::lock_guard lock(shards[s].mutex);
      for (const auto& [key, entry] : shards[s].entries)
        if (entry.ready) candidates.push_back({entry.lastUse, key, s});
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.lastUse < b.lastUse; });
    const std::size_t target = budget - budget / 16;
    for (const Candidate& c : candidates) {
      if (bytesHeld.load() <= target) break;
      Shard& shard = shards[c.shard];
      std::lock_guard lock(shard.mutex);
      auto it = shard.entries.find(c.key);
      // An entry used since the scan is recent now: kept.
      if (it == shard.entries.end() || !it->second.ready || it->second.lastUse != c.lastUse) continue;
      bytesHeld.fetch_sub(it->second.bytes);
      shard.entries.erase(it);
    }
  }
};

ChunkCache::ChunkCache(std::shared_ptr<const ChunkProvider> provider, std::size_t budgetBytes) {
  if (!provider) throw InvalidInput("the chunk cache has no chunk provider (null pointer)");
  const ChunkLayout layout = provider->layout();
  requireLayout(layout);
  state_ = std::make_unique<State>();
  state_->provider = std::move(provider);
  state_->layout = layout;
  state_->counts = layout.chunkCounts();
  state_->budget = budgetBytes;
  state_->voxelBytes = sizeOf(layout.type);
}

ChunkCache::~ChunkCache() = default;

const ChunkLayout& ChunkCache::layout() const { return state_->layout; }

std::shared_ptr<const DecodedChunk> ChunkCache::chunk(Voxel index) const { return state_->get(index); }

ChunkCacheCounters ChunkCache::counters() const {
  return {state_->chunksDecoded.load(), state_->bytesRead.load(), state_->hits.load()};
}

namespace {

/// The chunks whose voxels meet [lo, hi) on one axis (hi > lo, both inside [0, n]).
struct ChunkRange {
  int first, last;  // inclusive
};
ChunkRange chunksOf(int lo, int hi, int chunk) { return {lo / chunk, (hi - 1) / chunk}; }

template <class T>
class ChunkedSource final : public VoxelSource {
 public:
  ChunkedSource(std::shared_ptr<const ChunkCache> cache, const ImageGeometry& geometry)
      : cache_(std::move(cache)), layout_(cache_->layout()), geometry_(geometry) {}

  Dims dims() const override { return layout_.dims; }
  ImageGeometry geometry() const override { return geometry_; }
  ScalarType type() const override { return scalarTypeOf<T>(); }

  void binaryBlock(const Selection& selection, Voxel origin, int width, int ny, int nz,
                   std::uint16_t* out) const override {
    std::fill(out, out + std::size_t(ny) * std::size_t(nz), std::uint16_t(0));
    const Voxel size{width, ny, nz};
    Voxel lo, hi;  // the block inside the domain
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(origin[a], 0);
      hi[a] = int(std::min<std::int64_t>(std::int64_t(origin[a]) + size[a], layout_.dims[a]));
      if (lo[a] >= hi[a]) return requireThreshold(selection);
    }
    const ChunkRange cx = chunksOf(lo.x, hi.x, layout_.chunk.nx),
                     cy = chunksOf(lo.y, hi.y, layout_.chunk.ny),
                     cz = chunksOf(lo.z, hi.z, layout_.chunk.nz);
    thread_local std::vector<std::uint16_t> part;
    for (int iz = cz.first; iz <= cz.last; ++iz)
      for (int iy = cy.first; iy <= cy.last; ++iy)
        for (int ix = cx.first; ix <= cx.last; ++ix) {
          const ChunkPtr chunk = cache_->chunk({ix, iy, iz});
          const VolumeRef<T> ref = refOf(*chunk);
          const Voxel& o = chunk->origin;
          // The rows of the block inside this chunk, j in [j0, j1), k in [k0, k1).
          const int j0 = std::max(lo.y, o.y) - origin.y, j1 = std::min(hi.y, o.y + ref.dims.ny) - origin.y;
          const int k0 = std::max(lo.z, o.z) - origin.z, k1 = std::min(hi.z, o.z + ref.dims.nz) - origin.z;
          const int x0 = origin.x - o.x;
          if (selection.isLabel()) {
            const LabelImage<T> image(ref, selectionValue<T>(selection));
            for (int k = k0; k < k1; ++k)
              for (int j = j0; j < j1; ++j)
                out[std::size_t(k) * ny + j] |=
                    std::uint16_t(image.row(x0, origin.y + j - o.y, origin.z + k - o.z, width));
          } else {
            const int pny = j1 - j0, pnz = k1 - k0;
            part.resize(std::size_t(pny) * std::size_t(pnz));
            ThresholdImage<T>(ref, selection.value)
                .rows(x0, origin.y + j0 - o.y, origin.z + k0 - o.z, width, pny, pnz, part.data());
            for (int k = 0; k < pnz; ++k)
              for (int j = 0; j < pny; ++j)
                out[std::size_t(k0 + k) * ny + (j0 + j)] |= part[std::size_t(k) * pny + j];
          }
        }
  }

  std::uint64_t binaryRow(const Selection& selection, Voxel start, int count) const override {
    const Dims& d = layout_.dims;
    const int lo = std::max(start.x, 0);
    const int hi = int(std::min<std::int64_t>(std::int64_t(start.x) + count, d.nx));
    if (start.y < 0 || start.y >= d.ny || start.z < 0 || start.z >= d.nz || lo >= hi) {
      requireThreshold(selection);
      return 0;
    }
    const ChunkRange cx = chunksOf(lo, hi, layout_.chunk.nx);
    const int iy = start.y / layout_.chunk.ny, iz = start.z / layout_.chunk.nz;
    std::uint64_t bits = 0;
    for (int ix = cx.first; ix <= cx.last; ++ix) {
      const ChunkPtr chunk = cache_->chunk({ix, iy, iz});
      const VolumeRef<T> ref = refOf(*chunk);
      const Voxel local = start - chunk->origin;
      bits |= selection.isLabel()
                  ? LabelImage<T>(ref, selectionValue<T>(selection)).row(local.x, local.y, local.z, count)
                  : ThresholdImage<T>(ref, selection.value).row(local.x, local.y, local.z, count);
    }
    return bits;
  }

  void values(const Voxel* voxels, std::size_t n, double* out) const override {
    // By chunk, so that each chunk of the batch is asked for once.
    std::vector<std::pair<std::uint64_t, std::size_t>> order;
    order.reserve(n);
    const Dims& d = layout_.dims;
    const Dims counts = layout_.chunkCounts();
    for (std::size_t i = 0; i < n; ++i) {
      const Voxel v = voxels[i];
      if (!d.contains(v)) {
        out[i] = 0;  // outside the domain: a 0-voxel, no gray value
        continue;
      }
      const std::uint64_t key =
          (std::uint64_t(v.z / layout_.chunk.nz) * std::uint64_t(counts.ny) + std::uint64_t(v.y / layout_.chunk.ny)) *
              std::uint64_t(counts.nx) + std::uint64_t(v.x / layout_.chunk.nx);
      order.emplace_back(key, i);
    }
    std::sort(order.begin(), order.end());
    ChunkPtr chunk;
    std::uint64_t chunkKey = 0;
    for (const auto& [key, i] : order) {
      const Voxel v = voxels[i];
      if (!chunk || key != chunkKey) {
        chunk.reset();  // unpinned before the next is read: a one-chunk budget holds
        chunk = cache_->chunk({v.x / layout_.chunk.nx, v.y / layout_.chunk.ny, v.z / layout_.chunk.nz});
        chunkKey = key;
      }
      out[i] = double(refOf(*chunk).at(v - chunk->origin));
    }
  }

 private:
  static VolumeRef<T> refOf(const DecodedChunk& c) {
    return VolumeRef<T>(static_cast<const T*>(c.data), c.extent, 1, c.extent.nx,
                        std::ptrdiff_t(c.extent.nx) * c.extent.ny);
  }
  /// A block or row entirely outside the domain reads no chunk; a NaN threshold is refused
  /// there too, as ThresholdImage refuses it on a view.
  static void requireThreshold(const Selection& selection) {
    if (!selection.isLabel() && std::isnan(selection.value)) throw std::invalid_argument("iso-value is NaN");
  }

  std::shared_ptr<const ChunkCache> cache_;
  ChunkLayout layout_;
  ImageGeometry geometry_;
};

}  // namespace

void copyBox(const ChunkCache& cache, Voxel lo, Dims extent, void* out) {
  const ChunkLayout& layout = cache.layout();
  for (int a = 0; a < 3; ++a)
    if (lo[a] < 0 || extent[a] < 1 || std::int64_t(lo[a]) + extent[a] > layout.dims[a])
      throw InvalidInput("the box from (" + std::to_string(lo.x) + ", " + std::to_string(lo.y) + ", " +
                         std::to_string(lo.z) + ") of " + std::to_string(extent.nx) + " x " +
                         std::to_string(extent.ny) + " x " + std::to_string(extent.nz) +
                         " voxels is not inside the array");
  const std::size_t item = sizeOf(layout.type);
  const ChunkRange cx = chunksOf(lo.x, lo.x + extent.nx, layout.chunk.nx),
                   cy = chunksOf(lo.y, lo.y + extent.ny, layout.chunk.ny),
                   cz = chunksOf(lo.z, lo.z + extent.nz, layout.chunk.nz);
  auto* to = static_cast<unsigned char*>(out);
  for (int iz = cz.first; iz <= cz.last; ++iz)
    for (int iy = cy.first; iy <= cy.last; ++iy)
      for (int ix = cx.first; ix <= cx.last; ++ix) {
        const std::shared_ptr<const DecodedChunk> c = cache.chunk({ix, iy, iz});
        const auto* from = static_cast<const unsigned char*>(c->data);
        Voxel a, b;  // the part of the box in this chunk, in array coordinates
        for (int k = 0; k < 3; ++k) {
          a[k] = std::max(lo[k], c->origin[k]);
          b[k] = std::min(lo[k] + extent[k], c->origin[k] + c->extent[k]);
        }
        const std::size_t run = std::size_t(b.x - a.x) * item;
        for (int z = a.z; z < b.z; ++z)
          for (int y = a.y; y < b.y; ++y) {
            const std::size_t src = ((std::size_t(z - c->origin.z) * std::size_t(c->extent.ny) +
                                      std::size_t(y - c->origin.y)) * std::size_t(c->extent.nx) +
                                     std::size_t(a.x - c->origin.x)) * item;
            const std::size_t dst = ((std::size_t(z - lo.z) * std::size_t(extent.ny) + std::size_t(y - lo.y)) *
                                         std::size_t(extent.nx) + std::size_t(a.x - lo.x)) * item;
            std::memcpy(to + dst, from + src, run);
          }
      }
}

std::unique_ptr<VoxelSource> makeChunkedSource(std::shared_ptr<const ChunkCache> cache,
                                               std::optional<ImageGeometry> geometry) {
  if (!cache) throw InvalidInput("the chunked source has no chunk cache (null pointer)");
  const ImageGeometry g = geometry.value_or(cache->layout().geometry);
  return visitScalarType(cache->layout().type, [&](auto v) -> std::unique_ptr<VoxelSource> {
    return std::make_unique<ChunkedSource<decltype(v)>>(cache, g);
  });
}

}  // namespace surftrack
