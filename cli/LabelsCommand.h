// The work of `surftrack labels` (docs/cli.md), shared with `surftrack demo`: a label volume
// file to its meshes and table.
#pragma once

#include <string>
#include <vector>

#include "Extraction.h"
#include "LabelTable.h"
#include "Options.h"

namespace surftrack::cli {

struct LabelsRun {
  std::vector<LabelRow> rows;        ///< one per label, by increasing label
  std::vector<StageTiming> timings;  ///< read, extract, write
  std::string namesFile;             ///< where the names came from ("" for none)
};

/// Reads o.input, extracts the selected labels and writes their meshes and tables: all of them
/// or, on an error, none (a directory of outputs is staged and moved in whole).
/// \throw UsageError, surftrack::InvalidInput, std::runtime_error (one line each).
LabelsRun writeLabelMeshes(const LabelsOptions& o);

}  // namespace surftrack::cli
