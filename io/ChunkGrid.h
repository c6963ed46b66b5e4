// What zarr v2 arrays and N5 datasets share (docs/api.md "Chunked stores"): an N-dimensional
// array cut into a regular grid of chunk files, seen by the engine as a 3D volume. The array's
// axes are listed as numpy lists them (slowest first, zarr's order; N5's is the reverse); the
// engine's x is the last array axis, y the one before, z the one before that, as the Python
// package maps a numpy array (python/surftrack/__init__.py). Axes before the spatial ones (time,
// channel) are fixed at one index each. A format's reader parses its metadata into a ChunkGrid
// and says where a chunk's file is and how its bytes decode; GridProvider does the rest: missing
// chunk files, clipping at the far edges, memory order, byte order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ChunkedSource.h"

namespace surftrack::io::detail {

/// `text` with its control bytes escaped (\n, \x01), for messages of one line.
std::string escapedText(const std::string& text);

/// "'path'", for messages: a path or a name read from metadata, quoted, escaped.
std::string quotedPath(const std::string& path);

/// An N-dimensional chunked array, in numpy's axis order, and the 3D volume the engine reads.
struct ChunkGrid {
  std::vector<std::int64_t> shape;   ///< the array
  std::vector<std::int64_t> chunks;  ///< one chunk (the grid's cells; edge chunks may be stored whole)
  ScalarType type = ScalarType::UInt8;
  bool bigEndian = false;            ///< the stored byte order of multi-byte voxels
  bool fortranOrder = false;         ///< a chunk's first axis varies fastest (zarr's order "F")
  std::vector<unsigned char> fill;   ///< one voxel of the fill value, machine byte order
  /// The trailing axes that are spatial: 3, or 2 (the engine's z then has one voxel).
  int spatialAxes = 3;
  /// One index for each leading axis (shape.size() - spatialAxes of them).
  std::vector<std::int64_t> fixed;
  ImageGeometry geometry;

  int rank() const { return int(shape.size()); }
  /// The array axis of engine axis e (0: x), or -1 for z of a 2D volume.
  int arrayAxisOf(int e) const { return e < spatialAxes ? rank() - 1 - e : -1; }
};

/// The bytes a full chunk takes (all of `chunks`, leading axes included).
std::uint64_t chunkBytes(const ChunkGrid& grid);

/// Checks a parsed grid: rank 2 to 5 with spatialAxes of them spatial, positive shape and chunks,
/// spatial sizes and chunks that fit the engine's int, a full chunk of at most 2 GiB, leading
/// indices inside the shape, a fill value of one voxel. Throws ReadError "<context>: <why>".
void requireValidGrid(const ChunkGrid& grid, const std::string& context);

/// The engine's layout of the grid's volume.
ChunkLayout layoutOf(const ChunkGrid& grid);

/// A chunk file's bytes, or nothing if the file does not exist (a chunk the store does not
/// hold). Throws ReadError naming the file when it exists but cannot be read.
std::optional<std::string> readChunkFile(const std::string& path);

/// A provider over a ChunkGrid: the format's reader says where chunk files are and how their
/// bytes decode into a chunk's voxels.
class GridProvider : public ChunkProvider {
 public:
  explicit GridProvider(ChunkGrid grid);
  const ChunkLayout& layout() const override { return layout_; }
  std::uint64_t read(Voxel index, void* out) const override;
  const ChunkGrid& grid() const { return grid_; }

 protected:
  /// The decoded voxels of one chunk file: `shape` (numpy order, grid's memory and byte order)
  /// and its bytes, exactly product(shape) voxels; or, decoded in place (`bytes` null), the
  /// chunk's voxels are in the caller's `direct` buffer already.
  struct Decoded {
    std::vector<std::int64_t> shape;
    std::unique_ptr<unsigned char[]> bytes;
    std::size_t size = 0;
  };
  /// The file of the chunk at `coords` (array chunk coordinates, numpy order).
  virtual std::string chunkPath(const std::vector<std::int64_t>& coords) const = 0;
  /// Decodes a chunk file's bytes; the shape may be smaller than the grid's chunks at the far
  /// edges (N5) but must cover the array there. Throws ReadError naming `path`. When `direct`
  /// is not null, a chunk whose shape is the grid's chunks may be decoded into it (its bytes
  /// are then the engine's chunk as they are: GridProvider passes it only for those grids).
  virtual Decoded decode(const std::string& bytes, const std::string& path, unsigned char* direct) const = 0;

 private:
  ChunkGrid grid_;
  ChunkLayout layout_;
};

}  // namespace surftrack::io::detail
