// Every boundary of a threshold meshed block by block (docs/api.md, "Thresholds by blocks";
// docs/theory.md, "Thresholds by blocks"): each block of a partition of the volume is scanned on
// its own, from its box of voxels, into a fragment; the merge of all fragments is the Surface
// that extract() gives with SeedRule::all() over the whole volume, field for field.
//
//   surftrack::ExtractOptions options;
//   options.selection = surftrack::Selection::threshold(100);
//   options.seed = surftrack::SeedRule::all();
//   std::vector<surftrack::ThresholdFragment> fragments;
//   for (each block [lo, hi) of the volume, its box view from `origin`)
//     fragments.push_back(surftrack::scanThresholdBlock(box, origin, volumeDims, lo, hi, options));
//   surftrack::Surface s = surftrack::mergeThresholdFragments(fragments, geometry, options);
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "Extract.h"
#include "VolumeView.h"
#include "Voxel.h"

namespace surftrack {

/// The part of the iso-surface of f > s of one block of a volume: the triangles of the cubes
/// the block owns, with what the boundary mapping needs to place their vertices.
struct ThresholdFragment {
  Dims volume;               ///< the whole volume's dimensions
  std::uint64_t voxels = 0;  ///< voxels of the block's core
  /// The vertices: their surfels' keys (Surfel::key, volume coordinates), increasing, each
  /// used by a triangle.
  std::vector<std::uint64_t> keys;
  /// The linear mapping only (else empty): values[v] = {f(c), f(d)} of surfel keys[v] = (c, d),
  /// as the volume's source gives them (VoxelSource::values), NaN for a voxel outside the volume.
  std::vector<std::array<double, 2>> values;
  /// Indices into keys, in the table's orientation (geometry not applied), by owned cube
  /// (z, y, x), then the configuration table's order.
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The fragment of one block of a volume of `volume` voxels for the threshold options.selection
/// (f > s). The block's core is the box [lo, hi) of the volume; it owns the cubes whose min
/// corner lies in [lo, hi) on every axis, and also at -1 on an axis where lo = 0. `view` holds
/// the voxels [origin, origin + view.dims) of the volume, which must contain
/// [lo, min(hi + 1, volume)) (a one-voxel apron on the high sides) and lie in the volume;
/// view.geometry is not used. The options' selection, seed (SeedRule::all() only), pair, mapping
/// (Default: Linear), epsilon and threads apply. mergeThresholdFragments over the fragments of
/// all blocks of any partition of the volume gives extract()'s Surface over the whole volume.
/// \throw InvalidInput for a view or core that does not fit as above, volume dimensions beyond
///        the surfel keys' range, a label selection, a NaN threshold, a seed rule other than
///        all, an epsilon outside ]0, 0.5[, negative threads.
/// \throw Cancelled when options.cancel is raised.
ThresholdFragment scanThresholdBlock(const VolumeView& view, Voxel origin, Dims volume, Voxel lo, Voxel hi,
                                     const ExtractOptions& options);

/// The iso-surface from the fragments of every block of a partition of the volume (any order):
/// the Surface extract() gives with the same options over the whole volume with `geometry`,
/// field for field (vertices bit-equal, in the same order, triangles in the same order,
/// figures), but the stage timings, which are left empty.
/// \throw InvalidInput for no fragment, fragments of different volumes, keys not increasing or
///        out of the key range, a triangle index beyond its fragment's keys, values missing for
///        the linear mapping, an empty selection (no boundary in the volume), vertices beyond
///        the float range, options scanThresholdBlock refuses.
Surface mergeThresholdFragments(const std::vector<ThresholdFragment>& fragments, const ImageGeometry& geometry,
                                const ExtractOptions& options);

}  // namespace surftrack
