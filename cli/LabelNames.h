// The names of an atlas's labels (docs/cli.md, "surftrack labels"): a plain text table of
// lines `value name [anything else]`, as mricron-data's `aal.nii.txt` and the `--label-names`
// file give them.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "LabelValue.h"

namespace surftrack::cli {

using LabelNames = std::map<LabelValue, std::string>;

/// The table in `path`. Blank lines and lines starting with '#' are skipped.
/// \throw std::runtime_error (one line, naming the file and the line) when the file cannot be
///        read or a line is not `integer name ...`.
LabelNames readLabelNames(const std::string& path);

/// The sidecar table of an atlas volume, if there is one: for `dir/aal.nii.gz`, `dir/aal.nii.txt`
/// or `dir/aal.txt`; for `dir/x.nrrd`, `dir/x.txt`. (A `.lut` next to it holds colours, not names.)
std::optional<std::string> labelNamesSidecar(const std::string& volumePath);

/// The name of `label` in `names`, or "label<N>".
std::string labelName(const LabelNames& names, const LabelValue& label);

}  // namespace surftrack::cli
