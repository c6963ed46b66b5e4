// Reading scalar volumes from medical and microscopy image files into the engine's DenseImage,
// with their physical geometry. ITK does the reading (NIfTI, NRRD, MetaImage, DICOM, ...); it
// is confined to io/*.cpp so that nothing else pays for its headers. A raw file, whose layout
// the caller states, is read without ITK.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>

#include "Image.h"
#include "ScalarType.h"

namespace surftrack::io {

using surftrack::ScalarType;
using surftrack::parseScalarType;
using surftrack::sizeOf;
using surftrack::toString;

/// A volume of one of the ten scalar types.
using AnyVolume = std::variant<DenseImage<std::uint8_t>, DenseImage<std::int8_t>,
                               DenseImage<std::uint16_t>, DenseImage<std::int16_t>,
                               DenseImage<std::uint32_t>, DenseImage<std::int32_t>,
                               DenseImage<std::uint64_t>, DenseImage<std::int64_t>,
                               DenseImage<float>, DenseImage<double>>;

/// "uint8, int8, uint16, int16, uint32, int32, uint64, int64, float or double": the voxel types
/// a volume may have (one scalar per voxel), for messages.
std::string supportedTypesText();

ScalarType scalarTypeOf(const AnyVolume& volume);
const Dims& dimsOf(const AnyVolume& volume);
const ImageGeometry& geometryOf(const AnyVolume& volume);
ImageGeometry& geometryOf(AnyVolume& volume);

/// Any failure to read a volume (missing, unreadable, truncated or malformed file, unsupported
/// voxel type). The message is one line and names the file.
class ReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How to read a volume file.
struct ReadOptions {
  /// The channel to read, from 0, of a stack of several channels: a TIFF whose ImageJ or OME
  /// metadata announces them (io/TiffStack.h). Such a stack is a ReadError without one; any
  /// other file has one channel, 0.
  std::optional<int> channel;
};

/// Reads a volume with ITK. `path` is a file in a format ITK recognises (.nii, .nii.gz, .nrrd,
/// .nhdr, .mha, .mhd, a single DICOM file, .tif, ...) or a directory holding one DICOM series.
/// 2D images become one slice. A TIFF stack with ImageJ or OME metadata gives the slices of one
/// channel and the voxel size the metadata states. Throws ReadError.
AnyVolume readVolume(const std::string& path, const ReadOptions& options = {});

/// The layout of a headerless raw file: x fastest, then y, then z.
struct RawLayout {
  Dims dims;
  ScalarType type = ScalarType::UInt8;
  bool bigEndian = false;
  std::size_t headerBytes = 0;  ///< bytes to skip at the start of the file
  ImageGeometry geometry;
};

/// Reads a raw file. The file must hold exactly headerBytes + nx*ny*nz*sizeof(type) bytes.
/// Throws ReadError.
AnyVolume readRawVolume(const std::string& path, const RawLayout& layout);

/// Writes a volume with ITK, in the format of the file name's extension (used by the tests and
/// by the demo to leave its phantom next to the mesh). Throws std::runtime_error.
void writeVolume(const AnyVolume& volume, const std::string& path);
/// The same, compressed if `compress` and the format can be (NRRD: gzip encoding, MetaImage:
/// CompressedData; a .nii.gz is gzip'd whatever `compress` says).
void writeVolume(const AnyVolume& volume, const std::string& path, bool compress);

/// Writes a uint8 or uint16 volume as a DICOM series, one file per slice z in `directory`
/// (which must exist), with each slice's position, the orientation and the spacing (tests).
void writeDicomSeries(const AnyVolume& volume, const std::string& directory);

}  // namespace surftrack::io
