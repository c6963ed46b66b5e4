// Where the voxels of a volume file are: small, strict parsers of the headers of MetaImage,
// NRRD and NIfTI-1 files that find the data file, the byte offset of the first voxel, the voxel
// type, the dimensions and the byte order, so that io/LoadVolume.cpp can memory-map the voxels
// in place. They work on a buffer (the first bytes of the file) and do no I/O, so that
// fuzz/fuzz_volume_header.cpp can feed them arbitrary bytes.
//
// They do not compute the physical geometry: ITK reads that from the same header (io/LoadVolume.cpp
// explains why), and the voxel type, dimensions and byte order found here are checked against
// what ITK reads before anything is mapped.
#pragma once

#include <array>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "Geometry.h"
#include "ScalarType.h"

namespace surftrack::io {

/// A header that breaks its format's specification, or a file too short for what its header
/// announces. The message is one line and does not name the file (the caller does).
class HeaderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where and how a file stores its voxels.
struct DataLayout {
  Dims dims;                        ///< the first three axes; further axes all have size 1
  ScalarType type = ScalarType::UInt8;
  bool bigEndian = false;           ///< byte order of multi-byte voxels
  /// The file that holds the voxels, as the header writes it (relative to the header's
  /// directory unless absolute); empty: the header's own file.
  std::string dataFile;
  /// Byte offset of the first voxel in the data file (when !fromEnd).
  std::uint64_t offset = 0;
  /// The voxels are the last dataBytes() bytes of the data file (MetaImage HeaderSize = -1,
  /// NRRD "byte skip: -1"); for the header's own file, offset is then already resolved.
  bool fromEnd = false;
  /// The voxels are in several files (a list, or numbered files): dataFile is the header's
  /// description of them, not a file name.
  bool severalDataFiles = false;
  /// MetaImage "ElementDataFile = LIST", NRRD "data file: LIST": the listed files, as the
  /// header writes them (relative to the header's directory unless absolute), each holding an
  /// equal part of the voxels,
  std::vector<std::string> listedFiles;
  /// of at least this many bytes each when they are stored raw (0: not known).
  std::uint64_t listedPartBytes = 0;
  /// For voxels that are not stored raw: at most this many bytes of voxels per stored byte
  /// (deflate expands at most 1032 times; text needs two characters a value), so that a header
  /// announcing more voxels than its data can hold is an error before a reader allocates
  /// them; 0 when there is no such bound (bzip2).
  double maxExpansion = 0;
  /// MetaImage "CompressedData = True": the voxels are one zlib (or gzip) stream, at `offset`
  /// (or the last bytes of the file with fromEnd) and deflatedBytes long — CompressedDataSize;
  /// 0 when the header does not say, and MetaIO then inflates the whole file from its start.
  bool deflated = false;
  std::uint64_t deflatedBytes = 0;
  /// NIfTI-1 float32 and float64 voxels: readers built on niftilib (ITK's, hence readVolume)
  /// replace NaN and infinite values with 0 as they read, so a view in place of values stored
  /// that way would differ from them.
  bool nonFiniteReadAsZero = false;
  /// Non-empty: the voxels are not stored raw in one file with x fastest (compressed, text,
  /// several files, scaled, ...), so they cannot be viewed in place; ITK decodes them. Says why.
  std::string decodeReason;

  std::uint64_t dataBytes() const { return std::uint64_t(dims.count()) * sizeOf(type); }
};

/// The largest header the parsers look at: a header that does not end within it is an error.
inline constexpr std::size_t kMaxHeaderBytes = std::size_t(1) << 20;

// Each parser gets `head`, the first bytes of a file of `fileSize` bytes (head.size() <=
// fileSize). It returns std::nullopt when the header does not end within `head` and the file
// is longer (the caller reads more and calls again), the layout otherwise, and throws
// HeaderError for a malformed header or, when the voxels are in the same file and stored raw,
// a file shorter than the header announces. They never read outside `head`.

/// MetaImage (.mha, .mhd), as MetaIO reads it: "Key = Value" lines up to ElementDataFile.
std::optional<DataLayout> parseMetaImageHeader(std::string_view head, std::uint64_t fileSize);

/// NRRD (.nrrd, .nhdr), after the NRRD file format specification (NRRD0001 to NRRD0005).
std::optional<DataLayout> parseNrrdHeader(std::string_view head, std::uint64_t fileSize);

/// A single-file NIfTI-1 image (.nii), after the NIfTI-1 header (nifti1.h). NIfTI-2 headers,
/// and NIfTI-1 headers whose voxels are in a separate .img file, are left to ITK
/// (decodeReason); a header without the NIfTI magic is an error.
std::optional<DataLayout> parseNifti1Header(std::string_view head, std::uint64_t fileSize);

/// The two affines of a NIfTI-1 header, voxel index to RAS millimetres, rows of [M | t]
/// (nifti1.h, methods 2 and 3): the qform (quaternion, pixdim, qfac, offsets) and the sform
/// (srow_x..z). Only when both codes are > 0: a reader then has to choose (ITK and nibabel may
/// choose differently), which is worth a word to the user.
struct NiftiForms {
  std::array<std::array<double, 4>, 3> qform{}, sform{};
};
std::optional<NiftiForms> niftiForms(std::string_view head);

}  // namespace surftrack::io
