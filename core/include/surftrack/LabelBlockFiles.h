// Label maps by blocks through files (docs/api.md, "Label maps by blocks"; docs/theory.md,
// "Label maps by blocks" and "A label larger than one merge"): a block's fragments in one flat
// binary file, a label's fragments merged straight from the files, and the exact figures of a
// label too large for one merge, computed over a tree of groups of blocks.
//
//   writeLabelFragmentFile(path, volume, lo, hi, scanLabelBlock(view, origin, volume, lo, hi, o));
//   LabelSurface s = mergeLabelFragmentFiles(label, paths, geometry, o);       // as extractLabels
//   LabelFigures f = labelFiguresByTree(label, paths, volume, block, geometry, o, budget);
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "Extract.h"
#include "LabelValue.h"
#include "Labels.h"
#include "Voxel.h"

namespace surftrack {

/// What a fragment file's header and index say (the data are read per label, on demand).
struct FragmentFileIndex {
  Dims volume;
  Voxel lo, hi;  ///< the block's core
  struct Entry {
    LabelValue label;
    std::uint64_t voxels = 0, keys = 0, triangles = 0;
    std::uint64_t offset = 0;    ///< of the label's keys in the file; its triangles follow them
    std::uint64_t checksum = 0;  ///< of the keys' and triangles' bytes
  };
  std::vector<Entry> entries;  ///< by increasing label
  /// The entry of `label`, or null.
  const Entry* find(LabelValue label) const;
};

/// Writes the fragments of one block (scanLabelBlock's, labels increasing) to `path`: a
/// header (magic, format version, volume, core, label count, file length, checksum), an index
/// (label, voxels, counts, data checksum per label), then each label's keys (uint64) and
/// triangles (3 x uint32), little-endian. The same fragments give the same bytes; written to a
/// temporary file in the same directory and renamed over `path`, so `path` is whole or absent.
/// \throw InvalidInput for labels not increasing; std::runtime_error naming the path when it
///        cannot be written.
void writeLabelFragmentFile(const std::string& path, Dims volume, Voxel lo, Voxel hi,
                            const std::vector<LabelFragment>& fragments);

/// The header and index of a fragment file, checked: magic, version, lengths against the
/// file's size, the index's checksum. \throw InvalidInput naming the path and what is wrong
/// (missing, not a fragment file, another version, truncated, corrupted).
FragmentFileIndex readFragmentFileIndex(const std::string& path);

/// The fragment of `entry` (of readFragmentFileIndex(path)), its data checksum, keys and
/// triangle indices checked. \throw InvalidInput naming the path when the data are truncated
/// or corrupted.
LabelFragment readLabelFragment(const std::string& path, const FragmentFileIndex::Entry& entry);

/// mergeLabelFragments over the fragments of `label` in these files (a file without it is
/// skipped): the LabelSurface extractLabels gives for `label`. \throw InvalidInput as
/// readFragmentFileIndex, readLabelFragment and mergeLabelFragments, or when no file holds it.
LabelSurface mergeLabelFragmentFiles(LabelValue label, const std::vector<std::string>& paths,
                                     const ImageGeometry& geometry, const LabelOptions& options);

/// A label's figures without its mesh (docs/theory.md, "A label larger than one merge").
struct LabelFigures {
  LabelValue label;
  std::uint64_t voxels = 0;
  /// As Surface::components of extractLabels' surface: counts and Euler characteristics
  /// exactly, by decreasing vertex count (ties: the smallest vertex first); area and volume
  /// the same sums in another order (equal up to rounding).
  std::vector<ComponentFigures> components;
  int levels = 0;      ///< of the tree of groups above its leaves (0: one merge)
  std::size_t leaves = 0;  ///< merges of groups of fragments
};

/// The figures of `label` from its fragment files (blocks of a regular grid of `block` voxels
/// cut from the volume's low corner, as written by writeLabelFragmentFile) without holding its
/// mesh: the grid's blocks are grouped into an octree (cells of 2^k blocks a side); a cell
/// whose fragments of the label take at most `budget` bytes, or of one block, is merged into a
/// partial result (its components' integer counts, area and volume sums, and the keys on the
/// cell's outer border with their components); partials of sibling cells are combined, their
/// components joined through the shared border keys, up to the root.
/// \throw InvalidInput as readFragmentFileIndex; for files of another volume or grid, two files
///        of one block, or no file holding the label.
LabelFigures labelFiguresByTree(LabelValue label, const std::vector<std::string>& paths, Dims volume, Dims block,
                                const ImageGeometry& geometry, const LabelOptions& options, std::uint64_t budget);

/// What writeLabelMeshStreamed wrote.
struct LabelMeshCounts {
  std::uint64_t vertices = 0, triangles = 0;
};

/// Writes the mesh of `label` from its fragment files to `path` (binary .ply) with bounded
/// memory (docs/theory.md, "A label larger than one merge", "Its mesh, streamed"): the bytes
/// writeSurface(mergeLabelFragmentFiles(label, paths, geometry, o).surface, path) writes,
/// without that surface in memory. The vertices come from a k-way merge of the fragments' keys,
/// the triangles from a k-way merge of the fragments' triangles by owning cube, renumbered
/// through a file of vertex numbers beside `path`; each fragment is read a chunk at a time from
/// when the merge reaches its block, the chunk sized so that the chunks of a plane of blocks
/// take about `budget` bytes (16 to 65,536 items). Atomic (writeFileAtomically); the
/// temporary files beside `path` are removed. The closed-manifold check writeSurface makes is
/// not made (it needs the whole mesh): the fragments are checked as readLabelFragment checks
/// them, and their triangles must come in the block scan's order of cubes.
/// \throw InvalidInput as readFragmentFileIndex and readLabelFragment, for two files of one
///        block, no file holding the label, or a path that is not .ply; std::runtime_error
///        (FileWriteError) when a file cannot be written; Cancelled.
LabelMeshCounts writeLabelMeshStreamed(LabelValue label, const std::vector<std::string>& paths,
                                       const ImageGeometry& geometry, const std::string& path, std::uint64_t budget,
                                       const std::atomic<bool>* cancel = nullptr);

}  // namespace surftrack
