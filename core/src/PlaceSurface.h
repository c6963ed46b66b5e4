// The last stages of an extraction, shared by extract() and extractLabels() (internal to
// core/): a converted mesh placed as a Surface, and its per-component figures.
#pragma once

#include "Extract.h"
#include "TriangleMesh.h"

namespace surftrack {

/// Moves `mesh` into `out`: vertices placed by the boundary mapping (paper §3.1; `epsilon` for
/// the linear one, which reads the gray values from `source`) and then by the source's geometry,
/// triangles oriented from the 1-voxels to the 0-voxels in physical space (a mirrored geometry
/// swaps them); on `threads` threads (0: all cores; the source is then read from several at
/// once), the same vertices for any number.
/// \pre mapping is Midpoint or Linear (not Default).
void placeSurface(const VoxelSource& source, TriangleMesh&& mesh, Mapping mapping,
                  const Selection& selection, double epsilon, Surface& out, int threads = 1);

/// Sets out.components and out.euler from its vertices and triangles. `connected`: they are
/// known to form one component — one boundary tracked from its seed, whose surface graph is
/// connected (trackComponent) and whose every edge lies on a triangulated loop (paper §5.2) —
/// so no union-find is run to find the components.
void addFigures(Surface& out, bool connected = false);

/// The figures of a mesh that is one connected component (componentFigures' sums, in the same
/// order: the same bits).
ComponentFigures connectedMeshFigures(const std::vector<std::array<double, 3>>& vertices,
                                      const std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace surftrack
