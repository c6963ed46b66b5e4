// `.zarray` parsed and checked field by field; a chunk's file named and decoded whole.
#include "ZarrArray.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "ChunkGrid.h"
#include "JsonFile.h"
#include "ReadVolume.h"

namespace surftrack::io {

using detail::ChunkCodec;
using detail::jsonText;
using detail::quotedPath;
using nlohmann::json;

namespace {

constexpr const char* kDtypes = "u1, i1, u2, i2, u4, i4, u8, i8, f4 or f8, byte order '<', '>' or '|'";

void parseDtype(const json& value, ZarrHeader& h, const std::string& context) {
  const auto bad = [&] {
    return ReadError(context + ": unsupported dtype " + jsonText(value) + ": surftrack reads " + kDtypes);
  };
  if (!value.is_string()) throw bad();
  const std::string s = value.get<std::string>();
  if (s.size() != 3 || std::strchr("<>|", s[0]) == nullptr || s[0] == '\0') throw bad();
  static constexpr struct {
    char kind, size;
    ScalarType type;
  } kTypes[] = {{'u', '1', ScalarType::UInt8},  {'i', '1', ScalarType::Int8},    {'u', '2', ScalarType::UInt16},
                {'i', '2', ScalarType::Int16},  {'u', '4', ScalarType::UInt32},  {'i', '4', ScalarType::Int32},
                {'u', '8', ScalarType::UInt64}, {'i', '8', ScalarType::Int64},   {'f', '4', ScalarType::Float32},
                {'f', '8', ScalarType::Float64}};
  for (const auto& t : kTypes)
    if (s[1] == t.kind && s[2] == t.size) {
      // '|' (not applicable) is numpy's byte order of one-byte types only.
      if (s[0] == '|' && t.size != '1') throw bad();
      h.type = t.type;
      h.bigEndian = s[0] == '>';
      h.dtype = s;
      return;
    }
  throw bad();
}

/// One voxel of `value` (null: 0) in the machine's byte order.
std::vector<unsigned char> parseFill(const json& value, ScalarType type, const std::string& context) {
  std::vector<unsigned char> bytes(sizeOf(type), 0);
  if (value.is_null()) return bytes;
  const auto bad = [&] {
    return ReadError(context + ": the fill_value " + jsonText(value) + " is not a " + toString(type) + " value");
  };
  visitScalarType(type, [&](auto zero) {
    using T = decltype(zero);
    T v{};
    if constexpr (std::is_floating_point_v<T>) {
      double d = 0;
      if (value.is_number()) {
        d = value.get<double>();
        if (std::is_same_v<T, float> && std::isfinite(d) && std::abs(d) > double(std::numeric_limits<float>::max())) throw bad();
      } else if (value == "NaN") {
        d = std::numeric_limits<double>::quiet_NaN();
      } else if (value == "Infinity") {
        d = std::numeric_limits<double>::infinity();
      } else if (value == "-Infinity") {
        d = -std::numeric_limits<double>::infinity();
      } else {
        throw bad();
      }
      v = T(d);
    } else {
      if (value.is_number_unsigned()) {
        const std::uint64_t u = value.get<std::uint64_t>();
        if (u > std::uint64_t(std::numeric_limits<T>::max())) throw bad();
        v = T(u);
      } else if (value.is_number_integer()) {
        const std::int64_t i = value.get<std::int64_t>();
        if (i < std::int64_t(std::numeric_limits<T>::min()) ||
            (i > 0 && std::uint64_t(i) > std::uint64_t(std::numeric_limits<T>::max())))
          throw bad();
        v = T(i);
      } else if (value.is_number_float()) {
        // An integral float (0.0) is the same value; 2^63 and beyond do not convert exactly.
        const double d = value.get<double>();
        if (!(d == std::floor(d)) || d < double(std::numeric_limits<T>::min()) ||
            d >= 2.0 * (double(std::numeric_limits<T>::max() / 2) + 1))
          throw bad();
        v = T(d);
      } else {
        throw bad();
      }
    }
    std::memcpy(bytes.data(), &v, sizeof v);
  });
  return bytes;
}

ChunkCodec parseCompressor(const json& value, const std::string& context) {
  ChunkCodec codec;
  if (value.is_null()) {
    codec.description = "none";
    return codec;
  }
  const std::string id = value.is_object() && value.contains("id") && value["id"].is_string() ? value["id"].get<std::string>() : "";
  if (id == "blosc") {
    codec.kind = ChunkCodec::Kind::Blosc;
    const std::string cname = value.contains("cname") && value["cname"].is_string() ? value["cname"].get<std::string>() : "?";
    const std::string shuffle = value.contains("shuffle") ? value["shuffle"].dump() : "?";
    codec.description = "blosc (" + cname + ", shuffle " + shuffle + ")";
  } else if (id == "zstd" || id == "zlib" || id == "gzip") {
    codec.kind = id == "zstd" ? ChunkCodec::Kind::Zstd : id == "zlib" ? ChunkCodec::Kind::Zlib : ChunkCodec::Kind::Gzip;
    codec.description = id;
  } else {
    throw ReadError(context + ": unsupported compressor " + (id.empty() ? jsonText(value) : quotedPath(id)) +
                    ": surftrack reads blosc, zstd, zlib, gzip or none");
  }
  return codec;
}

/// The zarr array's chunk files, decoded whole.
class ZarrProvider final : public detail::GridProvider {
 public:
  ZarrProvider(detail::ChunkGrid grid, std::string dir, char separator, ChunkCodec codec)
      : GridProvider(std::move(grid)), dir_(std::move(dir)), separator_(separator), codec_(std::move(codec)) {}

