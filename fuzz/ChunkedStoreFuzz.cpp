// One fuzz input through the chunked-store readers (ChunkedStoreFuzz.h). A store is read as a
// user's tool reads it: recognised (isChunkedStore), opened (openChunkedStore), every chunk
// decoded by the provider (a sample when there are many), then read again through the core's
// ChunkCache and chunked VoxelSource, whose gray values must be the provider's. Arrays whose
// chunks decode to more than 4 MiB are opened but not read: the readers accept chunks of up to
// 2 GiB (io/ChunkGrid.h), which a fuzzer's memory limit cannot hold.
#include "ChunkedStoreFuzz.h"

#include <cxxabi.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <memory>
#include <typeinfo>
#include <vector>

#include "ChunkCodecs.h"
#include "ChunkGrid.h"
#include "ChunkedSource.h"
#include "ChunkedStore.h"
#include "Errors.h"
#include "ReadVolume.h"

namespace surftrack::fuzz {

namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kMaxChunkBytes = std::uint64_t(4) << 20;   // a decoded chunk read, whole
constexpr std::uint64_t kMaxBytesRead = std::uint64_t(8) << 20;    // all the chunks of one input
constexpr std::uint64_t kMaxChunks = 256;                          // chunks read per input
constexpr std::size_t kMaxDecoded = (std::size_t(1) << 20) - 1;    // codec inputs: decoded sizes

[[noreturn]] void finding(const std::string& what) { throw FuzzFinding{what}; }

bool gValid = false;  // the input is a valid store or chunk: a ReadError is a finding

/// `text` with its control bytes escaped, for a finding's message.
std::string printable(std::string_view text) {
  std::string s;
  for (unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f) {
      s += char(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      s += hex;
    }
  }
  return s;
}

std::string typeName(const std::exception& e) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> name(abi::__cxa_demangle(typeid(e).name(), nullptr, nullptr, &status), std::free);
  return status == 0 && name ? name.get() : typeid(e).name();
}

/// The readers' errors are one line (docs/api.md, "Chunked stores").
void requireOneLine(const std::exception& e, const char* where) {
  const std::string_view what = e.what();
  if (what.empty() || what.find_first_of("\n\r") != std::string_view::npos)
    finding(std::string(where) + ": an error message that is not one line: " + printable(what));
}

/// Runs `f`; true if it returned, false for a ReadError (one line). Any other exception is a
/// finding.
template <class F>
bool readOrRefuse(const char* where, F&& f) {
  try {
    f();
    return true;
  } catch (const io::ReadError& e) {
    requireOneLine(e, where);
    if (gValid) finding(std::string(where) + " refuses a valid input: " + printable(e.what()));
    return false;
  } catch (const FuzzFinding&) {
    throw;
  } catch (const std::exception& e) {
    finding(std::string(where) + " threw " + typeName(e) + ": " + printable(e.what()));
  } catch (...) {
    finding(std::string(where) + " threw an exception that is not a std::exception");
  }
}

// --- stores ---------------------------------------------------------------------------------

bool validName(std::string_view name) {
  if (name.empty() || name.size() > 100) return false;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    const std::string_view part = name.substr(start, end - start);
    if (part.empty() || part == "." || part == "..") return false;
    for (char c : part)
      if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-'))
        return false;
    if (end == name.size()) return true;
    start = end + 1;
  }
}

void writeStoreFile(const fs::path& store, std::string_view name, std::string_view bytes) {
  const fs::path path = store / fs::path(std::string(name));
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  if (ec || fs::is_directory(path, ec)) return;  // a place taken: not written
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

/// "level=1 channel=0 time=2": what each option is set to; other words are ignored.
void parseOptions(std::string_view text, io::ChunkedStoreOptions& options) {
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find_first_of(" \n\t", at), text.size());
    const std::string_view word = text.substr(at, end - at);
    at = end + 1;
    const std::size_t eq = word.find('=');
    if (eq == std::string_view::npos) continue;
    std::int64_t value = 0;
    const std::string_view key = word.substr(0, eq), number = word.substr(eq + 1);
    const auto r = std::from_chars(number.data(), number.data() + number.size(), value);
    if (r.ec != std::errc() || r.ptr != number.data() + number.size()) continue;
    if (key == "level" && value >= INT32_MIN && value <= INT32_MAX) options.level = int(value);
    if (key == "channel") options.channel = value;
    if (key == "time") options.time = value;
  }
}

