// zlib and gzip streams in volume files. Checking one before ITK inflates it: ITK 5.2's MetaIO
// does not report a corrupt stream (it leaves the voxels as allocated) and can loop forever on
// one, so the loader inflates MetaImage's compressed voxels once, keeping nothing, before ITK
// decodes them. Decoding a gzip'd file (a .nii.gz) once, into the buffer the engine reads:
// ITK's NIfTI reader inflates through niftilib's small gzread calls and copies the result; one
// libdeflate call into the final buffer takes a fifth to a seventh of its time on the demo's
// MRI (docs/performance.md).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "MappedFile.h"

namespace surftrack::io::detail {

/// Bytes [offset, offset + length) of `file` must be a complete zlib or gzip stream (zlib's
/// inflateInit2 with windowBits 47, as MetaIO opens it) that inflates to at least `expected`
/// bytes. Reads and inflates it a chunk at a time, keeping nothing; throws ReadError
/// "<file's context>: corrupt compressed data ..." otherwise.
void requireDeflated(const OpenFile& file, std::uint64_t offset, std::uint64_t length, std::uint64_t expected);

/// Whether `file` starts with the gzip magic bytes (1f 8b).
bool isGzip(const OpenFile& file);

/// Inflates the gzip members of `file` (zlib) into out[0 .. bytes): the count inflated, fewer
/// than `bytes` when the members (or the file) end first. Bytes after a member that do not
/// start another are ignored, as gzread ignores them. With `checkRest`, the members after the
/// first `bytes` are inflated too, their output discarded, so that damage anywhere is an error
/// (as readVolume finds it); without, inflation stops there. Throws ReadError "<context>:
/// corrupt compressed data (...)".
std::size_t inflateGzipPrefix(const OpenFile& file, unsigned char* out, std::size_t bytes, bool checkRest);

/// Where inflateGzip puts the inflated bytes: `data` points at byte 0 of them, `owner` keeps
/// the buffer alive (data - owner.get() < 64).
struct Inflated {
  std::shared_ptr<void> owner;
  unsigned char* data = nullptr;
};

/// Inflates the gzip members of `file` (one or more, as gzip and bgzip write them) with
/// libdeflate into a new buffer of exactly `bytes` bytes (on 2 MiB pages from 1 MiB on), byte
/// `alignedAt` of them on a 64-byte boundary. Members that hold more than `bytes` are read as
/// readVolume reads them: the first `bytes` kept, the rest checked (inflateGzipPrefix takes
/// over then); bytes after a member that do not start another are ignored. Throws ReadError:
/// corrupt compressed data, or fewer than `bytes` bytes ("truncated file?").
Inflated inflateGzip(const OpenFile& file, std::uint64_t bytes, std::uint64_t alignedAt);

}  // namespace surftrack::io::detail
