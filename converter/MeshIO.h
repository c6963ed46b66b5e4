// Writing a SurfaceMesh with OpenMesh's IO, the format chosen by the file extension.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include "LabelValue.h"
#include <functional>
#include <string>
#include <system_error>
#include <vector>

#include "SurfaceMesh.h"

namespace surftrack {

/// A file that cannot be written: a std::system_error (so a std::runtime_error) whose code() is
/// the system's errno (std::generic_category()) and whose message names the path and says why,
/// in the words of the CLI: "cannot write 'out/a.ply': directory 'out' does not exist".
class FileWriteError : public std::system_error {
 public:
  FileWriteError(int error, std::string message)
      : std::system_error(error, std::generic_category()), message_(std::move(message)) {}
  const char* what() const noexcept override { return message_.c_str(); }

 private:
  std::string message_;
};

/// Writes `mesh` to `path`; the format follows the extension (case-insensitive): .ply, .obj,
/// .off, .stl. `binary` applies to .ply and .stl (binary by default); .obj and .off are text.
/// The file is written to a temporary file in the same directory, then renamed over `path`,
/// so a failure never leaves a partial file.
/// Throws std::invalid_argument for an unknown extension, FileWriteError naming the path and
/// the reason when it cannot be written.
void writeMesh(const SurfaceMesh& mesh, const std::string& path, bool binary = true);

/// The same file from a triangle list, with no half-edge mesh: OpenMesh's writers read the
/// vertices and triangles through an exporter (OpenMesh::IO::BaseExporter) — binary PLY is
/// written from whole arrays instead, byte for byte as OpenMesh writes it — so the bytes are
/// those writeMesh writes for toSurfaceMesh of the same triangles. For files that need no
/// half-edge operation. `cancel`, if set, is checked every 2^16 vertices or triangles written:
/// raised, the temporary file is removed and Cancelled (lib/Cancellation.h) thrown.
/// \throw as writeMesh.
void writeTriangles(const std::vector<std::array<double, 3>>& vertices,
                    const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::string& path,
                    bool binary = true, const std::atomic<bool>* cancel = nullptr);
/// One mesh of a labelled PLY file (writeLabelledTriangles); the arrays are not copied.
struct LabelledMesh {
  const std::vector<std::array<double, 3>>* vertices;
  const std::vector<std::array<std::uint32_t, 3>>* triangles;
  LabelValue label;
};

/// Writes the meshes into one .ply (binary little-endian, or text), the vertices of each mesh in
/// turn and its triangles' indices shifted to them, with the label on every vertex and every
/// face: writeTriangles' binary PLY writer with more columns. PLY has no 64-bit integer, so
/// when every label fits int32 it is one property `int label`; otherwise two 32-bit words,
/// `label_high` and `uint label_low`, with label = label_high * 2^32 + label_low exactly —
/// label_high an `int` if some label is negative, else a `uint` (docs/cli.md, "labels"). Through
/// writeFileAtomically. \throw std::invalid_argument for another extension or more than
/// 2^31 - 1 vertices, FileWriteError naming the path and the reason when it cannot be written.
void writeLabelledTriangles(const std::vector<LabelledMesh>& meshes, const std::string& path, bool binary = true);

/// Calls write(temporary) with a fresh file name next to `path` (same directory and extension;
/// the file is created empty first), then renames that file over `path`: a reader sees the old
/// file or the whole new one, never a partial one. If `write` throws, the temporary file is
/// removed and the exception goes on; if the temporary cannot be created, `write` returns false
/// (errno then says why, or EIO) or the rename fails, the temporary file is removed and
/// FileWriteError names `path` and the reason. A `path` that is a directory is FileWriteError
/// (EISDIR) before anything is written. The temporary is a LiveTemporary while it exists
/// (TemporaryFiles.h): a handler of SIGINT removes it.
void writeFileAtomically(const std::string& path, const std::function<bool(const std::string& temporary)>& write);

}  // namespace surftrack
