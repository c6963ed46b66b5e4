// The output mesh file: its format from the extension, a check before any work that it can be
// written, and the write itself (a temporary file renamed over the target: never a partial file).
#pragma once

#include <cstdint>
#include <string>

#include "Extract.h"

namespace surftrack::cli {

/// "ply", "obj", "off" or "stl" from the extension (any case); throws UsageError otherwise.
std::string meshFormat(const std::string& path);

/// Throws std::runtime_error (one line) if `path` cannot be created or replaced: its directory
/// is missing or not writable, or `path` is a directory.
void requireWritable(const std::string& path);

/// Writes the surface's triangles (binary PLY / STL unless `binary` is false) with OpenMesh's
/// writers (converter/MeshIO.h writeTriangles); returns the file size.
std::uintmax_t writeMeshFile(const Surface& surface, const std::string& path, bool binary);

}  // namespace surftrack::cli
