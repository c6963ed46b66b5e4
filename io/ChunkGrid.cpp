// A chunk of the engine's volume from one chunk file: the file read whole (or found missing:
// the fill value), decoded by the format, checked against the shape it must have, and its
// voxels copied out in the engine's order (x fastest), byte-swapped to the machine's order. A
// zarr chunk at the far edges is stored whole and clipped here; an N5 block there is stored
// clipped already.
#include "ChunkGrid.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <climits>
#include <cstring>
#include <stdexcept>

#include "ReadVolume.h"

namespace surftrack::io::detail {

namespace {

[[noreturn]] void fail(const std::string& context, const std::string& why) { throw ReadError(context + ": " + why); }

std::string listText(const std::vector<std::int64_t>& values) {
  std::string s = "[";
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + std::to_string(values[i]);
  return s + "]";
}

// The largest chunk decoded at once: a chunk's buffer is allocated whole.
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t(1) << 31;

/// Copies n voxels of N bytes, `stride` voxels apart, swapping their bytes if asked.
template <std::size_t N>
void copyVoxels(const unsigned char* src, std::size_t stride, unsigned char* dst, int n, bool swap) {
  if (stride == 1 && !swap) {
    std::memcpy(dst, src, std::size_t(n) * N);
    return;
  }
  for (int i = 0; i < n; ++i, src += stride * N, dst += N) {
    if constexpr (N == 1) {
      *dst = *src;
    } else {
      unsigned char v[N];
      std::memcpy(v, src, N);
      if (swap) std::reverse(v, v + N);
      std::memcpy(dst, v, N);
    }
  }
}

}  // namespace

std::string escapedText(const std::string& text) {
  // A name read from metadata (an OME-Zarr level's path, an axis name or type, a codec's id)
  // may hold any character; messages are one line (docs/api.md, "Chunked stores"), so control
  // bytes are written as escapes (two-line messages: fuzz/findings/).
  std::string s;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) {
      s += c;
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      s += c == '\n' ? "\\n" : c == '\t' ? "\\t" : std::string("\\x") + kHex[u >> 4] + kHex[u & 15];
    }
  }
  return s;
}

std::string quotedPath(const std::string& path) { return "'" + escapedText(path) + "'"; }

std::uint64_t chunkBytes(const ChunkGrid& grid) {
  std::uint64_t bytes = sizeOf(grid.type);
  for (std::int64_t c : grid.chunks) {
    if (c <= 0 || std::uint64_t(c) > kMaxChunkBytes || bytes * std::uint64_t(c) > kMaxChunkBytes) return kMaxChunkBytes + 1;
    bytes *= std::uint64_t(c);
  }
  return bytes;
}

void requireValidGrid(const ChunkGrid& grid, const std::string& context) {
  const int rank = grid.rank();
  if (rank < 2 || rank > 5)
    fail(context, "the array has " + std::to_string(rank) +
                      " dimensions; a volume has 3 (or 2: one slice), and 4 or 5 with the leading time and channel axes chosen by index");
  if (grid.chunks.size() != grid.shape.size())
    fail(context, "the chunks " + listText(grid.chunks) + " do not have one size for each of the " + std::to_string(rank) + " axes of the shape " + listText(grid.shape));
  for (int a = 0; a < rank; ++a) {
    if (grid.shape[a] <= 0) fail(context, "the shape " + listText(grid.shape) + " has an empty axis");
    if (grid.chunks[a] <= 0) fail(context, "the chunks " + listText(grid.chunks) + " must be positive");
  }
  if (grid.spatialAxes < 2 || grid.spatialAxes > 3 || grid.spatialAxes > rank ||
      int(grid.fixed.size()) != rank - grid.spatialAxes)
    throw std::logic_error("ChunkGrid: inconsistent axes");
  for (int e = 0; e < grid.spatialAxes; ++e) {
    const int a = grid.arrayAxisOf(e);
    if (grid.shape[a] > INT_MAX)
      fail(context, "the shape " + listText(grid.shape) + " has more than " + std::to_string(INT_MAX) + " voxels along a spatial axis");
  }
  if (chunkBytes(grid) > kMaxChunkBytes)
    fail(context, "chunks of " + listText(grid.chunks) + " " + toString(grid.type) + " voxels take more than the 2 GiB a chunk may");
  for (std::size_t a = 0; a < grid.fixed.size(); ++a)
    if (grid.fixed[a] < 0 || grid.fixed[a] >= grid.shape[a])
      fail(context, "index " + std::to_string(grid.fixed[a]) + " is outside axis " + std::to_string(a) + " of the shape " + listText(grid.shape));
  if (grid.fill.size() != sizeOf(grid.type)) throw std::logic_error("ChunkGrid: fill value of the wrong size");
}

ChunkLayout layoutOf(const ChunkGrid& grid) {
  ChunkLayout layout;
  int dims[3] = {1, 1, 1}, chunk[3] = {1, 1, 1};
  for (int e = 0; e < grid.spatialAxes; ++e) {
    const int a = grid.arrayAxisOf(e);
    dims[e] = int(grid.shape[a]);
    chunk[e] = int(std::min(grid.chunks[a], grid.shape[a]));
  }
  layout.dims = {dims[0], dims[1], dims[2]};
  layout.chunk = {chunk[0], chunk[1], chunk[2]};
  layout.type = grid.type;
  layout.geometry = grid.geometry;
  return layout;
}

