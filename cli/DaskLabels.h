// `surftrack labels STORE -o DIR/ --dask ADDRESS`: every label of a chunked store meshed by
// blocks on a Dask cluster (docs/cli.md, "Every label by blocks on Dask"; the proof that the
// blocks merge into the single pass is docs/theory.md, "Label maps by blocks"). The graph is the
// Python package's (surftrack.distributed, run as python3 -m surftrack._cli_dask); this side
// checks the input, fixes the physical frame and the file names as the single pass does, and
// owns the outputs: the reducers write into the staged directory, the table comes back here.
#pragma once

#include <vector>

#include "LabelNames.h"
#include "LabelTable.h"
#include "Options.h"
#include "OutputFile.h"

namespace surftrack::cli {

/// Runs the Dask job for `o` (o.dask set, -o DIR/ staged in `staged`); returns the table's rows
/// in label order, each with its file (DIR/label_<L>.ply, or DIR/<L>_<name>.ply with `names`),
/// which the caller's `staged` then holds. Throws UsageError for an input that is not a chunked
/// store, std::runtime_error (one line) when the Python package cannot be run or the job fails.
std::vector<LabelRow> labelRowsOnDask(const LabelsOptions& o, const LabelNames& names, StagedOutputs& staged);

}  // namespace surftrack::cli
