// `surftrack demo`: the README's main job in one command. Builds the phantom, tracks its seed's
// surface, writes the mesh and prints the summary; with mricron-data installed, does the same
// for the cortex of a real MRI volume and one region of an atlas, and writes the whole atlas one
// file per region (`surftrack labels`).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "Commands.h"
#include "Extraction.h"
#include "LabelNames.h"
#include "LabelsCommand.h"
#include "OutputFile.h"
#include "Phantoms.h"
#include "Report.h"

namespace surftrack::cli {

namespace {

namespace fs = std::filesystem;

/// The cortical surface of ch2better.nii.gz (the Colin27 T1 MRI, skull-stripped, uint8,
/// 0.5 mm voxels). Its histogram ('surftrack info --json') has the background at 0 (63 % of the
/// voxels) and, inside the brain (51-130), a gray-matter peak at 86 and a white-matter peak at
/// 114 with a shallow valley between them; iso-value 100, about halfway, gives the gray/white-matter interface of
/// the cortex (the "white" surface). The largest boundary is the cerebral one.
constexpr double kCortexIso = 100;
/// The AAL atlas region extracted: label 1, the left precentral gyrus (aal.nii.txt).
constexpr int kAtlasLabel = 1;

struct DemoPart {
  std::string title;
  std::string input;      ///< file name, or the phantom's description
  std::string output;     ///< file in the demo directory
  std::string command;    ///< the equivalent `surftrack mesh` command line
};

struct DemoRun {
  DemoPart part;
  Extraction extraction;
};

Extraction extract(const io::AnyVolume& volume, const std::string& inputName, const SurfaceOptions& options,
                   const std::string& output, const OutputOptions& out, double readSeconds) {
  Extraction x;
  x.output = output;
  x.format = meshFormat(output);
  x.binary = true;
  requireWritable(output);
  Progress progress(Progress::wanted(out.quiet));
  StageClock clock;
  x.timings.push_back({"read", readSeconds});
  const io::LoadedVolume loaded = inMemory(volume);
  describeInput(loaded, inputName, x);
  const int stages = extractionStages(options) + 1;  // + write
  extractSurface(loaded.view, options, x, clock, progress, 0, stages);
  progress.stage(stages - 1, stages, "writing " + output);
  x.bytes = writeMeshFile(x.surface, output, x.binary);
  clock.lap(x.timings, "write");
  x.totalSeconds = clock.total() + readSeconds;
  progress.finish();
  return x;
}

std::string quoteArg(const std::string& s) {
  if (s.find_first_of(" '\"$\\") == std::string::npos) return s;
  std::string out = "'";
  for (char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

}  // namespace

int runDemo(const std::vector<std::string>& args) {
  const DemoOptions o = parseDemoOptions(args);
  std::error_code ec;
  fs::create_directories(o.outputDir, ec);
  if (ec || !fs::is_directory(o.outputDir))
    throw std::runtime_error("cannot create the demo directory '" + o.outputDir + "'" +
                             (ec ? ": " + ec.message() : ""));
  const fs::path dir(o.outputDir);
  std::vector<DemoRun> runs;
  std::vector<std::string> notes;
  LabelsRun atlasRegions;
  std::string atlasCommand;

  // 1. The phantom.
  {
    StageClock clock;
    const SphereMinusCylinders phantom = makeSphereMinusCylinders(o.size, o.noise);
    const std::string volumePath = (dir / "phantom.nrrd").string();
    io::writeVolume(io::AnyVolume(phantom.image), volumePath);
    const double buildSeconds = clock.total();
    SurfaceOptions s;
    s.iso = phantom.iso;
    s.seedMode = SeedMode::Surfel;
    s.seedVoxel = phantom.seed.inside();
    s.seedDirection = phantom.seed.n;
    const std::string mesh = (dir / "phantom.ply").string();
    std::ostringstream name;
    name << "phantom " << o.size << "^3, sphere minus 3 cylinders, " << o.noise * 100 << " % noise (" << volumePath << ")";
    DemoRun run{{"phantom (Figure 6c: sphere minus cylinders, salt-and-pepper noise)", volumePath, mesh, ""}, extract(io::AnyVolume(phantom.image), name.str(), s, mesh, o.out, 0)};
    run.extraction.timings.front() = {"build", buildSeconds};
    run.extraction.totalSeconds += buildSeconds;
    const Voxel c = phantom.seed.inside();
    run.part.command = "surftrack mesh " + quoteArg(volumePath) + " -o " + quoteArg(mesh) + " --iso 127.5 --seed " +
                       std::to_string(c.x) + "," + std::to_string(c.y) + "," + std::to_string(c.z) + ",+x";
    runs.push_back(std::move(run));
  }

  // 2. and 3. The real MRI volumes of mricron-data.
  const fs::path mricron(o.mricronDir);
  const fs::path brain = mricron / "ch2better.nii.gz", atlas = mricron / "aal.nii.gz";
  if (!o.realData) {
    notes.push_back("--no-mricron: the MRI part was skipped");
  } else if (!fs::exists(brain) || !fs::exists(atlas)) {
    notes.push_back("mricron-data is not installed (no " + brain.string() +
                    "): the MRI part was skipped; 'apt-get install mricron-data' adds it");
  } else {
    {
      StageClock clock;
      const io::AnyVolume volume = io::readVolume(brain.string());
      const double readSeconds = clock.total();
      SurfaceOptions s;
      s.iso = kCortexIso;
      s.seedMode = SeedMode::Largest;
      const std::string mesh = (dir / "cortex.ply").string();
      DemoRun run{{"cortex (gray/white-matter interface)", brain.string(), mesh, ""}, extract(volume, brain.string(), s, mesh, o.out, readSeconds)};
      run.part.command = "surftrack mesh " + quoteArg(brain.string()) + " -o " + quoteArg(mesh) + " --iso " +
                         std::to_string(int(kCortexIso)) + " --largest";
      runs.push_back(std::move(run));
    }
    {
      StageClock clock;
      const io::AnyVolume volume = io::readVolume(atlas.string());
      const double readSeconds = clock.total();
      SurfaceOptions s;
      s.label = kAtlasLabel;
      s.seedMode = SeedMode::Largest;
      const auto sidecar = labelNamesSidecar(atlas.string());
      const std::string name = labelName(sidecar ? readLabelNames(*sidecar) : LabelNames{}, kAtlasLabel);
      const std::string mesh = (dir / ("aal-" + name + ".ply")).string();
      DemoRun run{{"atlas region " + std::to_string(kAtlasLabel) + " (" + name + ")", atlas.string(), mesh, ""},
                  extract(volume, atlas.string(), s, mesh, o.out, readSeconds)};
      run.part.command = "surftrack mesh " + quoteArg(atlas.string()) + " -o " + quoteArg(mesh) + " --label " +
                         std::to_string(kAtlasLabel) + " --largest";
      runs.push_back(std::move(run));
    }
    {
      // 4. The whole atlas, one file per region named from aal.nii.txt (`surftrack labels`). The
      // directory is the demo's own: replaced when it holds an earlier demo's regions.
      const fs::path regions = dir / "aal-regions";
      if (fs::exists(regions / "labels.csv")) fs::remove_all(regions);
      LabelsOptions l;
      l.input.path = atlas.string();
      l.output = regions.string() + "/";
      atlasRegions = writeLabelMeshes(l);
      atlasCommand = "surftrack labels " + quoteArg(atlas.string()) + " -o " + quoteArg(l.output);
    }
  }

  std::size_t regionSurfels = 0, regionBoundaries = 0;
  for (const LabelRow& r : atlasRegions.rows) regionSurfels += r.surfels, regionBoundaries += r.boundaries;
  if (o.out.json) {
    nlohmann::ordered_json json;
    json["output_dir"] = o.outputDir;
    json["results"] = nlohmann::ordered_json::array();
    for (const auto& r : runs) {
      nlohmann::ordered_json result;
      result["name"] = r.part.title;
      result["command"] = r.part.command;
      result["result"] = extractionJson(r.extraction);
      json["results"].push_back(std::move(result));
    }
    if (!atlasRegions.rows.empty()) {
      nlohmann::ordered_json regions;
      regions["title"] = "atlas regions, one file each";
      regions["command"] = atlasCommand;
      regions["output"] = (dir / "aal-regions").string();
      regions["regions"] = atlasRegions.rows.size();
      regions["boundaries"] = regionBoundaries;
      regions["surfels"] = regionSurfels;
      json["atlas_regions"] = std::move(regions);
    }
    json["notes"] = notes;
    std::cout << jsonText(json) << std::endl;
  } else if (!o.out.quiet) {
    for (const auto& r : runs) {
      std::cout << "== " << r.part.title << "\n";
      printSummary(std::cout, r.extraction);
      std::cout << "  same as   " << r.part.command << "\n\n";
    }
    if (!atlasRegions.rows.empty()) {
      std::cout << "== atlas regions, one file each\n  regions   " << atlasRegions.rows.size() << " ("
                << regionBoundaries << " boundaries, " << regionSurfels << " surfels) in "
                << (dir / "aal-regions").string() << "/, e.g. " << fs::path(atlasRegions.rows.front().file).filename().string()
                << "\n  same as   " << atlasCommand << "\n\n";
    }
    for (const auto& n : notes) std::cout << "note: " << n << "\n";
    const std::size_t meshes = runs.size() + atlasRegions.rows.size();
    std::cout << "demo: " << meshes << " mesh" << (meshes == 1 ? "" : "es") << " written to "
              << o.outputDir << "/\n";
  }
  return 0;
}

}  // namespace surftrack::cli