std::optional<std::string> readChunkFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT || errno == ENOTDIR) return std::nullopt;
    fail("cannot read chunk " + quotedPath(path), std::strerror(errno));
  }
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) fail("cannot read chunk " + quotedPath(path), std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail("cannot read chunk " + quotedPath(path), "it is not a regular file");
  if (std::uint64_t(st.st_size) > 2 * kMaxChunkBytes)
    fail("cannot read chunk " + quotedPath(path), "the file holds " + std::to_string(st.st_size) + " bytes, more than any chunk may");
  std::string bytes(std::size_t(st.st_size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(fd, bytes.data() + done, bytes.size() - done, off_t(done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("cannot read chunk " + quotedPath(path), std::strerror(errno));
    if (n == 0) fail("cannot read chunk " + quotedPath(path), "the file ended early (changed while read?)");
    done += std::size_t(n);
  }
  return bytes;
}

GridProvider::GridProvider(ChunkGrid grid) : grid_(std::move(grid)), layout_(layoutOf(grid_)) {}

std::uint64_t GridProvider::read(Voxel index, void* out) const {
  const ChunkGrid& g = grid_;
  const int rank = g.rank();
  if (rank < g.spatialAxes || rank < 2) throw std::logic_error("GridProvider: a grid of rank " + std::to_string(rank));
  int extent[3];
  for (int e = 0; e < 3; ++e) {
    const int n = layout_.dims[e], c = layout_.chunk[e];
    if (index[e] < 0 || index[e] >= (n + c - 1) / c)
      throw std::out_of_range("chunk (" + std::to_string(index.x) + ", " + std::to_string(index.y) + ", " +
                              std::to_string(index.z) + ") is outside the grid of chunks");
    extent[e] = std::min(c, n - index[e] * c);
  }
  // The array chunk holding the engine's chunk, and where the volume starts inside it.
  std::vector<std::int64_t> coords(rank), start(rank, 0);
  for (std::size_t a = 0; a < g.fixed.size(); ++a) {
    coords[a] = g.fixed[a] / g.chunks[a];
    start[a] = g.fixed[a] % g.chunks[a];
  }
  for (int e = 0; e < g.spatialAxes; ++e) coords[g.arrayAxisOf(e)] = index[e];

  const std::size_t voxel = sizeOf(g.type);
  auto* dst = static_cast<unsigned char*>(out);
  const std::string path = chunkPath(coords);
  const std::optional<std::string> stored = readChunkFile(path);
  if (!stored) {
    const std::size_t count = std::size_t(extent[0]) * extent[1] * extent[2];
    for (std::size_t i = 0; i < count; ++i) std::memcpy(dst + i * voxel, g.fill.data(), voxel);
    return 0;
  }
  // A 3D C-ordered chunk in the machine's byte order, whole inside the array, is the engine's
  // chunk as it is stored: decoded straight into `out`, no copy.
  const bool swap = voxel > 1 && g.bigEndian != (std::endian::native == std::endian::big);
  bool inPlace = rank == 3 && g.spatialAxes == 3 && !g.fortranOrder && !swap;
  for (int e = 0; e < 3 && inPlace; ++e) inPlace = extent[e] == g.chunks[rank - 1 - e];
  const Decoded chunk = decode(*stored, path, inPlace ? dst : nullptr);
  if (!chunk.bytes) {
    if (!inPlace || chunk.shape != g.chunks) throw std::logic_error("GridProvider: a chunk decoded in place unasked");
    return stored->size();
  }
  const std::string context = "cannot read chunk " + quotedPath(path);
  if (int(chunk.shape.size()) != rank) fail(context, "it holds " + std::to_string(chunk.shape.size()) + " dimensions, not " + std::to_string(rank));
  std::uint64_t count = 1;
  for (std::int64_t s : chunk.shape) count *= std::uint64_t(std::max<std::int64_t>(s, 0));
  if (count * voxel != chunk.size) throw std::logic_error("GridProvider: decoded size and shape disagree");
  // The stored chunk must cover the volume's part of it: whole (zarr), or clipped at the far
  // edges (N5), never less.
  for (int a = 0; a < rank; ++a) {
    std::int64_t need = start[a] + 1;
    for (int e = 0; e < g.spatialAxes; ++e)
      if (g.arrayAxisOf(e) == a) need = extent[e];
    if (chunk.shape[a] < need || chunk.shape[a] > g.chunks[a])
      fail(context, "it holds a chunk of " + listText(chunk.shape) + " voxels where the array's chunks are " + listText(g.chunks));
  }
  // Strides of the stored chunk, in voxels.
  std::vector<std::size_t> stride(rank);
  std::size_t s = 1;
  for (int i = 0; i < rank; ++i) {
    const int a = g.fortranOrder ? i : rank - 1 - i;
    stride[a] = s;
    s *= std::size_t(chunk.shape[a]);
  }
  std::size_t base = 0;
  for (int a = 0; a < rank; ++a) base += std::size_t(start[a]) * stride[a];
  const std::size_t sx = stride[rank - 1], sy = stride[rank - 2];  // engine x, y (arrayAxisOf)
  const std::size_t sz = g.spatialAxes == 3 ? stride[rank - 3] : 0;
  const unsigned char* src = chunk.bytes.get();
  for (int z = 0; z < extent[2]; ++z)
    for (int y = 0; y < extent[1]; ++y) {
      const unsigned char* row = src + (base + z * sz + y * sy) * voxel;
      unsigned char* to = dst + (std::size_t(z) * extent[1] + y) * extent[0] * voxel;
      switch (voxel) {
        case 1: copyVoxels<1>(row, sx, to, extent[0], swap); break;
        case 2: copyVoxels<2>(row, sx, to, extent[0], swap); break;
        case 4: copyVoxels<4>(row, sx, to, extent[0], swap); break;
        default: copyVoxels<8>(row, sx, to, extent[0], swap); break;
      }
    }
  return stored->size();
}

}  // namespace surftrack::io::detail
