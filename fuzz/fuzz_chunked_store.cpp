// libFuzzer target: arbitrary bytes as a chunked store or one compressed chunk, of the format
// named by the program's name, fuzz_chunked_store_<format> (one binary, one link to it per
// format, fuzz/CMakeLists.txt): "zarr", "n5" and "omezarr" (a whole store: metadata and chunk
// files, io/ChunkedStore.h), "blosc", "zstd" and "gzip" (a chunk with the size it must decode
// to, io/ChunkCodecs.h). What each input goes through, and what is a finding, is
// fuzz/ChunkedStoreFuzz.h's (the gcc test suite replays the kept findings through the same
// code); here a finding aborts, as a crash, a hang or a sanitizer report does.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "ChunkedStoreFuzz.h"

namespace {

namespace fs = std::filesystem;

std::string gFormat;  // from the program's name, set once by LLVMFuzzerInitialize
fs::path gScratch;    // each input's store is written here

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const std::string name = *argc > 0 ? fs::path((*argv)[0]).filename().string() : "";
  const std::string prefix = "fuzz_chunked_store_";
  gFormat = name.rfind(prefix, 0) == 0 ? name.substr(prefix.size()) : "";
  if (!surftrack::fuzz::isChunkedFuzzFormat(gFormat)) {
    std::fprintf(stderr, "run me as fuzz_chunked_store_<format>, format zarr, n5, omezarr, blosc, zstd or gzip (not '%s')\n",
                 name.c_str());
    std::abort();
  }
  // One directory per process (libFuzzer's -jobs/-workers run several): under /dev/shm when
  // there is one, so that the stores never reach a disk.
  const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
  std::string dir = (base / "surftrack-fuzz-XXXXXX").string();
  if (!::mkdtemp(dir.data())) {
    std::fprintf(stderr, "fuzz_chunked_store: mkdtemp failed\n");
    std::abort();
  }
  gScratch = dir;
  std::atexit([] {
    std::error_code ec;
    fs::remove_all(gScratch, ec);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > (1 << 20)) return 0;
  try {
    surftrack::fuzz::runChunkedFuzzInput(gFormat, std::string_view(reinterpret_cast<const char*>(data), size), gScratch);
  } catch (const surftrack::fuzz::FuzzFinding& f) {
    std::fprintf(stderr, "fuzz_chunked_store (%s): %s\n", gFormat.c_str(), f.what.c_str());
    std::abort();
  }
  return 0;
}
