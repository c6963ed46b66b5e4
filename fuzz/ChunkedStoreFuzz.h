// What the chunked-store fuzz target (fuzz/fuzz_chunked_store.cpp) does with one input, shared
// with the gcc test suite (tests/test_chunked_fuzz_replay.cpp), which replays the kept findings
// and corpus through exactly this code: one "format" per target name,
//   zarr, n5, omezarr  the input is a whole store (unpackStore below), opened with
//                      io::openChunkedStore and read chunk by chunk, then through the core's
//                      ChunkCache and chunked VoxelSource;
//   blosc, zstd, gzip  the input is one chunk's bytes after a 4-byte header giving the size it
//                      must decode to (io/ChunkCodecs.h), checked against the codec's library
//                      itself (zstd) or zlib (gzip and zlib streams, decoded by libdeflate).
// A finding (a crash or a sanitizer report aside: those stop the process) is thrown as
// FuzzFinding: an exception type the readers never throw, so no handler of theirs catches it.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace surftrack::fuzz {

/// A broken guarantee: an exception the readers do not document, a two-line error message,
/// reads that disagree.
struct FuzzFinding {
  std::string what;
};

/// The formats, in the order fuzz/run_fuzzers.sh runs them.
inline constexpr const char* kChunkedFuzzFormats[] = {"zarr", "n5", "omezarr", "blosc", "zstd", "gzip"};
bool isChunkedFuzzFormat(std::string_view format);

/// A store's files in one input: the first file's bytes, then for each further file a line
/// "\n@@@@ <name>\n" and its bytes. The first file is the format's metadata (.zarray for zarr,
/// attributes.json for n5, the group's .zattrs for omezarr); names are paths relative to the
/// store ("0.0.0", "1/.zarray", "0/1/2"), letters, digits, '.', '_', '-' and '/' between
/// components other than "." and ".."; a file whose name breaks these rules, or whose place is
/// taken (a directory, a file where a directory is needed), is not written. The file named
/// "!options" is not written: it chooses the level, channel and time ("level=1 channel=0").
inline constexpr std::string_view kFileMarker = "\n@@@@ ";

/// Runs one input of `format` (the store written in `scratch`, emptied first). Throws
/// FuzzFinding; the readers' ReadErrors (one line) and the cache's InvalidInput are expected,
/// unless the input is `valid` (a seed): then it must be read whole.
void runChunkedFuzzInput(std::string_view format, std::string_view input, const std::filesystem::path& scratch,
                         bool valid = false);

}  // namespace surftrack::fuzz
