// What a TIFF file says about the stack it holds, beyond what ITK's TIFF reader reads: the
// ImageJ description ("ImageJ=...\nimages=80\nchannels=2\nslices=40\nspacing=0.3\nunit=micron")
// or the OME-XML (SizeC, SizeZ, DimensionOrder, PhysicalSizeX/Y/Z) in the ImageDescription of
// its first page, and the XResolution and YResolution tags (pixels per unit). ITK reads the
// pages of a multi-page TIFF as the slices of one volume, whatever they are: with two channels
// interleaved along z it reads twice the slices, and it keeps a spacing of 1 where ImageJ
// states its voxel size in the description. readVolume and loadVolume (io/ReadVolume.cpp) use
// this to choose one channel's slices and to give the stated voxel size.
//
// The parser works through a callback that reads bytes of the file and does no other I/O,
// so that fuzz/fuzz_volume_header.cpp can feed it arbitrary bytes.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace surftrack::io {

/// The stack of pages of a TIFF file, as its ImageJ or OME metadata describes it.
struct TiffStack {
  /// "ImageJ" or "OME-TIFF"; empty: neither (a plain TIFF, left to ITK as it reads it).
  std::string source;
  /// The pages are channels x slices x frames images; the channel varies fastest
  /// (ImageJ's order, OME's XYCZT) when channelFirst, the slice otherwise (OME's XYZCT).
  std::int64_t channels = 1, slices = 1, frames = 1;
  bool channelFirst = true;
  std::int64_t width = 0, height = 0;  ///< OME's SizeX, SizeY (0: not stated)
  /// The voxel size in `unit` (x and y from XResolution and YResolution or PhysicalSizeX/Y,
  /// z from ImageJ's spacing or PhysicalSizeZ), when the metadata states it.
  std::optional<std::array<double, 3>> spacing;
  /// "µm", "nm", "mm", "cm", "m", "Å", "inch", another unit as the file names it, or empty:
  /// none stated (ImageJ's "pixel").
  std::string unit;
  /// Where the channel count was read, for messages: "ImageJ channels=2", "OME SizeC=2".
  std::string channelsField;

  std::int64_t pages() const { return channels * slices * frames; }
};

/// Reads up to `bytes` bytes at `offset` of the file (fewer at its end).
using ReadAt = std::function<std::string(std::uint64_t offset, std::size_t bytes)>;

/// The stack described by the first page of a TIFF file of `fileSize` bytes named `fileName`
/// (OME-XML may name the file its planes are in). Throws HeaderError (io/VolumeHeader.h) for
/// a file that is not a TIFF, a page directory or tag outside the file, and ImageJ or OME
/// metadata that is malformed or describes what readVolume cannot give (several images or time
/// points, planes out of order or in other files, interleaved samples).
TiffStack parseTiffStack(const ReadAt& read, std::uint64_t fileSize, std::string_view fileName);

}  // namespace surftrack::io
