#include "MeshIO.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

#include <OpenMesh/Core/IO/MeshIO.hh>

namespace surftrack {
namespace {

namespace fs = std::filesystem;

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return char(std::tolower(ch)); });
  return ext;
}

/// A fresh name next to `path`, with the same extension (OpenMesh picks the writer by it).
fs::path temporaryPathFor(const fs::path& path, const std::string& ext) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  std::string name = path.stem().string();
  name += ".tmp-" + std::to_string(rng()) + ext;
  return path.parent_path() / ("." + name);
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::function<bool(const std::string&)>& write) {
  const fs::path target(path);
  const fs::path temporary = temporaryPathFor(target, lowerExtension(target));
  std::error_code ignored;
  bool written = false;
  try {
    written = write(temporary.string());
  } catch (...) {
    fs::remove(temporary, ignored);
    throw;
  }
  if (!written) {
    fs::remove(temporary, ignored);
    throw std::runtime_error("cannot write '" + path + "'");
  }
  std::error_code error;
  fs::rename(temporary, target, error);
  if (error) {
    fs::remove(temporary, ignored);
    throw std::runtime_error("cannot write '" + path + "': " + error.message());
  }
}

void writeMesh(const SurfaceMesh& mesh, const std::string& path, bool binary) {
  constexpr std::array<const char*, 4> kFormats = {".ply", ".obj", ".off", ".stl"};
  const fs::path target(path);
  const std::string ext = lowerExtension(target);
  if (std::find(kFormats.begin(), kFormats.end(), ext) == kFormats.end())
    throw std::invalid_argument("cannot write mesh '" + path + "': unknown extension '" + ext +
                                "' (expected .ply, .obj, .off or .stl)");

  OpenMesh::IO::Options options = OpenMesh::IO::Options::Default;
  if (binary && (ext == ".ply" || ext == ".stl")) options += OpenMesh::IO::Options::Binary;

  writeFileAtomically(path, [&](const std::string& temporary) {
    return OpenMesh::IO::write_mesh(mesh, temporary, options, 12);
  });
}

}  // namespace surftrack
