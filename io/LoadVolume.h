// Volumes for the engine without a copy: a VolumeView of the voxels where they already are, and
// what keeps that memory alive.
//
// An uncompressed volume whose voxels are stored little-endian (this machine's order) with x
// fastest — a raw file, a MetaImage (.mha, .mhd + its data file), a NRRD (.nrrd, .nhdr + its
// data file, "encoding: raw") or a NIfTI-1 image (.nii) — is memory-mapped read-only and viewed
// in place: opening it reads its header, not its voxels; the pages of voxels the engine
// touches are read from the file when it touches them, and the kernel may drop them again
// under memory pressure. (Voxels at a file offset that is not a multiple of their size — after
// an .mha or .nrrd text header of odd length, say — cannot be viewed as the T* the engine reads:
// they are read into one aligned buffer instead.) A gzip'd NIfTI-1 image (.nii.gz) is inflated
// once, by libdeflate, into the buffer that is viewed (its header parsed and its geometry read
// as a .nii's). Any other volume (compressed NRRD or MetaImage, big-endian multi-byte voxels,
// DICOM, TIFF, VTK, NIfTI-2, ...) is decoded once by ITK into ITK's own buffer, which is viewed
// in place; byte-swapped raw files are read and swapped into
// one buffer. In both cases the geometry and the voxel values are what readVolume gives for
// the same file — which is why a float32/float64 .nii, whose NaN and infinite voxels ITK's
// NIfTI reader (niftilib) reads as 0, is read through once when loaded, to look for them (and
// decoded by ITK if it has any): those files are mapped but not lazy.
//
// A mapped file must not shrink while it is mapped: the size is checked before mapping and
// again just after, but a file truncated later (by another process) makes the next access to
// a lost page raise SIGBUS, which ends the process — surftrack installs no signal handler. Read
// files that other programs may rewrite in place with readVolume (a copy) instead.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ReadVolume.h"
#include "VolumeView.h"

namespace surftrack::io {

struct ChunkedStore;  // io/ChunkedStore.h

/// A volume ready for the engine: a view of its voxels and what keeps their memory alive.
/// Copies share the memory; the view stays valid as long as one copy of `owner` lives (even
/// after the file is deleted: a mapping outlives its file's name).
struct LoadedVolume {
  VolumeView view;                    ///< data, type, dims, strides (x fastest), geometry
  std::shared_ptr<const void> owner;  ///< the mapping, or the decoded buffer (owner.get() == view.data)
  bool mapped = false;                ///< true: the file is memory-mapped, pages are read on demand
  std::string format;  ///< "raw", "mha", "mhd", "nrrd", "nhdr", "nii", "nii.gz", "dicom", "tiff", "vtk", ...
  /// The unit of the spacing when the file states one that is not its format's own: "µm", "nm",
  /// ... from a TIFF's ImageJ or OME metadata; empty otherwise (NIfTI, NRRD, MetaImage, DICOM:
  /// millimetres, as ITK reads them).
  std::string unit;
  int channel = 0;   ///< the channel viewed, of
  int channels = 1;  ///< the channels of a multi-channel TIFF stack (ReadOptions::channel)
  std::uintmax_t dataBytes = 0;  ///< bytes of voxel data (nx ny nz sizeof(type); decompressed size if compressed)
  /// Why the voxels were decoded or read rather than mapped in place (empty when mapped):
  /// "its voxels are gzip-encoded", "its voxels at byte 301 are not aligned to their 2-byte
  /// int16 values", ...
  std::string decodeReason;
  /// The frame of the geometry's physical coordinates: "LPS" as ITK reads every format (x
  /// towards the patient's left, y posterior, z superior); the CLI's --frame ras makes it "RAS",
  /// nibabel's and MNI's convention (x and y negated).
  std::string frame = "LPS";
  /// Things the reader of the file should know about its geometry, one line each (a NIfTI
  /// whose qform and sform disagree).
  std::vector<std::string> warnings;

  /// Bytes of voxel data resident in memory now: for a mapping, the pages that mincore()
  /// reports resident — on Linux that is the file's pages in the page cache, whether or not
  /// this process has touched them, so a file just written or read by anyone counts as
  /// resident until the kernel evicts it; what the figure says is how much of the volume the
  /// engine can read without waiting for the disk. dataBytes when decoded (the buffer is
  /// ordinary memory), 0 if mincore() fails.
  std::uintmax_t residentBytes() const;

  /// How the engine is about to read a mapped volume. Sparse — a seeded extraction, which reads
  /// 8^3 bricks near one surface — turns the kernel's read-around off (MADV_RANDOM), so that a
  /// page fault reads its own page and not the 128 KiB or more around it: on a large volume
  /// that is the difference between reading the surface's pages and reading a good part of
  /// the file. Dense (the default of a mapping; scans, statistics) restores the read-around,
  /// which suits rows read in order. No effect on a decoded volume or if madvise fails.
  enum class Access { Dense, Sparse };
  void advise(Access access) const;
};

/// Loads a volume, the format from the file name: .mha, .mhd, .nrrd, .nhdr and .nii are
/// mapped when they can be (their headers read by this library's own strict parsers, their
/// geometry by ITK), .nii.gz inflated by libdeflate when it can be, anything else ITK reads (see
/// readVolume: a multi-channel TIFF stack needs options.channel), including a directory holding
/// one DICOM series. Throws ReadError with one line naming the file: missing, unreadable,
/// malformed header, a file shorter than its header announces ("truncated file?"), unsupported
/// voxel type.
LoadedVolume loadVolume(const std::string& path, const ReadOptions& options = {});

/// Loads a headerless raw file (see RawLayout). The file must hold exactly headerBytes +
/// nx ny nz sizeof(type) bytes. Mapped when its voxels are little-endian (or one byte each) and
/// headerBytes is a multiple of the voxel size; read into one buffer (and byte-swapped)
/// otherwise. Throws ReadError, with readRawVolume's messages.
LoadedVolume loadRawVolume(const std::string& path, const RawLayout& layout);

/// The bytes and chunks a whole chunked store took to load.
struct ChunkedLoadCounts {
  std::uint64_t chunks = 0;         ///< chunks decoded
  std::uint64_t missingChunks = 0;  ///< of which the store holds no file (the fill value)
  std::uint64_t bytesRead = 0;      ///< from storage
};

/// Loads a chunked store (openChunkedStore, io/ChunkedStore.h) whole: every chunk decoded
/// through its provider's read(), on `threads` threads (0: every core), into one buffer, x
/// fastest. format "zarr", "ome-zarr" or "n5", unit (OME-Zarr's), channel and channels (the
/// channel axis's, if any); decodeReason says the chunks were decoded. Throws the provider's
/// ReadError (the first chunk that fails).
LoadedVolume loadChunkedStore(const ChunkedStore& store, int threads = 0, ChunkedLoadCounts* counts = nullptr);

}  // namespace surftrack::io
