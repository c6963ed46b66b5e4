// The ITK-free half of io/: voxel type names, raw files, index <-> physical geometry.
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ReadVolume.h"

namespace surftrack::io {

std::string toString(ScalarType type) {
  switch (type) {
    case ScalarType::UInt8: return "uint8";
    case ScalarType::Int16: return "int16";
    case ScalarType::UInt16: return "uint16";
    case ScalarType::Int32: return "int32";
    case ScalarType::Float32: return "float";
    case ScalarType::Float64: return "double";
  }
  return "?";
}

ScalarType parseScalarType(std::string_view text) {
  const std::string s(text);
  if (s == "uint8" || s == "u8" || s == "uchar") return ScalarType::UInt8;
  if (s == "int16" || s == "i16" || s == "short") return ScalarType::Int16;
  if (s == "uint16" || s == "u16" || s == "ushort") return ScalarType::UInt16;
  if (s == "int32" || s == "i32" || s == "int") return ScalarType::Int32;
  if (s == "float" || s == "float32" || s == "f32") return ScalarType::Float32;
  if (s == "double" || s == "float64" || s == "f64") return ScalarType::Float64;
  throw std::invalid_argument("unsupported voxel type '" + s +
                              "': expected uint8, int16, uint16, int32, float or double");
}

std::size_t sizeOf(ScalarType type) {
  switch (type) {
    case ScalarType::UInt8: return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16: return 2;
    case ScalarType::Int32:
    case ScalarType::Float32: return 4;
    case ScalarType::Float64: return 8;
  }
  return 0;
}

ScalarType scalarTypeOf(const AnyVolume& volume) { return ScalarType(volume.index()); }

const Dims& dimsOf(const AnyVolume& volume) {
  return std::visit([](const auto& image) -> const Dims& { return image.dims(); }, volume);
}
const ImageGeometry& geometryOf(const AnyVolume& volume) {
  return std::visit([](const auto& image) -> const ImageGeometry& { return image.geometry(); },
                    volume);
}
ImageGeometry& geometryOf(AnyVolume& volume) {
  return std::visit([](auto& image) -> ImageGeometry& { return image.geometry(); }, volume);
}

namespace {

template <class T>
AnyVolume readRawAs(std::ifstream& in, const std::string& path, const RawLayout& layout) {
  DenseImage<T> image(layout.dims, T{}, layout.geometry);
  auto& data = image.data();
  in.seekg(std::streamoff(layout.headerBytes));
  in.read(reinterpret_cast<char*>(data.data()), std::streamsize(data.size() * sizeof(T)));
  if (!in) throw ReadError("cannot read '" + path + "': read error");
  const bool swap = layout.bigEndian != (std::endian::native == std::endian::big);
  if (swap && sizeof(T) > 1)
    for (T& v : data) {
      auto* b = reinterpret_cast<unsigned char*>(&v);
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
  return AnyVolume(std::move(image));
}

}  // namespace

AnyVolume readRawVolume(const std::string& path, const RawLayout& layout) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw ReadError("cannot read '" + path + "': no such file");
  if (!fs::is_regular_file(path, ec)) throw ReadError("cannot read '" + path + "': not a regular file");
  if (layout.dims.empty())
    throw ReadError("cannot read raw file '" + path + "': dimensions must be positive");
  for (int a = 0; a < 3; ++a)
    if (!(layout.geometry.spacing[a] > 0) || !std::isfinite(layout.geometry.spacing[a]))
      throw ReadError("cannot read raw file '" + path + "': spacing must be positive");
  const std::uintmax_t size = fs::file_size(path, ec);
  const std::uintmax_t expected = layout.headerBytes + layout.dims.count() * sizeOf(layout.type);
  if (ec) throw ReadError("cannot read '" + path + "': " + ec.message());
  if (size != expected) {
    std::ostringstream msg;
    msg << "raw file '" << path << "' has " << size << " bytes, but " << layout.dims.nx << "x"
        << layout.dims.ny << "x" << layout.dims.nz << " " << toString(layout.type) << " voxels";
    if (layout.headerBytes) msg << " after a " << layout.headerBytes << "-byte header";
    msg << " need " << expected << (size < expected ? " (truncated file?)" : "");
    throw ReadError(msg.str());
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ReadError("cannot open '" + path + "': " + std::strerror(errno));
  switch (layout.type) {
    case ScalarType::UInt8: return readRawAs<std::uint8_t>(in, path, layout);
    case ScalarType::Int16: return readRawAs<std::int16_t>(in, path, layout);
    case ScalarType::UInt16: return readRawAs<std::uint16_t>(in, path, layout);
    case ScalarType::Int32: return readRawAs<std::int32_t>(in, path, layout);
    case ScalarType::Float32: return readRawAs<float>(in, path, layout);
    case ScalarType::Float64: return readRawAs<double>(in, path, layout);
  }
  throw ReadError("unsupported voxel type");
}

std::array<double, 3> toIndex(const ImageGeometry& g, const std::array<double, 3>& point) {
  // Solve (direction * diag(spacing)) * index = point - origin with Cramer's rule.
  double m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = g.direction[r][c] * g.spacing[c];
  auto det3 = [](const double a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  const double det = det3(m);
  if (!(std::abs(det) > 1e-300)) throw std::invalid_argument("the image geometry is singular");
  std::array<double, 3> b{};
  for (int r = 0; r < 3; ++r) b[r] = point[r] - g.origin[r];
  std::array<double, 3> x{};
  for (int c = 0; c < 3; ++c) {
    double mc[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) mc[r][k] = k == c ? b[r] : m[r][k];
    x[c] = det3(mc) / det;
  }
  return x;
}

}  // namespace surftrack::io