 protected:
  std::string chunkPath(const std::vector<std::int64_t>& coords) const override {
    std::string path = dir_ + '/';
    for (std::size_t a = 0; a < coords.size(); ++a) {
      if (a) path += separator_;
      path += std::to_string(coords[a]);
    }
    return path;
  }
  Decoded decode(const std::string& bytes, const std::string& path, unsigned char* direct) const override {
    Decoded d;
    d.shape = grid().chunks;
    d.size = std::size_t(detail::chunkBytes(grid()));
    if (!direct) d.bytes = std::make_unique_for_overwrite<unsigned char[]>(d.size);
    detail::decodeChunk(codec_, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), direct ? direct : d.bytes.get(),
                        d.size, "cannot read chunk " + quotedPath(path));
    return d;
  }

 private:
  std::string dir_;
  char separator_;
  ChunkCodec codec_;
};

}  // namespace

ZarrHeader readZarrHeader(const std::string& dir) {
  const std::string file = dir + "/.zarray";
  const std::optional<json> meta = detail::readJsonFile(file);
  if (!meta) throw ReadError("cannot read " + quotedPath(dir) + ": not a zarr array (no .zarray)");
  const std::string context = "cannot read " + quotedPath(file);
  if (!meta->is_object()) throw ReadError(context + ": not a JSON object");
  const json& m = *meta;
  if (!m.contains("zarr_format") || m["zarr_format"] != 2)
    throw ReadError(context + ": zarr_format " + (m.contains("zarr_format") ? jsonText(m["zarr_format"]) : "missing") +
                    ": surftrack reads zarr format 2");
  ZarrHeader h;
  h.shape = detail::integerList(m, "shape", 0, context);
  h.chunks = detail::integerList(m, "chunks", 1, context);
  if (!m.contains("dtype")) throw ReadError(context + ": 'dtype' is missing");
  parseDtype(m["dtype"], h, context);
  const json order = m.value("order", json());
  if (order != "C" && order != "F") throw ReadError(context + ": the order " + jsonText(order) + " is neither \"C\" nor \"F\"");
  h.fortranOrder = order == "F";
  const json separator = m.value("dimension_separator", json("."));
  if (separator != "." && separator != "/")
    throw ReadError(context + ": the dimension_separator " + jsonText(separator) + " is neither \".\" nor \"/\"");
  h.separator = separator.get<std::string>()[0];
  h.fill = parseFill(m.value("fill_value", json()), h.type, context);
  if (!m.contains("compressor")) throw ReadError(context + ": 'compressor' is missing");
  h.codec = parseCompressor(m["compressor"], context);
  const json filters = m.value("filters", json());
  if (!filters.is_null() && !(filters.is_array() && filters.empty()))
    throw ReadError(context + ": filters " + jsonText(filters) + " are not supported: surftrack reads arrays without filters");
  return h;
}

std::shared_ptr<const ChunkProvider> openZarrArray(const std::string& dir, const ZarrHeader& header, int spatialAxes,
                                                   const std::vector<std::int64_t>& fixed, const ImageGeometry& geometry) {
  detail::ChunkGrid grid;
  grid.shape = header.shape;
  grid.chunks = header.chunks;
  grid.type = header.type;
  grid.bigEndian = header.bigEndian;
  grid.fortranOrder = header.fortranOrder;
  grid.fill = header.fill;
  grid.spatialAxes = spatialAxes;
  grid.fixed = fixed;
  grid.geometry = geometry;
  detail::requireValidGrid(grid, "cannot read " + quotedPath(dir));
  return std::make_shared<ZarrProvider>(std::move(grid), dir, header.separator, header.codec);
}

}  // namespace surftrack::io
