// Neuroglancer's precomputed mesh format, legacy single-resolution variant (docs/cli.md,
// "Neuroglancer output"): a directory Neuroglancer opens as `precomputed://URL` —
//   info                 {"@type": "neuroglancer_legacy_mesh", "segment_properties": ...}
//   <id>:0               the manifest of segment <id>: {"fragments": ["<id>.mesh"]}
//   <id>.mesh            uint32 vertex count, float32 x y z per vertex (nanometres), uint32
//                        vertex indices per triangle, all little-endian
//   segment_properties/info  the segments' names, when some are named
// Segment ids are uint64 (nonzero), written as decimal text, exact.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "LabelValue.h"

namespace surftrack {

/// One segment: its id, its mesh (not copied) and its name ("" for none).
struct PrecomputedSegment {
  LabelValue id;
  const std::vector<std::array<double, 3>>* vertices = nullptr;
  const std::vector<std::array<std::uint32_t, 3>>* triangles = nullptr;
  std::string name;
};

/// The affine map from the meshes' coordinates to Neuroglancer's x, y, z in nanometres:
/// nm[r] = sum_c linear[r][c] * p[c] + offset[r].
struct ToNanometres {
  std::array<std::array<double, 3>, 3> linear{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<double, 3> offset{};

  /// det(linear): negative for a map that mirrors (the triangles are then written reversed).
  double determinant() const {
    const auto& a = linear;
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  }
};

/// The files of one segment, as writePrecomputedMeshes writes them (what a task that encodes
/// some of the segments writes, python/surftrack/distributed.py): `<id>.mesh` (the fragment)
/// and `<id>:0` (its manifest). \throw std::invalid_argument as writePrecomputedMeshes.
std::string legacyFragmentBytes(const PrecomputedSegment& segment, const ToNanometres& toNanometres);
std::string legacyManifestBytes(const LabelValue& id);
/// The `info` file of the legacy format, with segment properties when some segment is named.
std::string legacyInfoBytes(bool named);

/// Writes `segments` as a legacy precomputed mesh directory at `directory`, whole or not at
/// all: into a hidden directory beside it, renamed into place at the end (`directory` must not
/// exist or be empty; a handler of SIGINT removes the hidden one, converter/TemporaryFiles.h).
/// A mirroring map (negative determinant) writes every triangle reversed, so that the meshes
/// still face out of their labels in Neuroglancer's space.
/// \throw std::invalid_argument for a singular map, a segment id that is not a positive uint64, two segments
/// with one id, a coordinate that is not a finite float32 in nanometres, more than 2^32 - 1
/// vertices; FileWriteError (MeshIO.h) naming the path and the reason when it cannot be written.
void writePrecomputedMeshes(const std::vector<PrecomputedSegment>& segments, const std::string& directory,
                            const ToNanometres& toNanometres = {});

}  // namespace surftrack
