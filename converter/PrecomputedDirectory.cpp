// What the precomputed mesh formats share (PrecomputedDirectory.h).
#include "PrecomputedDirectory.h"

#include <cerrno>
#include <fstream>
#include <random>
#include <set>
#include <stdexcept>
#include <system_error>

#include <nlohmann/json.hpp>

#include "MeshIO.h"

namespace surftrack {

namespace fs = std::filesystem;

namespace {

/// A fresh hidden name beside `path`: ".NAME.tmp-RANDOM".
fs::path hiddenBeside(const fs::path& path) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  return path.parent_path() / ("." + path.filename().string() + ".tmp-" + std::to_string(rng()));
}

FileWriteError cannotWrite(const std::string& path, int error) {
  return FileWriteError(error, "cannot write '" + path + "': " + std::generic_category().message(error));
}

}  // namespace

fs::path precomputedTarget(const std::string& directory) {
  fs::path target(directory);
  if (target.filename().empty()) target = target.parent_path();  // "out/" -> "out"
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    throw FileWriteError(ENOTDIR, "cannot write '" + directory + "': it is a file, not a directory");
  if (fs::is_directory(target, ec) && !fs::is_empty(target, ec))
    throw FileWriteError(ENOTEMPTY, "cannot write into '" + directory +
                                        "': the directory is not empty (a mesh directory is written whole)");
  return target;
}

bool checkSegmentIds(const std::vector<std::pair<LabelValue, const std::string*>>& segments) {
  std::set<LabelValue> ids;
  bool named = false;
  for (const auto& [id, name] : segments) {
    if (id.negative() || id == LabelValue(0))
      throw std::invalid_argument("segment id " + id.text() +
                                  " cannot be written: Neuroglancer's segment ids are positive uint64 values");
    if (!ids.insert(id).second) throw std::invalid_argument("segment id " + id.text() + " is given twice");
    named = named || (name && !name->empty());
  }
  return named;
}

StagingDirectory::StagingDirectory(const fs::path& target, const std::string& shown) : target_(target), shown_(shown) {
  path_ = hiddenBeside(target);
  live_.emplace_back(path_.string(), LiveTemporary::Kind::Directory);
  std::error_code ec;
  if (!fs::create_directory(path_, ec)) throw cannotWrite(shown_, ec ? ec.value() : EEXIST);
}

StagingDirectory::~StagingDirectory() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

void StagingDirectory::makeDirectory(const std::string& name) {
  const fs::path dir = path_ / name;
  live_.emplace_back(dir.string(), LiveTemporary::Kind::Directory);
  std::error_code ec;
  if (!fs::create_directory(dir, ec)) throw cannotWrite(shown_, ec ? ec.value() : EEXIST);
}

void StagingDirectory::write(const std::string& name, const std::string& bytes) {
  const fs::path file = path_ / name;
  live_.emplace_back(file.string());
  std::ofstream out(file, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  out.close();
  if (!out) throw cannotWrite(shown_, errno != 0 ? errno : EIO);
}

std::string segmentPropertiesBytes(const std::vector<std::pair<LabelValue, std::string>>& names) {
  nlohmann::ordered_json ids = nlohmann::ordered_json::array(), values = nlohmann::ordered_json::array();
  for (const auto& [id, name] : names) {
    ids.push_back(id.text());
    values.push_back(name);
  }
  const nlohmann::ordered_json properties = {
      {"@type", "neuroglancer_segment_properties"},
      {"inline", {{"ids", ids}, {"properties", {{{"id", "label"}, {"type", "label"}, {"values", values}}}}}}};
  return properties.dump() + "\n";
}

void StagingDirectory::writeSegmentProperties(const std::vector<std::pair<LabelValue, std::string>>& names) {
  makeDirectory("segment_properties");
  write("segment_properties/info", segmentPropertiesBytes(names));
}

void StagingDirectory::commit() {
  const TerminationSignalsDeferred deferred;  // the rename and the registry change together
  std::error_code ec;
  fs::rename(path_, target_, ec);
  if (ec) throw cannotWrite(shown_, ec.value());
  committed_ = true;
  live_.clear();
}

}  // namespace surftrack
