// A scanned label's Surface around its vertices and triangles (internal to core/), shared by
// the single pass (Labels.cpp, scanAll) and the merge of a label's block fragments
// (LabelBlocks.cpp), so that both give the same Surface field for field (docs/theory.md,
// "Label maps by blocks").
#pragma once

#include <utility>

#include "Labels.h"
#include "MeshComponents.h"
#include "PlaceSurface.h"

namespace surftrack {

/// The fields of a label's result that do not depend on how its mesh was made (but the
/// vertices, triangles and surfels).
inline LabelSurface labelFields(const ImageGeometry& geometry, LabelValue label, std::uint64_t voxels,
                                const LabelOptions& o) {
  LabelSurface result;
  result.label = label;
  result.voxels = voxels;
  Surface& s = result.surface;
  s.geometry = geometry;  // the segments smoothing keeps each vertex on (Refine.h)
  s.pair = o.pair;
  s.selection = Selection::label(label);
  s.mapping = Mapping::Midpoint;
  return result;
}

/// The last stage of a label's mesh from the scan of the cubes (triangles in the table's
/// orientation): the normals kept pointing outwards under a mirrored geometry (as placeSurface
/// does), its figures if asked for, and its boundaries: its components (Proposition 39).
inline void finishScannedLabel(Surface& s, bool mirrored, const LabelOptions& o) {
  if (mirrored)
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
  if (o.figures) addFigures(s);
  std::size_t boundaries = s.components.size();
  if (!o.figures) triangleComponents(s.vertices.size(), s.triangles, boundaries);
  s.boundariesInImage = boundaries;
}

}  // namespace surftrack
