// The table of `surftrack labels` (docs/cli.md): one row per label, as CSV or JSON.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "LabelValue.h"

#include <nlohmann/json_fwd.hpp>

namespace surftrack::cli {

struct LabelRow {
  LabelValue label;  ///< exact (64-bit ids)
  std::string name;
  std::uint64_t voxels = 0;
  double voxelVolume = 0;  ///< voxels times the physical volume of one voxel
  std::size_t surfels = 0, triangles = 0, boundaries = 0;
  long long euler = 0;     ///< of all its boundaries
  double genus = 0;        ///< sum over its boundaries of (2 - chi) / 2
  double area = 0, volume = 0;  ///< physical: area and volume enclosed by the mesh
  std::string file;        ///< its mesh file ("" in one PLY)
  /// --smooth (shared walls): the enclosed volume before the smoothing and the largest vertex
  /// move, physical units; the table has their columns only when some row is smoothed.
  bool smoothed = false;
  double volumeBeforeSmoothing = 0, maxDisplacement = 0;
  /// --dask --merge-budget: a label over the budget has its figures from a tree of groups of
  /// blocks of this many levels (docs/theory.md, "A label larger than one merge"; -1: merged
  /// whole), and `noFile` says why it has no mesh file when none was written ("" when one was).
  /// The table has the merge_levels and no_file columns only when some row needs them.
  int mergeLevels = -1;
  std::string noFile;
  /// --max-error, --reduce (shared walls): the triangles and the enclosed volume before the
  /// decimation (after the smoothing), the triangles --reduce aimed at (0 without it); a
  /// decimation moves no vertex (the largest move is the smoothing's). Columns only when some
  /// row is decimated.
  bool decimated = false;
  std::size_t trianglesBeforeDecimation = 0, targetTriangles = 0;
  double volumeBeforeDecimation = 0;
  /// --walls shared: where the label touches itself (docs/theory.md §12, "Pinches"), its vertex
  /// copies, its edges of more than two triangles and those of them taken as joined. Columns
  /// only when some row has a pinch.
  std::size_t pinchCopies = 0, pinchedEdges = 0, joinedEdges = 0;
};

/// The table as CSV: a header line, then one line per row (a field with a comma or a quote is
/// quoted).
std::string labelTableCsv(const std::vector<LabelRow>& rows);

/// The table as a JSON array of objects with the CSV's columns as keys.
nlohmann::ordered_json labelTableJson(const std::vector<LabelRow>& rows);

}  // namespace surftrack::cli