io::ChunkedStoreOptions unpackStore(std::string_view format, std::string_view input, const fs::path& store) {
  io::ChunkedStoreOptions options;
  std::string_view name = format == "zarr" ? ".zarray" : format == "n5" ? "attributes.json" : ".zattrs";
  std::size_t at = 0;
  while (true) {
    const std::size_t next = input.find(kFileMarker, at);
    const std::string_view bytes = input.substr(at, next == std::string_view::npos ? std::string_view::npos : next - at);
    if (name == "!options")
      parseOptions(bytes, options);
    else if (validName(name))
      writeStoreFile(store, name, bytes);
    if (next == std::string_view::npos) break;
    const std::size_t nameStart = next + kFileMarker.size(), nameEnd = input.find('\n', nameStart);
    if (nameEnd == std::string_view::npos) break;  // a name without its line's end: no file
    name = input.substr(nameStart, nameEnd - nameStart);
    at = nameEnd + 1;
  }
  return options;
}

/// Voxel `i` of `bytes` (voxels of `type`) as the engine's double.
double valueAt(const std::vector<unsigned char>& bytes, std::size_t i, ScalarType type) {
  double d = 0;
  visitScalarType(type, [&](auto zero) {
    decltype(zero) v;
    std::memcpy(&v, bytes.data() + i * sizeof v, sizeof v);
    d = double(v);
  });
  return d;
}

bool sameValue(double a, double b) { return a == b || (a != a && b != b); }

struct ReadChunk {
  Voxel index;
  Dims extent;
  std::vector<unsigned char> bytes;
};

