// Zarr v2 arrays (docs/api.md "Chunked stores"): a directory holding `.zarray` (JSON: shape,
// chunks, dtype, order, fill_value, compressor, filters, dimension_separator) and one file per
// chunk, named by its chunk coordinates joined by the separator ("0.1.2", or "0/1/2" in nested
// directories). Every chunk is stored whole, the ones at the far edges too; a missing chunk
// file holds the fill value. Axes: numpy's, the engine's x the last (io/ChunkGrid.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ChunkCodecs.h"
#include "ChunkedSource.h"

namespace surftrack::io {

/// What `.zarray` says, checked.
struct ZarrHeader {
  std::vector<std::int64_t> shape, chunks;  ///< numpy's axis order
  ScalarType type = ScalarType::UInt8;
  bool bigEndian = false;
  std::string dtype;         ///< as stored: "<u2", ">f8", "|u1"
  bool fortranOrder = false; ///< order "F"
  char separator = '.';      ///< dimension_separator: '.' or '/'
  std::vector<unsigned char> fill;  ///< one voxel, machine byte order (null: 0)
  detail::ChunkCodec codec;
};

/// Reads and checks `<dir>/.zarray`. Throws ReadError naming the file: missing (not a zarr
/// array), not JSON, zarr_format other than 2, a dtype other than the ten voxel types (u1 i1 u2
/// i2 u4 i4 u8 i8 f4 f8, byte order '<', '>' or '|'), an order other than C or F, a fill value
/// the dtype cannot hold, a compressor other than blosc, zstd, zlib or gzip, any filter.
ZarrHeader readZarrHeader(const std::string& dir);

/// The volume of the zarr array in `dir` as chunks for the engine: its last `spatialAxes` axes
/// (3, or 2 for one slice), each leading axis fixed at its index in `fixed`, placed by
/// `geometry`. Throws ReadError for shapes and chunks the engine cannot read (io/ChunkGrid.h).
std::shared_ptr<const ChunkProvider> openZarrArray(const std::string& dir, const ZarrHeader& header, int spatialAxes,
                                                   const std::vector<std::int64_t>& fixed, const ImageGeometry& geometry);

}  // namespace surftrack::io
