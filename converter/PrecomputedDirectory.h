// What Neuroglancer's two precomputed mesh formats share (docs/cli.md, "Neuroglancer output"):
// the directory written whole or not at all, the segment ids, the segment properties, and
// little-endian numbers.
#pragma once

#include <bit>
#include <cstring>
#include <filesystem>
#include <list>
#include <string>
#include <utility>
#include <vector>

#include "LabelValue.h"
#include "TemporaryFiles.h"

namespace surftrack {

/// Appends the little-endian bytes of `value` (the formats' byte order, whatever the machine's).
template <class T>
void appendLittleEndian(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

/// The directory `directory` names ("out/" -> "out"), checked before any work: it must not be
/// a file, and if it exists it must be empty (a mesh directory is written whole).
/// \throw FileWriteError (MeshIO.h) naming the path and the reason.
std::filesystem::path precomputedTarget(const std::string& directory);

/// Segment ids and names as the formats hold them: each id a positive uint64, given once.
/// Returns whether any segment is named. \throw std::invalid_argument naming the id.
bool checkSegmentIds(const std::vector<std::pair<LabelValue, const std::string*>>& segments);

/// The bytes of `segment_properties/info`: each segment's name (Neuroglancer's "label"
/// property), in the order given.
std::string segmentPropertiesBytes(const std::vector<std::pair<LabelValue, std::string>>& names);

/// The hidden directory the outputs are written into, beside the target, its files registered
/// as live temporaries as they are created (converter/TemporaryFiles.h: a SIGINT removes
/// them); removed with what it holds unless committed, then renamed into place.
class StagingDirectory {
 public:
  /// \param shown the path as the user gave it, for messages.
  StagingDirectory(const std::filesystem::path& target, const std::string& shown);
  ~StagingDirectory();
  StagingDirectory(const StagingDirectory&) = delete;
  StagingDirectory& operator=(const StagingDirectory&) = delete;

  void makeDirectory(const std::string& name);
  void write(const std::string& name, const std::string& bytes);
  /// `segment_properties/info` with each segment's name (Neuroglancer's "label" property).
  void writeSegmentProperties(const std::vector<std::pair<LabelValue, std::string>>& names);
  /// Moves the directory into place (rename replaces an empty directory).
  void commit();

 private:
  std::filesystem::path target_, path_;
  std::string shown_;
  std::list<LiveTemporary> live_;
  bool committed_ = false;
};

}  // namespace surftrack
