#include "OutputFile.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <random>

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

void requireWritableDirectory(const std::string& directory, const std::string& what) {
  std::error_code ec;
  const fs::path dir(directory);
  if (!fs::exists(dir, ec))
    throw std::runtime_error("cannot write '" + what + "': directory '" + directory + "' does not exist");
  if (!fs::is_directory(dir, ec))
    throw std::runtime_error("cannot write '" + what + "': '" + directory + "' is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw std::runtime_error("cannot write '" + what + "': directory '" + directory + "' is not writable");
}

void requireWritable(const std::string& path) {
  std::error_code ec;
  const fs::path target(path);
  if (fs::is_directory(target, ec))
    throw std::runtime_error("cannot write '" + path + "': it is a directory");
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  requireWritableDirectory(dir.string(), path);
  if (fs::exists(target, ec) && ::access(target.c_str(), W_OK) != 0 && ::access(dir.c_str(), W_OK) != 0)
    throw std::runtime_error("cannot write '" + path + "': permission denied");
}

void requireNotInput(const std::string& output, const std::string& input) {
  std::error_code ec;
  if (fs::equivalent(output, input, ec) && !ec)
    throw std::runtime_error("cannot write '" + output + "': it is the input file '" + input +
                             "' (writing it would replace the input)");
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

void writeTextFile(const std::string& path, const std::string& text) {
  writeFileAtomically(path, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    out.close();
    return bool(out);
  });
}

namespace {

/// ".NAME.tmp-RANDOM": a hidden temporary name next to NAME (appended piecewise: GCC 12 warns
/// falsely, -Wrestrict, on "." + std::string).
std::string hiddenTemporaryName(const std::string& name, const std::string& extension = "") {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  std::string out(1, '.');
  out += name;
  out += ".tmp-";
  out += std::to_string(rng());
  out += extension;
  return out;
}

}  // namespace

void requireOutputDirectory(const std::string& directory) {
  std::error_code ec;
  fs::path dir(directory);
  if (dir.filename().empty()) dir = dir.parent_path();  // "out/" -> "out"
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw std::runtime_error("cannot write '" + directory + "': it is a file, not a directory");
  if (fs::is_directory(dir, ec) && !fs::is_empty(dir, ec))
    throw std::runtime_error("cannot write into '" + directory +
                             "': the directory is not empty (a directory of outputs is written whole)");
  requireWritableDirectory((dir.parent_path().empty() ? fs::path(".") : dir.parent_path()).string(), directory);
}

StagedOutputs StagedOutputs::inDirectory(const std::string& directory) {
  requireOutputDirectory(directory);
  fs::path dir(directory);
  if (dir.filename().empty()) dir = dir.parent_path();
  std::error_code ec;
  StagedOutputs out;
  out.directory_ = dir.string();
  out.staging_ = (dir.parent_path() / hiddenTemporaryName(dir.filename().string())).string();
  out.live_.emplace_back(out.staging_, LiveTemporary::Kind::Directory);
  if (!fs::create_directory(out.staging_, ec))
    throw std::runtime_error("cannot create '" + out.staging_ + "': " + ec.message());
  return out;
}

StagedOutputs::StagedOutputs(StagedOutputs&& other) noexcept
    : directory_(std::move(other.directory_)), staging_(std::move(other.staging_)),
      files_(std::move(other.files_)), live_(std::move(other.live_)), committed_(other.committed_) {
  other.staging_.clear();
  other.files_.clear();
  other.live_.clear();
}

StagedOutputs::~StagedOutputs() {
  if (committed_) return;
  std::error_code ignored;
  for (const auto& [temporary, target] : files_) fs::remove(temporary, ignored);
  if (!staging_.empty()) fs::remove_all(staging_, ignored);
}

std::string StagedOutputs::temporaryFor(const std::string& target) {
  const fs::path t(target);
  std::string temporary;
  if (!staging_.empty()) {
    temporary = (fs::path(staging_) / t.filename()).string();
  } else {
    requireWritable(target);
    temporary = (t.parent_path() / hiddenTemporaryName(t.stem().string(), t.extension().string())).string();
  }
  live_.emplace_back(temporary);
  files_.emplace_back(temporary, target);
  return temporary;
}

void StagedOutputs::commit() {
  // Whole or not at all: a signal is handled after the renames, when no temporary is left.
  const TerminationSignalsDeferred deferred;
  std::error_code ec;
  if (!staging_.empty()) {
    fs::rename(staging_, directory_, ec);  // replaces an empty directory
    if (ec) throw std::runtime_error("cannot move the outputs into '" + directory_ + "': " + ec.message());
  } else {
    // All or nothing, as far as renames allow: the files already there are moved aside first;
    // if a rename fails, the new files moved so far are removed and the old ones put back.
    std::vector<std::pair<std::string, std::string>> aside;  // (target, its old file's name)
    std::size_t moved = 0;
    auto undo = [&](const std::string& target, const std::error_code& error) {
      std::error_code ignored;
      for (std::size_t i = 0; i < moved; ++i) fs::remove(files_[i].second, ignored);
      for (const auto& [old, backup] : aside) fs::rename(backup, old, ignored);
      return std::runtime_error("cannot write '" + target + "': " + error.message() +
                                " (no output written)");
    };
    for (const auto& [temporary, target] : files_) {
      if (!fs::is_regular_file(target, ec)) continue;
      const fs::path t(target);
      const std::string backup =
          (t.parent_path() / hiddenTemporaryName(t.stem().string(), t.extension().string())).string();
      fs::rename(target, backup, ec);
      if (ec) throw undo(target, ec);
      aside.emplace_back(target, backup);
    }
    for (; moved < files_.size(); ++moved) {
      fs::rename(files_[moved].first, files_[moved].second, ec);
      if (ec) throw undo(files_[moved].second, ec);
    }
    std::error_code ignored;
    for (const auto& [old, backup] : aside) fs::remove(backup, ignored);
  }
  committed_ = true;
  live_.clear();
}

}  // namespace surftrack::cli
