// Where the command line's Neuroglancer outputs put a label's surface (docs/cli.md, "Neuroglancer
// output"): the map of its physical coordinates to nanometres for the legacy format, and for the
// multi-resolution format the voxel indices it stores (its grid lies off the voxel lattice,
// LevelsOfDetail.h) with the map of those to nanometres. Shared by the single pass
// (cli/PrecomputedOutput.cpp) and the block meshing on Dask (python/surftrack/_cli_dask.py), so
// that both write the same bytes.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "Geometry.h"
#include "PrecomputedMesh.h"

namespace surftrack {

/// The legacy format's map: physical coordinates times `nanometresPerUnit`, plus half a voxel
/// along each voxel axis (Neuroglancer draws voxel i over [i, i + 1) where the physical
/// coordinates put its centre at i).
ToNanometres legacyFrame(const ImageGeometry& geometry, double nanometresPerUnit);

/// The multi-resolution format's map: voxel index p is at k (origin + D diag(s) (p + 1/2)) nm.
ToNanometres multiresFrame(const ImageGeometry& geometry, double nanometresPerUnit);

/// A surface's physical vertices as voxel indices (`vertices`), and its triangles (`triangles`)
/// facing out in index space: reversed when the geometry mirrors.
void toVoxelIndices(const ImageGeometry& geometry, std::vector<std::array<double, 3>>& vertices,
                    std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace surftrack