void runStore(std::string_view format, std::string_view input, const fs::path& scratch) {
  const fs::path store = scratch / "store";
  std::error_code ec;
  fs::remove_all(store, ec);
  fs::create_directories(store);
  const io::ChunkedStoreOptions options = unpackStore(format, input, store);

  bool recognised = false;
  try {
    recognised = io::isChunkedStore(store.string());
  } catch (...) {
    finding("isChunkedStore threw (it never throws)");
  }
  io::ChunkedStore opened;
  if (!readOrRefuse("openChunkedStore", [&] { opened = io::openChunkedStore(store.string(), options); })) return;
  if (!recognised) finding("openChunkedStore opens a store that isChunkedStore does not recognise");
  if (!opened.provider) finding("openChunkedStore gives no provider");
  if (opened.level < 0 || opened.level >= opened.levels) finding("openChunkedStore gives level " + std::to_string(opened.level) + " of " + std::to_string(opened.levels));

  const ChunkProvider& provider = *opened.provider;
  const ChunkLayout layout = provider.layout();
  if (int(layout.type) < int(ScalarType::UInt8) || int(layout.type) > int(ScalarType::Float64)) finding("a layout of no scalar type");
  for (int a = 0; a < 3; ++a)
    if (layout.dims[a] < 1 || layout.chunk[a] < 1 || layout.chunk[a] > layout.dims[a])
      finding("a layout of dims " + std::to_string(layout.dims[a]) + " and chunk " + std::to_string(layout.chunk[a]) + " on axis " + std::to_string(a));
  for (int e = 0; e < 3; ++e)
    if (!(std::isfinite(layout.geometry.spacing[e]) && layout.geometry.spacing[e] > 0) || !std::isfinite(layout.geometry.origin[e]))
      finding("a geometry that is not finite: spacing " + std::to_string(layout.geometry.spacing[e]) + ", origin " +
              std::to_string(layout.geometry.origin[e]) + " on axis " + std::to_string(e));
  const auto* grid = dynamic_cast<const io::detail::GridProvider*>(&provider);
  if (!grid) finding("the provider is not a GridProvider");
  const std::size_t voxel = sizeOf(layout.type);
  if (io::detail::chunkBytes(grid->grid()) > kMaxChunkBytes || layout.chunk.count() * voxel > kMaxChunkBytes) return;

  // The chunks read: all of them, or the corners and an even sample.
  const Dims counts = layout.chunkCounts();
  const std::uint64_t total = std::uint64_t(counts.count());
  const auto indexOf = [&](std::uint64_t k) {
    return Voxel{int(k % std::uint64_t(counts.nx)), int(k / std::uint64_t(counts.nx) % std::uint64_t(counts.ny)),
                 int(k / std::uint64_t(counts.nx) / std::uint64_t(counts.ny))};
  };
  std::vector<Voxel> indices;
  if (total <= kMaxChunks) {
    for (std::uint64_t k = 0; k < total; ++k) indices.push_back(indexOf(k));
  } else {
    for (int c = 0; c < 8; ++c)
      indices.push_back({c & 1 ? counts.nx - 1 : 0, c & 2 ? counts.ny - 1 : 0, c & 4 ? counts.nz - 1 : 0});
    for (std::uint64_t k = 0; k < kMaxChunks - 8; ++k) indices.push_back(indexOf(k * (total / (kMaxChunks - 8))));
  }
  const std::vector<unsigned char>& fill = grid->grid().fill;
  std::vector<ReadChunk> kept;  // the first chunks read, for the cache's reads
  std::uint64_t budget = kMaxBytesRead;
  bool readTwice = false;
  for (const Voxel index : indices) {
    const Dims extent = layout.extentOf(index);
    const std::size_t bytes = extent.count() * voxel;
    if (bytes > budget) break;
    budget -= bytes;
    // Exactly the chunk's bytes: AddressSanitizer reports a write past them.
    std::vector<unsigned char> out(bytes);
    std::uint64_t stored = 0;
    if (!readOrRefuse("ChunkProvider::read", [&] { stored = provider.read(index, out.data()); })) continue;
    if (stored == 0)
      for (std::size_t i = 0; i < extent.count(); ++i)
        if (std::memcmp(out.data() + i * voxel, fill.data(), voxel) != 0) finding("a missing chunk that does not hold the fill value");
    if (!readTwice) {  // the same bytes read again
      readTwice = true;
      std::vector<unsigned char> again(bytes);
      std::uint64_t storedAgain = 0;
      if (!readOrRefuse("ChunkProvider::read", [&] { storedAgain = provider.read(index, again.data()); }) ||
          storedAgain != stored || again != out)
        finding("a chunk read twice gives two answers");
    }
    if (kept.size() < 4) kept.push_back({index, extent, std::move(out)});
  }

  // The core: a cache of 1 MiB and the chunked source over it, whose gray values are the
  // provider's voxels.
  std::shared_ptr<const ChunkCache> cache;
  try {
    cache = std::make_shared<const ChunkCache>(opened.provider, std::size_t(1) << 20);
  } catch (const InvalidInput& e) {  // dimensions beyond the surfel keys' 20 bits
    requireOneLine(e, "ChunkCache");
    if (gValid) finding(std::string("ChunkCache refuses a valid store: ") + printable(e.what()));
    return;
  } catch (const std::exception& e) {
    finding("ChunkCache threw " + typeName(e) + ": " + printable(e.what()));
  }
  const std::unique_ptr<VoxelSource> source = makeChunkedSource(cache);
  if (source->dims() != layout.dims || source->type() != layout.type) finding("the chunked source's dims or type are not the store's");
  std::vector<Voxel> voxels{{-1, 0, 0}, {layout.dims.nx, layout.dims.ny - 1, 0}};
  std::vector<double> expected{0, 0};  // outside the domain: 0-voxels
  for (const ReadChunk& c : kept) {
    const Voxel origin{c.index.x * layout.chunk.nx, c.index.y * layout.chunk.ny, c.index.z * layout.chunk.nz};
    for (const Voxel local : {Voxel{0, 0, 0}, Voxel{c.extent.nx - 1, c.extent.ny - 1, c.extent.nz - 1},
                              Voxel{c.extent.nx / 2, c.extent.ny / 2, c.extent.nz / 2}}) {
      voxels.push_back(origin + local);
      expected.push_back(valueAt(c.bytes, (std::size_t(local.z) * c.extent.ny + local.y) * c.extent.nx + local.x, layout.type));
    }
  }
  std::vector<double> got(voxels.size());
  try {
    source->values(voxels.data(), voxels.size(), got.data());
  } catch (const std::exception& e) {
    finding("the chunked source cannot read chunks the provider read: " + typeName(e) + ": " + printable(e.what()));
  }
  for (std::size_t i = 0; i < voxels.size(); ++i)
    if (!sameValue(got[i], expected[i]))
      finding("the chunked source reads " + std::to_string(got[i]) + " at (" + std::to_string(voxels[i].x) + ", " +
              std::to_string(voxels[i].y) + ", " + std::to_string(voxels[i].z) + ") where the provider gives " +
              std::to_string(expected[i]));
  // A row and a block from the first voxel, as the scanner and the tracker read them.
  readOrRefuse("binaryRow", [&] { source->binaryRow(Selection::threshold(0), {0, 0, 0}, std::min(64, layout.dims.nx + 1)); });
  readOrRefuse("binaryBlock", [&] {
    std::vector<std::uint16_t> block(10 * 10);
    source->binaryBlock(Selection::threshold(0.5), {-1, -1, -1}, 16, 10, 10, block.data());
  });
}

// --- codecs ---------------------------------------------------------------------------------

