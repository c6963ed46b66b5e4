// The command line's --dask (docs/cli.md, "Every label by blocks on Dask"): the graph is the
// Python package's (surftrack.distributed, run as python3 -m surftrack._cli_dask JOB.json);
// this side checks the input, fixes the physical frame and owns the outputs. A job is a JSON
// object: the store and its choices, the frame, the blocks, "kind" ("labels" or "threshold")
// and what that kind needs; the driver writes its result (or {"error": one line}) to a file.
#pragma once

#include <array>
#include <string>

#include <nlohmann/json.hpp>

#include "Geometry.h"
#include "Options.h"

namespace surftrack::cli {

/// The part of a job that names the chunked store `input` and its frame (the store's geometry
/// with --frame, --spacing, --origin applied, returned in `geometry`). Throws UsageError for an
/// input that is not a chunked store, ReadError for one that cannot be opened.
nlohmann::json storeJob(const InputOptions& input, const std::string& dask, std::array<int, 3> block,
                        const std::string& workDir, ImageGeometry& geometry);

/// Runs `job` with the Python package (the one built beside this tool when there is one; the
/// interpreter SURFTRACK_PYTHON, or the one it was built for) and returns its result. Its job
/// and result files are `scratch`.job.json and .result.json (removed at the end, and by a
/// Ctrl-C, which the driver receives too). When the driver fails, `clearOnFailure` (a
/// directory's contents, or a file) is removed before this process handles a pending signal.
/// Throws std::runtime_error (one line: the driver's own error when it gives one).
nlohmann::json runDaskJob(nlohmann::json job, const std::string& scratch, const std::string& clearOnFailure);

}  // namespace surftrack::cli
