// N5 datasets (docs/api.md "Chunked stores"): a directory holding `attributes.json`
// (dimensions, blockSize, dataType, compression) and one file per block at `i/j/k`. N5 lists
// axes the other way round from zarr and numpy: x first. A block starts with a header (mode 0:
// the block's own size, smaller at the far edges; big-endian), then its voxels, big-endian, x
// fastest, compressed as a whole. A missing block holds 0.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ChunkCodecs.h"
#include "ChunkedSource.h"

namespace surftrack::io {

/// What `attributes.json` says about a dataset, checked.
struct N5Header {
  std::vector<std::int64_t> dimensions, blockSize;  ///< N5's order: x first
  ScalarType type = ScalarType::UInt8;
  std::string dataType;  ///< as stored: "uint16", "float32", ...
  detail::ChunkCodec codec;
};

/// Whether `<dir>/attributes.json` names a dataset (has "dimensions"); false for a group or no
/// N5 at all. Throws ReadError for a file that is not JSON.
bool isN5Dataset(const std::string& dir);

/// Reads and checks `<dir>/attributes.json`. Throws ReadError naming the file: missing, not
/// JSON, not a dataset, a dataType other than the ten voxel types, a compression other than
/// raw, gzip (or zlib), zstd or blosc.
N5Header readN5Header(const std::string& dir);

/// The volume of the dataset in `dir`, as openZarrArray gives a zarr array's: `fixed` indexes
/// the axes before the spatial ones in numpy's order (N5's last axes).
std::shared_ptr<const ChunkProvider> openN5Dataset(const std::string& dir, const N5Header& header, int spatialAxes,
                                                   const std::vector<std::int64_t>& fixed, const ImageGeometry& geometry);

}  // namespace surftrack::io
