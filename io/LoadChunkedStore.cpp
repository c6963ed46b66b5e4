// A chunked store read whole, for the tools that want every voxel in one buffer (a scan, the
// statistics of `info`, the tests' comparisons): chunks handed out to threads one at a time,
// each decoded by the provider into a scratch chunk and copied into place.
#include <algorithm>
#include <atomic>
#include <cstring>
#include <exception>
#include <new>
#include <thread>
#include <vector>

#include "ChunkedStore.h"
#include "HugePages.h"
#include "LoadVolume.h"

namespace surftrack::io {

LoadedVolume loadChunkedStore(const ChunkedStore& store, int threads, ChunkedLoadCounts* counts) {
  const ChunkProvider& provider = *store.provider;
  const ChunkLayout& layout = provider.layout();
  const Dims d = layout.dims, c = layout.chunk;
  const Dims grid{(d.nx + c.nx - 1) / c.nx, (d.ny + c.ny - 1) / c.ny, (d.nz + c.nz - 1) / c.nz};
  const std::size_t voxel = sizeOf(layout.type), bytes = d.count() * voxel;
  constexpr std::align_val_t kAlign{64};
  void* raw = ::operator new(std::max<std::size_t>(bytes, 1), kAlign);
  std::shared_ptr<void> buffer(raw, [](void* p) { ::operator delete(p, kAlign); });
  adviseHugePages(raw, bytes);
  auto* volume = static_cast<unsigned char*>(raw);

  std::atomic<std::size_t> next{0};
  std::atomic<std::uint64_t> missing{0}, bytesRead{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  const auto work = [&] {
    std::vector<unsigned char> chunk(c.count() * voxel);
    for (std::size_t k; !failed && (k = next++) < grid.count();) {
      const Voxel index{int(k % grid.nx), int(k / grid.nx % grid.ny), int(k / grid.nx / grid.ny)};
      try {
        const std::uint64_t n = provider.read(index, chunk.data());
        bytesRead += n;
        missing += n == 0;
      } catch (...) {
        if (!failed.exchange(true)) error = std::current_exception();
        return;
      }
      const Voxel o{index.x * c.nx, index.y * c.ny, index.z * c.nz};
      const int ex = std::min(c.nx, d.nx - o.x), ey = std::min(c.ny, d.ny - o.y), ez = std::min(c.nz, d.nz - o.z);
      for (int z = 0; z < ez; ++z)
        for (int y = 0; y < ey; ++y)
          std::memcpy(volume + ((std::size_t(o.z + z) * d.ny + (o.y + y)) * d.nx + o.x) * voxel,
                      chunk.data() + ((std::size_t(z) * ey + y) * ex) * voxel, std::size_t(ex) * voxel);
    }
  };
  const int n = int(std::min<std::size_t>(threads > 0 ? std::size_t(threads) : std::max(1u, std::thread::hardware_concurrency()),
                                          grid.count()));
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);

  LoadedVolume out;
  out.view = VolumeView{raw, layout.type, d, {1, std::ptrdiff_t(d.nx), std::ptrdiff_t(d.nx) * d.ny}, layout.geometry};
  out.owner = std::move(buffer);
  out.format = store.format;
  out.unit = store.unit;
  out.dataBytes = bytes;
  out.decodeReason = "its " + std::to_string(grid.count()) + " chunks decoded whole, compressor " + store.compressor;
  for (const AxisChoice& a : store.chosen)
    if (a.type == "channel") out.channel = int(a.index), out.channels = int(a.size);
  if (counts) *counts = {grid.count(), missing.load(), bytesRead.load()};
  return out;
}

}  // namespace surftrack::io
