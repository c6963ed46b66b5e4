// A test tool for the chunked-store readers (io/ChunkedStore.h), for tests/test_chunked_readers.py:
// opens a store, decodes every chunk through ChunkProvider::read() (loadChunkedStore, on several
// threads, as ChunkCache does) and writes the whole volume into a raw file, x fastest, in the
// machine's byte order; prints the layout and what was chosen as JSON on stdout. Errors: one
// line on stderr, exit status 1.
//   chunk_dump STORE OUT.raw [--level N] [--channel C] [--time T] [--threads K]
//   chunk_dump --probe PATH      prints whether isChunkedStore(PATH): true or false
#include <fstream>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "ChunkedStore.h"
#include "LoadVolume.h"

using namespace surftrack;

namespace {

int run(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--probe") {
    std::cout << (io::isChunkedStore(argv[2]) ? "true" : "false") << "\n";
    return 0;
  }
  if (argc < 3) throw std::invalid_argument("usage: chunk_dump STORE OUT.raw [--level N] [--channel C] [--time T] [--threads K]");
  io::ChunkedStoreOptions options;
  int threads = 3;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    const long long v = std::stoll(argv[i + 1]);
    if (flag == "--level") options.level = int(v);
    else if (flag == "--channel") options.channel = v;
    else if (flag == "--time") options.time = v;
    else if (flag == "--threads") threads = int(v);
    else throw std::invalid_argument("unknown option " + flag);
  }
  const io::ChunkedStore store = io::openChunkedStore(argv[1], options);
  io::ChunkedLoadCounts counts;
  const io::LoadedVolume volume = io::loadChunkedStore(store, threads, &counts);
  const ChunkLayout& layout = store.provider->layout();
  const Dims d = layout.dims, c = layout.chunk;
  std::ofstream out(argv[2], std::ios::binary);
  out.write(static_cast<const char*>(volume.view.data), std::streamsize(volume.dataBytes));
  if (!out) throw std::runtime_error(std::string("cannot write ") + argv[2]);

  nlohmann::json report = {
      {"format", store.format},          {"array", store.arrayPath},
      {"dtype", store.dtype},            {"compressor", store.compressor},
      {"unit", store.unit},              {"type", toString(layout.type)},
      {"dims", {d.nx, d.ny, d.nz}},      {"chunk", {c.nx, c.ny, c.nz}},
      {"chunks", counts.chunks},         {"missing_chunks", counts.missingChunks},
      {"bytes_read", counts.bytesRead},  {"spacing", layout.geometry.spacing},
      {"origin", layout.geometry.origin}, {"direction", layout.geometry.direction},
      {"level", store.level},            {"levels", store.levels},
      {"choice", store.choiceText()},    {"chosen", nlohmann::json::array()}};
  for (const io::AxisChoice& a : store.chosen) report["chosen"].push_back({{"name", a.name}, {"index", a.index}, {"size", a.size}});
  report["channel"] = volume.channel;
  report["channels"] = volume.channels;
  if (volume.view.dims != d || volume.view.type != layout.type) throw std::logic_error("the loaded volume is not the store's");
  std::cout << report.dump() << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "chunk_dump: error: " << e.what() << "\n";
    return 1;
  }
}
