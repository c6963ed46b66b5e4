// The output mesh file: its format from the extension, a check before any work that it can be
// written, and the write itself (a temporary file renamed over the target: never a partial file).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "Extract.h"
#include "TemporaryFiles.h"

namespace surftrack::cli {

/// "ply", "obj", "off" or "stl" from the extension (any case); throws UsageError otherwise.
std::string meshFormat(const std::string& path);

/// Throws std::runtime_error (one line) if `path` cannot be created or replaced: its directory
/// is missing or not writable, or `path` is a directory.
void requireWritable(const std::string& path);

/// Throws std::runtime_error (one line, "cannot write '<what>': ...") unless `directory` exists,
/// is a directory and this process may create files in it (access W_OK | X_OK: no file is
/// created to find out, so no name in it is reserved).
void requireWritableDirectory(const std::string& directory, const std::string& what);
/// A directory of outputs, written whole: `directory` must be absent or empty, its parent
/// writable. Throws std::runtime_error (one line) otherwise.
void requireOutputDirectory(const std::string& directory);

/// Throws std::runtime_error (one line) if `output` is the file `input` — the same file by
/// std::filesystem::equivalent, so also through a symbolic or hard link or another spelling of
/// the path: writing the output would replace the input. Nothing is checked when either does
/// not exist.
void requireNotInput(const std::string& output, const std::string& input);

/// Writes the surface's triangles (binary PLY / STL unless `binary` is false) with OpenMesh's
/// writers (converter/MeshIO.h writeTriangles); returns the file size.
std::uintmax_t writeMeshFile(const Surface& surface, const std::string& path, bool binary);

/// Writes `text` to `path` (a temporary file renamed over it).
void writeTextFile(const std::string& path, const std::string& text);

/// Several output files written completely or not at all: each is written under a temporary
/// name (a LiveTemporary, removed by the tool's handler of SIGINT: cli/Interrupt.h), and
/// commit() moves them all into place, with SIGINT and SIGTERM held until it is done. In a
/// directory of outputs the temporary names
/// lie in a staging directory next to it, which commit() renames to the directory (which must
/// then not exist, or be empty); otherwise they lie next to their targets, and commit() moves
/// the files already there aside, renames the new ones over them and, if a rename fails,
/// removes the new ones it moved and puts the old ones back. Whatever commit() has not moved is
/// removed by the destructor (an error, an exception on the way).
class StagedOutputs {
 public:
  /// Outputs inside `directory`. Throws std::runtime_error (one line) if it is a non-empty
  /// directory or a file, or its parent is not writable.
  static StagedOutputs inDirectory(const std::string& directory);
  /// Outputs anywhere (a name pattern): each target's directory must be writable.
  StagedOutputs() = default;
  StagedOutputs(StagedOutputs&&) noexcept;
  StagedOutputs& operator=(StagedOutputs&&) = delete;
  ~StagedOutputs();

  /// The temporary name to write `target` to (same extension).
  std::string temporaryFor(const std::string& target);
  /// Moves every output into place.
  void commit();
  /// The hidden directory the outputs of inDirectory() are written into ("" otherwise).
  const std::string& stagingDirectory() const { return staging_; }

 private:
  std::string directory_, staging_;
  std::vector<std::pair<std::string, std::string>> files_;  ///< (temporary, target)
  std::vector<LiveTemporary> live_;  ///< the staging directory and the temporaries
  bool committed_ = false;
};

}  // namespace surftrack::cli
