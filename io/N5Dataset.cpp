// `attributes.json` parsed and checked; a block's header read, its voxels decoded, and both
// turned to numpy's axis order (reversed) for the shared chunk grid (io/ChunkGrid.h): a block's
// x-fastest voxels are a C-ordered chunk of the reversed shape.
#include "N5Dataset.h"

#include <algorithm>

#include "ChunkGrid.h"
#include "JsonFile.h"
#include "ReadVolume.h"

namespace surftrack::io {

using detail::ChunkCodec;
using detail::jsonText;
using detail::quotedPath;
using nlohmann::json;

namespace {

ScalarType parseDataType(const json& value, const std::string& context) {
  static constexpr struct {
    const char* name;
    ScalarType type;
  } kTypes[] = {{"uint8", ScalarType::UInt8},   {"int8", ScalarType::Int8},       {"uint16", ScalarType::UInt16},
                {"int16", ScalarType::Int16},   {"uint32", ScalarType::UInt32},   {"int32", ScalarType::Int32},
                {"uint64", ScalarType::UInt64}, {"int64", ScalarType::Int64},     {"float32", ScalarType::Float32},
                {"float64", ScalarType::Float64}};
  for (const auto& t : kTypes)
    if (value == t.name) return t.type;
  throw ReadError(context + ": unsupported dataType " + jsonText(value) +
                  ": surftrack reads uint8, int8, uint16, int16, uint32, int32, uint64, int64, float32 or float64");
}

ChunkCodec parseCompression(const json& m, const std::string& context) {
  json c = m.value("compression", json());
  // Before N5 1.0 the compression was a bare name.
  if (c.is_null() && m.contains("compressionType")) c = json{{"type", m["compressionType"]}};
  const std::string type = c.is_object() && c.contains("type") && c["type"].is_string() ? c["type"].get<std::string>() : "";
  ChunkCodec codec;
  if (type == "raw") {
    codec.description = "none";
  } else if (type == "gzip") {
    const bool zlib = c.contains("useZlib") && c["useZlib"] == true;
    codec.kind = zlib ? ChunkCodec::Kind::Zlib : ChunkCodec::Kind::Gzip;
    codec.description = zlib ? "zlib" : "gzip";
  } else if (type == "zstd") {
    codec.kind = ChunkCodec::Kind::Zstd;
    codec.description = "zstd";
  } else if (type == "blosc") {
    codec.kind = ChunkCodec::Kind::Blosc;
    codec.description = "blosc (" + (c.contains("cname") ? c["cname"].dump() : std::string("?")) + ", shuffle " +
                        (c.contains("shuffle") ? c["shuffle"].dump() : std::string("?")) + ")";
  } else {
    throw ReadError(context + ": unsupported compression " + (type.empty() ? jsonText(c) : quotedPath(type)) +
                    ": surftrack reads raw, gzip, zstd or blosc");
  }
  return codec;
}

std::uint32_t bigEndian32(const unsigned char* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

/// The dataset's blocks: header, then voxels.
class N5Provider final : public detail::GridProvider {
 public:
  N5Provider(detail::ChunkGrid grid, std::string dir, ChunkCodec codec)
      : GridProvider(std::move(grid)), dir_(std::move(dir)), codec_(std::move(codec)) {}

 protected:
  std::string chunkPath(const std::vector<std::int64_t>& coords) const override {
    std::string path = dir_;
    for (auto c = coords.rbegin(); c != coords.rend(); ++c) path += '/' + std::to_string(*c);
    return path;
  }
  Decoded decode(const std::string& stored, const std::string& path, unsigned char* direct) const override {
    const std::string context = "cannot read block " + quotedPath(path);
    const auto* p = reinterpret_cast<const unsigned char*>(stored.data());
    const std::size_t rank = grid().shape.size();
    if (stored.size() < 4) throw ReadError(context + ": the file is shorter than a block header");
    const unsigned mode = unsigned(p[0]) << 8 | p[1], dims = unsigned(p[2]) << 8 | p[3];
    if (mode != 0)
      throw ReadError(context + ": block mode " + std::to_string(mode) + (mode == 1 ? " (varlength)" : "") +
                      ": surftrack reads mode 0 (default) blocks");
    if (dims != rank)
      throw ReadError(context + ": the block has " + std::to_string(dims) + " dimensions, the dataset " + std::to_string(rank));
    const std::size_t header = 4 + 4 * rank;
    if (stored.size() < header) throw ReadError(context + ": the file is shorter than its block header");
    Decoded d;
    d.shape.resize(rank);
    std::uint64_t bytes = sizeOf(grid().type);
    for (std::size_t i = 0; i < rank; ++i) {
      const std::uint32_t n = bigEndian32(p + 4 + 4 * i);
      // Numpy's order: N5's reversed. A block larger than the dataset's blocks is refused
      // before its size is allocated.
      const std::size_t a = rank - 1 - i;
      if (n == 0 || std::int64_t(n) > grid().chunks[a])
        throw ReadError(context + ": its header gives the block " + std::to_string(n) + " voxels along axis " + std::to_string(i) +
                        " where the dataset's blocks have " + std::to_string(grid().chunks[a]));
      d.shape[a] = n;
      bytes *= n;
    }
    d.size = std::size_t(bytes);
    if (d.shape != grid().chunks) direct = nullptr;  // a clipped block: GridProvider copies it out
    if (!direct) d.bytes = std::make_unique_for_overwrite<unsigned char[]>(d.size);
    detail::decodeChunk(codec_, p + header, stored.size() - header, direct ? direct : d.bytes.get(), d.size, context);
    return d;
  }

 private:
  std::string dir_;
  ChunkCodec codec_;
};

}  // namespace

bool isN5Dataset(const std::string& dir) {
  const std::optional<json> meta = detail::readJsonFile(dir + "/attributes.json");
  return meta && meta->is_object() && meta->contains("dimensions");
}

N5Header readN5Header(const std::string& dir) {
  const std::string file = dir + "/attributes.json";
  const std::optional<json> meta = detail::readJsonFile(file);
  if (!meta) throw ReadError("cannot read " + quotedPath(dir) + ": not an N5 dataset (no attributes.json)");
  const std::string context = "cannot read " + quotedPath(file);
  if (!meta->is_object()) throw ReadError(context + ": not a JSON object");
  const json& m = *meta;
  if (!m.contains("dimensions")) throw ReadError(context + ": not an N5 dataset (no 'dimensions'; a group?)");
  N5Header h;
  h.dimensions = detail::integerList(m, "dimensions", 0, context);
  h.blockSize = detail::integerList(m, "blockSize", 1, context);
  if (!m.contains("dataType")) throw ReadError(context + ": 'dataType' is missing");
  h.type = parseDataType(m["dataType"], context);
  h.dataType = m["dataType"].get<std::string>();
  h.codec = parseCompression(m, context);
  return h;
}

std::shared_ptr<const ChunkProvider> openN5Dataset(const std::string& dir, const N5Header& header, int spatialAxes,
                                                   const std::vector<std::int64_t>& fixed, const ImageGeometry& geometry) {
  detail::ChunkGrid grid;
  grid.shape.assign(header.dimensions.rbegin(), header.dimensions.rend());
  grid.chunks.assign(header.blockSize.rbegin(), header.blockSize.rend());
  grid.type = header.type;
  grid.bigEndian = true;
  grid.fortranOrder = false;
  grid.fill.assign(sizeOf(header.type), 0);
  grid.spatialAxes = spatialAxes;
  grid.fixed = fixed;
  grid.geometry = geometry;
  detail::requireValidGrid(grid, "cannot read " + quotedPath(dir));
  return std::make_shared<N5Provider>(std::move(grid), dir, header.codec);
}

}  // namespace surftrack::io
