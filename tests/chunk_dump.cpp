// A test tool for the chunked-store readers (io/ChunkedStore.h), for tests/test_chunked_readers.py:
// opens a store, decodes every chunk through ChunkProvider::read() (on several threads, as
// ChunkCache does) and writes the whole volume into a raw file, x fastest, in the machine's byte
// order; prints the layout and what was chosen as JSON on stdout. Errors: one line on stderr,
// exit status 1.
//   chunk_dump STORE OUT.raw [--level N] [--channel C] [--time T] [--threads K]
//   chunk_dump --probe PATH      prints whether isChunkedStore(PATH): true or false
#include <atomic>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "ChunkedStore.h"

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
  const ChunkLayout& layout = store.provider->layout();
  const Dims d = layout.dims, c = layout.chunk;
  const Dims counts{(d.nx + c.nx - 1) / c.nx, (d.ny + c.ny - 1) / c.ny, (d.nz + c.nz - 1) / c.nz};
  const std::size_t voxel = sizeOf(layout.type);
  std::vector<unsigned char> volume(d.count() * voxel);

  // Chunks handed out to the threads one at a time; the first error stops them all.
  std::atomic<std::size_t> next{0}, missing{0};
  std::atomic<std::uint64_t> bytesRead{0};
  std::exception_ptr error;
  std::atomic<bool> failed{false};
  const auto work = [&] {
    std::vector<unsigned char> chunk(c.count() * voxel);
    for (std::size_t k; !failed && (k = next++) < counts.count();) {
      const Voxel index{int(k % counts.nx), int(k / counts.nx % counts.ny), int(k / counts.nx / counts.ny)};
      try {
        const std::uint64_t n = store.provider->read(index, chunk.data());
        bytesRead += n;
        missing += n == 0;
      } catch (...) {
        if (!failed.exchange(true)) error = std::current_exception();
        return;
      }
      const Voxel o{index.x * c.nx, index.y * c.ny, index.z * c.nz};
      const int ex = std::min(c.nx, d.nx - o.x), ey = std::min(c.ny, d.ny - o.y), ez = std::min(c.nz, d.nz - o.z);
      for (int z = 0; z < ez; ++z)
        for (int y = 0; y < ey; ++y)
          std::memcpy(volume.data() + ((std::size_t(o.z + z) * d.ny + (o.y + y)) * d.nx + o.x) * voxel,
                      chunk.data() + ((std::size_t(z) * ey + y) * ex) * voxel, std::size_t(ex) * voxel);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::max(1, threads); ++t) pool.emplace_back(work);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);

  std::ofstream out(argv[2], std::ios::binary);
  out.write(reinterpret_cast<const char*>(volume.data()), std::streamsize(volume.size()));
  if (!out) throw std::runtime_error(std::string("cannot write ") + argv[2]);

  nlohmann::json report = {
      {"format", store.format},          {"array", store.arrayPath},
      {"dtype", store.dtype},            {"compressor", store.compressor},
      {"unit", store.unit},              {"type", toString(layout.type)},
      {"dims", {d.nx, d.ny, d.nz}},      {"chunk", {c.nx, c.ny, c.nz}},
      {"chunks", counts.count()},        {"missing_chunks", missing.load()},
      {"bytes_read", bytesRead.load()},  {"spacing", layout.geometry.spacing},
      {"origin", layout.geometry.origin}, {"direction", layout.geometry.direction},
      {"level", store.level},            {"levels", store.levels},
      {"choice", store.choiceText()},    {"chosen", nlohmann::json::array()}};
  for (const io::AxisChoice& a : store.chosen) report["chosen"].push_back({{"name", a.name}, {"index", a.index}, {"size", a.size}});
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
