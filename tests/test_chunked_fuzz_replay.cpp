// The chunked-store fuzzers' kept findings and corpus (fuzz/findings/<format>/ and
// fuzz/corpus/<format>/ for zarr, n5, omezarr, blosc, zstd and gzip; fuzz/run_fuzzers.sh) and
// their seeds (stores and chunks written by zarr-python and numcodecs, fuzz/make_store_seeds.py,
// run by tests/CMakeLists.txt) replayed through this build by the fuzz target's own code
// (fuzz/ChunkedStoreFuzz.h): each input is refused with a one-line ReadError or read, chunk by
// chunk and through the chunk cache, with the provider, the cache and the reference decoders
// agreeing; every seed, a valid store or chunk, is read whole. A finding once crashed, hung or
// broke one of these; a crash or hang would stop this test, the sanitized suite (scripts/
// ci-checks.sh sanitize) reports the memory errors the fuzzer's sanitizers did.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include "../fuzz/ChunkedStoreFuzz.h"

namespace fs = std::filesystem;

namespace {

std::string contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(ChunkedFuzzReplay, CorpusAndFindings) {
  std::string scratch = (fs::temp_directory_path() / "surftrack-fuzz-replay-XXXXXX").string();
  ASSERT_NE(::mkdtemp(scratch.data()), nullptr);
  std::map<std::string, int> replayed;
  int findings = 0, seeds = 0;
  for (const std::string kind : {"seeds", "corpus", "findings"})
    for (const char* format : surftrack::fuzz::kChunkedFuzzFormats) {
      const fs::path dir = (kind == "seeds" ? fs::path(SURFTRACK_STORE_SEEDS) : fs::path(SURFTRACK_FUZZ_DIR) / kind) / format;
      if (!fs::is_directory(dir)) continue;
      for (const auto& entry : fs::directory_iterator(dir)) {
        SCOPED_TRACE(entry.path().string());
        try {
          surftrack::fuzz::runChunkedFuzzInput(format, contents(entry.path()), scratch, kind == "seeds");
        } catch (const surftrack::fuzz::FuzzFinding& f) {
          ADD_FAILURE() << f.what;
        }
        ++replayed[format];
        findings += kind == "findings";
        seeds += kind == "seeds";
      }
    }
  std::error_code ec;
  fs::remove_all(scratch, ec);
  for (const char* format : surftrack::fuzz::kChunkedFuzzFormats)
    EXPECT_GT(replayed[format], 0) << format << ": no input (make_store_seeds.py needs python3-zarr and python3-numcodecs)";
  EXPECT_GT(findings, 0) << SURFTRACK_FUZZ_DIR "/findings holds no chunked-store finding";
  int total = 0;
  for (const auto& [format, n] : replayed) total += n;
  std::printf("[          ] %d inputs replayed: %d seeds, %d kept findings\n", total, seeds, findings);
}
