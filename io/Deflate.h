// Checking a zlib (or gzip) stream before ITK inflates it: ITK 5.2's MetaIO does not report a
// corrupt stream (it leaves the voxels as allocated) and can loop forever on one, so the loader
// inflates MetaImage's compressed voxels once, keeping nothing, before ITK decodes them.
#pragma once

#include <cstdint>

#include "MappedFile.h"

namespace surftrack::io::detail {

/// Bytes [offset, offset + length) of `file` must be a complete zlib or gzip stream (zlib's
/// inflateInit2 with windowBits 47, as MetaIO opens it) that inflates to at least `expected`
/// bytes. Reads and inflates it a chunk at a time, keeping nothing; throws ReadError
/// "<file's context>: corrupt compressed data ..." otherwise.
void requireDeflated(const OpenFile& file, std::uint64_t offset, std::uint64_t length, std::uint64_t expected);

}  // namespace surftrack::io::detail