/// zlib's own inflate of what decodeChunk gives libdeflate: one zlib stream, or gzip members
/// while the chunk is not full (io/ChunkCodecs.cpp). True if it decodes to exactly `expected`
/// bytes (into out, which has room for one more).
bool inflateWithZlib(bool gzip, const unsigned char* in, std::size_t size, std::vector<unsigned char>& out, std::size_t expected) {
  out.assign(expected + 1, 0);
  std::size_t used = 0, made = 0;
  do {
    z_stream s{};
    if (inflateInit2(&s, gzip ? 16 + 15 : 15) != Z_OK) throw std::bad_alloc();
    s.next_in = const_cast<unsigned char*>(in + used);
    s.avail_in = uInt(size - used);
    s.next_out = out.data() + made;
    s.avail_out = uInt(out.size() - made);
    const int r = inflate(&s, Z_FINISH);
    used += s.total_in;
    made += s.total_out;
    inflateEnd(&s);
    if (r != Z_STREAM_END) return false;
  } while (gzip && made < expected && size - used >= 2 && in[used] == 0x1f && in[used + 1] == 0x8b);
  return made == expected;
}

void runCodec(std::string_view format, std::string_view input) {
  if (input.size() < 4) return;
  const auto* p = reinterpret_cast<const unsigned char*>(input.data());
  const std::uint32_t header = std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
  const std::size_t expected = header & kMaxDecoded, size = input.size() - 4;
  using Kind = io::detail::ChunkCodec::Kind;
  io::detail::ChunkCodec codec;
  codec.kind = format == "blosc" ? Kind::Blosc : format == "zstd" ? Kind::Zstd : header >> 31 ? Kind::Zlib : Kind::Gzip;
  // The chunk and its voxels in buffers of exactly their size: AddressSanitizer reports a read
  // or write past them (in the uninstrumented libraries too, where they call memcpy).
  const std::unique_ptr<unsigned char[]> in(new unsigned char[std::max<std::size_t>(size, 1)]);
  std::memcpy(in.get(), p + 4, size);
  const std::unique_ptr<unsigned char[]> out(new unsigned char[std::max<std::size_t>(expected, 1)]);
  const bool decoded = readOrRefuse("decodeChunk", [&] { io::detail::decodeChunk(codec, in.get(), size, out.get(), expected, "chunk"); });

  std::vector<unsigned char> reference;
  bool referenceDecoded = false;
  if (codec.kind == Kind::Zstd) {
    // libzstd itself, with room for one byte more: it decodes to exactly `expected` bytes or
    // decodeChunk must refuse it.
    reference.assign(expected + 1, 0);
    const std::size_t made = ZSTD_decompress(reference.data(), reference.size(), in.get(), size);
    referenceDecoded = !ZSTD_isError(made) && made == expected;
    if (decoded != referenceDecoded)
      finding(std::string("decodeChunk ") + (decoded ? "decodes" : "refuses") + " zstd data that libzstd " +
              (referenceDecoded ? "decodes" : "refuses"));
  } else if (codec.kind == Kind::Zlib || codec.kind == Kind::Gzip) {
    const bool gzip = codec.kind == Kind::Gzip;
    referenceDecoded = inflateWithZlib(gzip, in.get(), size, reference, expected);
    if (referenceDecoded && !decoded) finding(std::string("libdeflate refuses ") + (gzip ? "gzip" : "zlib") + " data zlib decodes");
    // libdeflate skips a gzip header's CRC (FHCRC), which zlib checks: the one leniency allowed.
    if (decoded && !referenceDecoded && !(gzip && size > 3 && (in[3] & 0x02)))
      finding(std::string("libdeflate decodes ") + (gzip ? "gzip" : "zlib") + " data zlib refuses");
  }
  if (decoded && referenceDecoded && std::memcmp(out.get(), reference.data(), expected) != 0)
    finding("decodeChunk and the reference decoder give different bytes");
}

}  // namespace

bool isChunkedFuzzFormat(std::string_view format) {
  for (const char* f : kChunkedFuzzFormats)
    if (format == f) return true;
  return false;
}

void runChunkedFuzzInput(std::string_view format, std::string_view input, const fs::path& scratch, bool valid) {
  gValid = valid;
  if (format == "zarr" || format == "n5" || format == "omezarr")
    runStore(format, input, scratch);
  else if (isChunkedFuzzFormat(format))
    runCodec(format, input);
  else
    throw std::invalid_argument("runChunkedFuzzInput: no format '" + std::string(format) + "'");
}

}  // namespace surftrack::fuzz
