// Segments written in Neuroglancer's multi-resolution format with levels of detail (docs/cli.md
// and docs/python.md, "Neuroglancer output"): for each segment a grid (LevelsOfDetail.h,
// gridFor), its levels (levelsOfDetail), then the writer (converter/MultiresMesh.h). What the
// CLI's `--format precomputed-multires` and Python's write_precomputed(multires=True) call.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "MultiresMesh.h"
#include "PrecomputedMesh.h"

namespace surftrack::refine {

struct MultiresolutionOptions {
  int lods = 3;               ///< levels of detail, 1 to 10
  int quantizationBits = 16;  ///< 10 or 16
  bool sharded = false;       ///< the sharded layout (ShardedFormat.h), murmurhash3_x86_128 unless identity
  bool identityHash = false;
  /// Level 1's error bound in the vertices' units (voxels for voxel indices); level k's
  /// increment is firstError * 2^(k-1) (LevelsOfDetail.h). lod_scales[k] = 2^k units.
  double firstError = 0.5;
  const std::atomic<bool>* cancel = nullptr;
};

/// \throw std::invalid_argument for options out of range.
void checkMultiresolutionOptions(const MultiresolutionOptions& options);

/// One segment's grid and levels of detail, as writeMultiresolutionMeshes makes them (what a
/// task that encodes some of the segments calls, python/surftrack/distributed.py).
/// \throw std::invalid_argument as writeMultiresolutionMeshes, for this segment; Cancelled.
MultiresSegment multiresolutionSegment(const PrecomputedSegment& segment, const MultiresolutionOptions& options);

/// The format of `count` segments: the sharding layout (ShardedFormat.h, shardingFor) depends
/// on the count of every segment written, not only on those a task encodes.
MultiresFormat multiresolutionFormat(std::size_t count, const MultiresolutionOptions& options);

/// Writes `segments` (vertices in the stored model's units, triangles facing out in them) at
/// `directory` with `toNanometres` as the transform, whole or not at all. The directory is
/// checked before any work.
/// \throw std::invalid_argument for options out of range, a segment id the format cannot hold,
///        a mesh that is not a closed oriented manifold when lods > 1; FileWriteError when the
///        directory cannot be written; Cancelled.
void writeMultiresolutionMeshes(const std::vector<PrecomputedSegment>& segments, const std::string& directory,
                                const ToNanometres& toNanometres, const MultiresolutionOptions& options);

}  // namespace surftrack::refine
