// Neuroglancer's precomputed mesh format, multi-resolution variant "neuroglancer_multilod_draco"
// (docs/cli.md, "Neuroglancer output"): per segment an octree of fragments over a grid, one
// Draco mesh per node and level of detail, and a binary manifest; unsharded
//   info                   {"@type": "neuroglancer_multilod_draco", "vertex_quantization_bits",
//                           "transform", "lod_scale_multiplier", "segment_properties"?}
//   <id>.index             the manifest: chunk_shape, grid_origin, num_lods, lod_scales,
//                          vertex_offsets, num_fragments_per_lod, then per level the nodes'
//                          positions ([3, n] uint32, in Z-order) and their fragments' sizes
//   <id>                   the fragments, level 0 first, in the manifest's order
// or sharded (ShardedFormat.h: "sharding" in info, the manifest the value of key <id>, its
// fragments just before it in the same shard file). This file writes levels already built
// (refine/LevelsOfDetail.h makes them): it quantizes, encodes and lays them out.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "LabelValue.h"
#include "OctreeGrid.h"
#include "PrecomputedMesh.h"
#include "ShardedFormat.h"

namespace surftrack {

struct MultiresLevel {
  std::vector<std::array<double, 3>> vertices;          ///< stored model coordinates
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< facing out of the segment
};

struct MultiresSegment {
  LabelValue id;
  std::string name;  ///< "" for none
  /// The octree: origin and chunk exact float32 values (the manifest stores them so).
  OctreeGrid grid;
  /// levels[k] is level of detail k, grid.lods of them; level 0 cut on level 0's planes,
  /// level k > 0 on level k - 1's (OctreeGrid.h).
  std::vector<MultiresLevel> levels;
  std::vector<double> lodScales;  ///< nondecreasing, positive: the manifest's lod_scales
};

struct MultiresFormat {
  int quantizationBits = 16;               ///< vertex_quantization_bits: 10 or 16
  std::optional<ShardingSpec> sharding;    ///< nothing: unsharded
};

/// One segment encoded as writePrecomputedMultires stores it (what a task that encodes some of
/// the segments writes, python/surftrack/distributed.py): `manifest` is `<id>.index` (sharded:
/// the value of key <id>), `data` the fragments (`<id>`; sharded: the bytes before the value).
struct EncodedMultiresSegment {
  std::string manifest, data;
};
/// \param reverse the map to nanometres mirrors (the triangles are written reversed).
/// \throw std::invalid_argument as writePrecomputedMultires, for this segment.
EncodedMultiresSegment encodeMultiresSegment(const MultiresSegment& segment, int quantizationBits, bool reverse);

/// The `info` file of the multi-resolution format (the sharding spec in it when sharded, the
/// segment properties named when some segment is).
std::string multiresInfoBytes(const ToNanometres& toNanometres, const MultiresFormat& format, bool named);

/// Writes `segments` at `directory`, whole or not at all (as writePrecomputedMeshes), with
/// `toNanometres` as the info's transform from the stored model coordinates. A vertex of a
/// fragment of level k, cell c, is quantized to round(((p - origin) / (chunk 2^k) - c) (2^b - 1))
/// per axis; for k > 0 one on the cell's middle plane to 2^(b-1), where Neuroglancer splits
/// the fragment in octants, and one off it never to that value (it moves by at most 1.5 steps
/// of the quantization), so that Neuroglancer puts each triangle in the octant it lies in.
/// A mirroring map writes the triangles reversed (as writePrecomputedMeshes).
/// \throw std::invalid_argument for a segment id that is not a positive uint64 or given twice, a
/// singular map, quantization bits other than 10 and 16, levels that do not match the grid,
/// a triangle across a plane of its level's cut, a grid beyond the manifest's float32 and
/// uint32 fields; FileWriteError (MeshIO.h) when the directory cannot be written.
void writePrecomputedMultires(const std::vector<MultiresSegment>& segments, const std::string& directory,
                              const ToNanometres& toNanometres, const MultiresFormat& format);

}  // namespace surftrack
