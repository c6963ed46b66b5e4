#include "OutputFile.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "MeshIO.h"
#include "Options.h"

namespace surftrack::cli {

namespace fs = std::filesystem;

std::string meshFormat(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  for (const char* f : {"ply", "obj", "off", "stl"})
    if (ext == std::string(".") + f) return f;
  throw UsageError("cannot write '" + path + "': unknown mesh format '" + ext +
                   "' (the extension must be .ply, .obj, .off or .stl)");
}

void requireWritable(const std::string& path) {
  std::error_code ec;
  const fs::path target(path);
  if (fs::is_directory(target, ec))
    throw std::runtime_error("cannot write '" + path + "': it is a directory");
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::exists(dir, ec))
    throw std::runtime_error("cannot write '" + path + "': directory '" + dir.string() + "' does not exist");
  if (!fs::is_directory(dir, ec))
    throw std::runtime_error("cannot write '" + path + "': '" + dir.string() + "' is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw std::runtime_error("cannot write '" + path + "': directory '" + dir.string() + "' is not writable");
  if (fs::exists(target, ec) && ::access(target.c_str(), W_OK) != 0 && ::access(dir.c_str(), W_OK) != 0)
    throw std::runtime_error("cannot write '" + path + "': permission denied");
}

std::uintmax_t writeMeshFile(const Surface& surface, const std::string& path, bool binary) {
  try {
    writeTriangles(surface.vertices, surface.triangles, path, binary);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  return ec ? 0 : size;
}

}  // namespace surftrack::cli
