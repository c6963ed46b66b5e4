// The Neuroglancer outputs of `labels` and `mesh` (docs/cli.md, "Neuroglancer output"): the
// map to nanometres from the volume's geometry and unit, and the writing in either format.
#pragma once

#include <string>
#include <vector>

#include "Extract.h"
#include "Options.h"
#include "PrecomputedMesh.h"

namespace surftrack::cli {

/// The unit of the spacing: --unit, else the one the file states, else mm for the medical
/// formats (ITK's); a raw file has none. \throw UsageError when there is none or it is not a length.
struct SpacingUnit {
  std::string option;      ///< --unit ("" if not given)
  std::string fileUnit;    ///< as the file states it ("" if not)
  std::string fileFormat;  ///< "raw", "nii", "zarr", ...
};

/// Nanometres per unit of the spacing. \throw UsageError as SpacingUnit says.
double nanometresOf(const SpacingUnit& unit);

/// One segment to write: its id, its surface (physical coordinates) and its name.
struct OutputSegment {
  LabelValue id;
  const Surface* surface = nullptr;
  std::string name;
};

/// Writes `segments` at `directory` in `format` ("precomputed" or "precomputed-multires"),
/// whole or not at all. The legacy format stores the physical coordinates mapped to nanometres
/// with half a voxel added (Neuroglancer draws voxel i over [i, i + 1)); the multi-resolution
/// format stores voxel indices (its grid off the voxel lattice, LevelsOfDetail.h) and the map of
/// the voxel corner to nanometres as its transform, so both put the meshes in the same place.
void writePrecomputedOutput(const std::vector<OutputSegment>& segments, const std::string& directory,
                            const std::string& format, const ImageGeometry& geometry, const SpacingUnit& unit,
                            const PrecomputedOptions& options);

}  // namespace surftrack::cli
