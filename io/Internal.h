// The seams between io/'s translation units, not part of its API: what the loader
// (io/LoadVolume.cpp) asks of the ITK half (io/ReadVolume.cpp, the one file that includes ITK)
// and of the raw-file half (io/Volume.cpp). No ITK types appear here.
#pragma once

#include <cstdint>
#include <string>

#include "LoadVolume.h"
#include "ReadVolume.h"

namespace surftrack::io::detail {

/// A header as ITK reads it, without the voxels: the dimensions, the voxel type and the
/// geometry exactly as readVolume would give them (the same ImageIO, the same
/// itk::ImageFileReader up to its output information), and the byte order the ImageIO reports.
struct ItkHeader {
  Dims dims;
  ScalarType type = ScalarType::UInt8;
  ImageGeometry geometry;
  enum class ByteOrder { Little, Big, Unknown } byteOrder = ByteOrder::Unknown;
};

/// Reads the header of `path` with ITK; the checks and ReadErrors of readVolume.
ItkHeader readItkHeader(const std::string& path);

/// Reads `path` (a file or a directory holding a DICOM series) with ITK once, as readVolume
/// does, and views ITK's own buffer: `owner` keeps the itk::Image alive, nothing is copied (but
/// the chosen channel of a multi-channel TIFF stack, copied out of it). `format` is filled in
/// from the file name or the ImageIO ("dicom", "tiff", "vtk", ...), and `unit`, `channel` and
/// `channels` from a TIFF's ImageJ or OME metadata.
LoadedVolume decodeWithItk(const std::string& path, const ReadOptions& options);

/// ReadError unless `options` chooses a channel the file has (`channels` of them, named by
/// `field` when more than one) or, with one channel, none. The channel to read.
int requireChannel(const std::string& path, const ReadOptions& options, std::int64_t channels, const std::string& field);

/// The checks of readRawVolume on a raw file of `fileSize` bytes: positive dimensions and
/// spacing, and exactly headerBytes + voxel bytes in the file. Throws ReadError.
void requireRawLayout(const std::string& path, const RawLayout& layout, std::uintmax_t fileSize);

}  // namespace surftrack::io::detail
