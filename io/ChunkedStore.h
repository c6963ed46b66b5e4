// The one entry to chunked stores (docs/api.md "Chunked stores"): a directory recognised as a
// zarr v2 array, an OME-Zarr 0.4 image (a zarr group with "multiscales") or an N5 dataset,
// opened as a ChunkProvider of the 3D volume the engine reads, with what was chosen on the way
// (the resolution level, the index of each time or channel axis) for reports. Local or network
// file systems only: chunks are files.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ChunkedSource.h"

namespace surftrack::io {

struct ChunkedStoreOptions {
  int level = 0;  ///< OME-Zarr: the resolution level, 0 the finest; other stores have level 0 only
  /// The index along the channel axis (OME-Zarr's axis of type "channel"; the 4th-last axis of
  /// a zarr array or N5 dataset of 4 or 5 dimensions): 0 when not given.
  std::optional<std::int64_t> channel;
  /// The index along the time axis (OME-Zarr's "time" axis; the 5th-last axis): 0 when not given.
  std::optional<std::int64_t> time;
};

/// A leading axis of the array and the index read along it.
struct AxisChoice {
  std::string name;  ///< OME-Zarr's axis name; "c" (channel) or "t" (time) otherwise
  std::string type;  ///< "channel", "time", or OME-Zarr's other type ("index" when none is stated)
  std::int64_t index = 0, size = 1;
};

struct ChunkedStore {
  std::shared_ptr<const ChunkProvider> provider;
  std::string format;      ///< "zarr", "ome-zarr" or "n5"
  std::string arrayPath;   ///< the array read: the store, or an OME-Zarr level's directory
  std::string dtype;       ///< as stored: "<u2", ">f4", "|u1" (zarr), "uint16" (N5)
  std::string compressor;  ///< "none", "blosc (lz4, shuffle 1)", "zstd", "zlib", "gzip"
  std::string unit;        ///< OME-Zarr's unit of the space axes ("micrometer"); empty: not stated
  int level = 0, levels = 1;
  std::vector<AxisChoice> chosen;  ///< the axes before the spatial ones, each at one index

  /// "level 1 of 3, c 0 of 2": what was chosen, empty for a single 3D array.
  std::string choiceText() const;
};

/// Whether `path` is a directory holding a zarr array (.zarray), an OME-Zarr image (.zattrs
/// with multiscales), an N5 dataset (attributes.json), or a zarr (.zgroup) or N5 group, which
/// openChunkedStore refuses naming their arrays. Never throws.
bool isChunkedStore(const std::string& path);

/// Opens the store at `path`. Throws ReadError, one line naming the path: not a directory, not
/// a store (a zarr or N5 group: its arrays named), a level, channel or time index it does not
/// have, and the readers' errors (io/ZarrArray.h, io/N5Dataset.h, io/OmeZarr.h).
ChunkedStore openChunkedStore(const std::string& path, const ChunkedStoreOptions& options = {});

}  // namespace surftrack::io
