// Neuroglancer's legacy precomputed meshes (PrecomputedMesh.h).
#include "PrecomputedMesh.h"

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <list>
#include <random>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "MeshIO.h"
#include "TemporaryFiles.h"

namespace surftrack {

namespace {

namespace fs = std::filesystem;

/// Appends the little-endian bytes of `value` (the format's byte order, whatever the machine's).
template <class T>
void appendLittleEndian(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

/// The fragment file of one segment: vertex count, float32 x y z in nanometres, triangles.
std::string fragmentBytes(const PrecomputedSegment& s, const ToNanometres& m) {
  const auto& vertices = *s.vertices;
  const auto& triangles = *s.triangles;
  if (vertices.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("segment " + s.id.text() + " has more than 2^32 - 1 vertices: the format counts them in 32 bits");
  std::string out;
  out.reserve(4 + 12 * vertices.size() + 12 * triangles.size());
  appendLittleEndian(out, std::uint32_t(vertices.size()));
  for (const auto& p : vertices) {
    for (int r = 0; r < 3; ++r) {
      const double nm = m.linear[r][0] * p[0] + m.linear[r][1] * p[1] + m.linear[r][2] * p[2] + m.offset[r];
      if (!std::isfinite(nm) || std::abs(nm) > double(std::numeric_limits<float>::max()))
        throw std::invalid_argument("segment " + s.id.text() + " has a vertex at " + std::to_string(nm) +
                                    " nm, beyond a float32: the format stores float32 nanometres");
      appendLittleEndian(out, float(nm));
    }
  }
  // A map that mirrors (negative determinant, e.g. array columns z, y, x read as x, y, z) would
  // turn the triangles inwards: they are written reversed, still facing out of the label.
  const auto& a = m.linear;
  const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  for (std::array<std::uint32_t, 3> t : triangles) {
    if (det < 0) std::swap(t[1], t[2]);
    for (std::uint32_t v : t) {
      if (v >= vertices.size())
        throw std::invalid_argument("segment " + s.id.text() + " has a triangle corner " + std::to_string(v) +
                                    " beyond its " + std::to_string(vertices.size()) + " vertices");
      appendLittleEndian(out, v);
    }
  }
  return out;
}

/// A fresh hidden name beside `path`: ".NAME.tmp-RANDOM".
fs::path hiddenBeside(const fs::path& path) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  return path.parent_path() / ("." + path.filename().string() + ".tmp-" + std::to_string(rng()));
}

FileWriteError cannotWrite(const std::string& path, int error) {
  return FileWriteError(error, "cannot write '" + path + "': " + std::generic_category().message(error));
}

/// The hidden directory the outputs are written into, its files registered as live
/// temporaries as they are created; removed with what it holds unless committed.
class StagingDirectory {
 public:
  StagingDirectory(const fs::path& target, const std::string& shown) : target_(target), shown_(shown) {
    path_ = hiddenBeside(target);
    live_.emplace_back(path_.string(), LiveTemporary::Kind::Directory);
    std::error_code ec;
    if (!fs::create_directory(path_, ec)) throw cannotWrite(shown_, ec ? ec.value() : EEXIST);
  }
  ~StagingDirectory() {
    if (committed_) return;
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }

  void makeDirectory(const std::string& name) {
    const fs::path dir = path_ / name;
    live_.emplace_back(dir.string(), LiveTemporary::Kind::Directory);
    std::error_code ec;
    if (!fs::create_directory(dir, ec)) throw cannotWrite(shown_, ec ? ec.value() : EEXIST);
  }
  void write(const std::string& name, const std::string& bytes) {
    const fs::path file = path_ / name;
    live_.emplace_back(file.string());
    std::ofstream out(file, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (!out) throw cannotWrite(shown_, errno != 0 ? errno : EIO);
  }
  /// Moves the directory into place (rename replaces an empty directory).
  void commit() {
    const TerminationSignalsDeferred deferred;  // the rename and the registry change together
    std::error_code ec;
    fs::rename(path_, target_, ec);
    if (ec) throw cannotWrite(shown_, ec.value());
    committed_ = true;
    live_.clear();
  }

 private:
  fs::path target_, path_;
  std::string shown_;
  std::list<LiveTemporary> live_;
  bool committed_ = false;
};

}  // namespace

void writePrecomputedMeshes(const std::vector<PrecomputedSegment>& segments, const std::string& directory,
                            const ToNanometres& toNanometres) {
  fs::path target(directory);
  if (target.filename().empty()) target = target.parent_path();  // "out/" -> "out"
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    throw FileWriteError(ENOTDIR, "cannot write '" + directory + "': it is a file, not a directory");
  if (fs::is_directory(target, ec) && !fs::is_empty(target, ec))
    throw FileWriteError(ENOTEMPTY, "cannot write into '" + directory +
                                        "': the directory is not empty (a mesh directory is written whole)");
  const auto& a = toNanometres.linear;
  const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  if (!std::isfinite(det) || det == 0)
    throw std::invalid_argument("the map of the meshes to nanometres is singular or not finite");
  std::set<LabelValue> ids;
  bool named = false;
  for (const PrecomputedSegment& s : segments) {
    if (!s.vertices || !s.triangles) throw std::invalid_argument("segment " + s.id.text() + " has no mesh");
    if (s.id.negative() || s.id == LabelValue(0))
      throw std::invalid_argument("segment id " + s.id.text() +
                                  " cannot be written: Neuroglancer's segment ids are positive uint64 values");
    if (!ids.insert(s.id).second) throw std::invalid_argument("segment id " + s.id.text() + " is given twice");
    named = named || !s.name.empty();
  }

  StagingDirectory staging(target, directory);
  nlohmann::ordered_json info = {{"@type", "neuroglancer_legacy_mesh"}};
  if (named) info["segment_properties"] = "segment_properties";
  staging.write("info", info.dump() + "\n");
  for (const PrecomputedSegment& s : segments) {
    const std::string id = s.id.text();
    staging.write(id + ".mesh", fragmentBytes(s, toNanometres));
    staging.write(id + ":0", nlohmann::ordered_json{{"fragments", {id + ".mesh"}}}.dump() + "\n");
  }
  if (named) {
    nlohmann::ordered_json ids = nlohmann::ordered_json::array(), names = nlohmann::ordered_json::array();
    for (const PrecomputedSegment& s : segments) {
      ids.push_back(s.id.text());
      names.push_back(s.name);
    }
    const nlohmann::ordered_json properties = {
        {"@type", "neuroglancer_segment_properties"},
        {"inline", {{"ids", ids}, {"properties", {{{"id", "label"}, {"type", "label"}, {"values", names}}}}}}};
    staging.makeDirectory("segment_properties");
    staging.write("segment_properties/info", properties.dump() + "\n");
  }
  staging.commit();
}

}  // namespace surftrack
