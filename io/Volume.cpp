// The ITK-free half of io/: the volume variant, raw files (read into a DenseImage; the checks
// shared with loadRawVolume).
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "Internal.h"
#include "ReadVolume.h"

namespace surftrack::io {

std::string supportedTypesText() {
  std::string out;
  constexpr int kLast = int(ScalarType::Float64);  // (the ten types, in ScalarType's order)
  for (int t = 0; t <= kLast; ++t) out += (t == 0 ? "" : t == kLast ? " or " : ", ") + toString(ScalarType(t));
  return out;
}

ScalarType scalarTypeOf(const AnyVolume& volume) {
  return std::visit([](const auto& image) {
    return surftrack::scalarTypeOf<typename std::decay_t<decltype(image)>::value_type>();
  }, volume);
}

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

namespace detail {

void requireRawLayout(const std::string& path, const RawLayout& layout, std::uintmax_t size) {
  if (layout.dims.empty())
    throw ReadError("cannot read raw file '" + path + "': dimensions must be positive");
  for (int a = 0; a < 3; ++a)
    if (!(layout.geometry.spacing[a] > 0) || !std::isfinite(layout.geometry.spacing[a]))
      throw ReadError("cannot read raw file '" + path + "': spacing must be positive");
  if (layout.dims.count() > (std::uintmax_t(1) << 62) / sizeOf(layout.type) ||
      layout.headerBytes > (std::uintmax_t(1) << 62))
    throw ReadError("cannot read raw file '" + path + "': more than 2^62 bytes of header or voxels");
  const std::uintmax_t expected = layout.headerBytes + layout.dims.count() * sizeOf(layout.type);
  if (size != expected) {
    std::ostringstream msg;
    msg << "raw file '" << path << "' has " << size << " bytes, but " << layout.dims.nx << "x"
        << layout.dims.ny << "x" << layout.dims.nz << " " << toString(layout.type) << " voxels";
    if (layout.headerBytes) msg << " after a " << layout.headerBytes << "-byte header";
    msg << " need " << expected << (size < expected ? " (truncated file?)" : "");
    throw ReadError(msg.str());
  }
}

}  // namespace detail

AnyVolume readRawVolume(const std::string& path, const RawLayout& layout) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw ReadError("cannot read '" + path + "': no such file");
  if (!fs::is_regular_file(path, ec)) throw ReadError("cannot read '" + path + "': not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw ReadError("cannot read '" + path + "': " + ec.message());
  detail::requireRawLayout(path, layout, size);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ReadError("cannot open '" + path + "': " + std::strerror(errno));
  return visitScalarType(layout.type, [&](auto v) { return readRawAs<decltype(v)>(in, path, layout); });
}

}  // namespace surftrack::io
