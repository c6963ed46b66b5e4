// `surftrack labels STORE -o DIR/ --dask ADDRESS` (DaskLabels.h).
#include "DaskLabels.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "DaskJob.h"
#include "PrecomputedOutput.h"

namespace surftrack::cli {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::vector<LabelRow> labelRowsOnDask(const LabelsOptions& o, const LabelNames& names, StagedOutputs& staged) {
  ImageGeometry g;
  json job = storeJob(o.input, o.dask, o.block, o.workDir, g);
  const std::string staging = staged.stagingDirectory();
  job["kind"] = "labels";
  job["background"] = o.background.text();
  job["adjacency"] = toString(o.pair);
  job["staging"] = staging;
  json named = json::object();
  for (const auto& [label, name] : names) named[label.text()] = name;
  job["names"] = named;
  job["binary"] = !o.ascii;
  job["quiet"] = o.out.quiet;
  job["merge_budget"] = o.mergeBudget ? json(*o.mergeBudget) : json(nullptr);
  const bool precomputed = !o.format.empty();
  if (precomputed) {
    // The reduce tasks encode each label as the single pass' writers do (PrecomputedOutput.h),
    // from the same physical vertices, with the same unit.
    job["format"] = o.format;
    job["lods"] = o.format == "precomputed" ? 0 : o.precomputed.lods;
    job["sharded"] = o.precomputed.sharded;
    job["shard_hash"] = o.precomputed.identityHash ? "identity" : "murmurhash3_x86_128";
    job["quantization_bits"] = o.precomputed.quantizationBits;
    job["nanometres"] = nanometresOf({o.unit, job["store_unit"].get<std::string>(), job["store_format"].get<std::string>()});
  }
  const json result = runDaskJob(job, staging, staging);
  if (!result.is_array()) throw std::runtime_error("the Dask driver gave no table");

  const double voxelVolume = std::abs(g.handedness());
  std::vector<LabelRow> rows;
  std::set<std::string> files;
  for (const json& f : result) {
    LabelRow r;
    r.label = *LabelValue::parse(f["label"].get<std::string>());
    r.name = labelName(names, r.label);
    r.voxels = f["voxels"].get<std::uint64_t>();
    r.voxelVolume = double(r.voxels) * voxelVolume;
    r.surfels = f["vertices"].get<std::size_t>();
    r.triangles = f["triangles"].get<std::size_t>();
    r.boundaries = f["boundaries"].get<std::size_t>();
    r.euler = f["euler"].get<long long>();
    r.genus = (2.0 * double(r.boundaries) - double(r.euler)) / 2.0;
    r.area = f["area"].get<double>();
    r.volume = f["volume"].get<double>();
    if (precomputed) {  // the segment's manifest (sharded: the shard file holds it), as the single pass
      r.file = o.precomputed.sharded ? o.output
               : (fs::path(o.output) / (r.label.text() + (o.format == "precomputed" ? ":0" : ".index"))).string();
      rows.push_back(std::move(r));
      continue;
    }
    if (f.contains("levels")) r.mergeLevels = f["levels"].get<int>();  // figures from the tree (--merge-budget)
    if (f["file"].is_null()) {  // over --merge-budget and not written: the row says so, never a silent gap
      r.noFile = f.value("no_file", std::string("over --merge-budget: figures from a tree of blocks, no mesh"));
      rows.push_back(std::move(r));
      continue;
    }
    r.file = (fs::path(o.output) / f["file"].get<std::string>()).string();  // as the single pass names it
    if (!files.insert(r.file).second)
      throw UsageError("two labels give the file name '" + r.file + "': their names are the same");
    staged.temporaryFor(r.file);  // (written there by a reducer)
    rows.push_back(std::move(r));
  }
  std::sort(rows.begin(), rows.end(), [](const LabelRow& a, const LabelRow& b) { return a.label < b.label; });
  return rows;
}

}  // namespace surftrack::cli
