// `surftrack labels INPUT -o OUTPUT [options]`: extractLabels (docs/api.md, "Label maps") on a
// volume file, the meshes written one file per label or as one PLY, with a table per label.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <variant>

#include <nlohmann/json.hpp>

#include "LabelsCommand.h"

#include "Commands.h"
#include "DaskLabels.h"
#include "LabelNames.h"
#include "Labels.h"
#include "MeshIO.h"
#include "OutputFile.h"
#include "PrecomputedOutput.h"
#include "Report.h"

namespace surftrack::cli {

namespace {

namespace fs = std::filesystem;

enum class OutputKind { Directory, Pattern, OnePly };

OutputKind outputKind(const std::string& output) {
  if (output.find("{label}") != std::string::npos || output.find("{name}") != std::string::npos)
    return OutputKind::Pattern;
  std::error_code ec;
  if (output.back() == '/' || fs::is_directory(output, ec)) return OutputKind::Directory;
  if (meshFormat(output) != "ply")
    throw UsageError("one file of every label must be .ply (it carries a label per face): '" + output +
                     "'; give DIR/ or a pattern with {label} for other formats");
  return OutputKind::OnePly;
}

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
}

/// A name as part of a file name: '/' and spaces become '_'.
std::string fileSafe(std::string name) {
  for (char& ch : name)
    if (ch == '/' || ch == ' ' || ch == '\\') ch = '_';
  return name;
}

std::string tableText(const std::string& path, const std::vector<LabelRow>& rows) {
  return fs::path(path).extension() == ".json" ? jsonText(labelTableJson(rows)) + "\n" : labelTableCsv(rows);
}

}  // namespace

LabelsRun writeLabelMeshes(const LabelsOptions& o) {
  // Everything that can be checked before the work is.
  const bool precomputed = !o.format.empty();  // precomputed, precomputed-multires
  const OutputKind kind = precomputed ? OutputKind::Directory : outputKind(o.output);
  if (kind == OutputKind::Pattern) {
    meshFormat(o.output);
    const std::string dir = fs::path(o.output).parent_path().string();  // when the pattern does not vary it
    if (dir.find('{') == std::string::npos) requireWritableDirectory(dir.empty() ? "." : dir, o.output);
  }
  if (kind == OutputKind::OnePly) requireWritable(o.output);
  if (!o.table.empty()) {
    const std::string ext = fs::path(o.table).extension().string();
    if (ext != ".csv" && ext != ".json")
      throw UsageError("--table '" + o.table + "': the extension must be .csv or .json");
    requireWritable(o.table);
  }
  LabelNames names;
  std::string namesFile;
  if (!o.labelNames.empty()) {
    namesFile = o.labelNames;
  } else if (!o.noNames) {
    if (const auto sidecar = labelNamesSidecar(o.input.path)) namesFile = *sidecar;
  }
  // No output may be an input (the volume, the names): the files of a pattern are checked once
  // their names are known, before any is written.
  const std::vector<std::string> inputs = {o.input.path, namesFile};
  auto requireNoInput = [&](const std::string& output) {
    for (const std::string& input : inputs) requireNotInput(output, input);
  };
  if (kind == OutputKind::OnePly) requireNoInput(o.output);
  if (!o.table.empty()) requireNoInput(o.table);
  if (!namesFile.empty()) names = readLabelNames(namesFile);
  if (precomputed) requireOutputDirectory(o.output);  // before the work
  // The single pass' precomputed writers stage their own directory; on Dask the tasks write
  // into this one (DaskLabels.h).
  StagedOutputs staged = kind == OutputKind::Directory && (!precomputed || !o.dask.empty())
                             ? StagedOutputs::inDirectory(o.output)
                             : StagedOutputs();

  StageClock clock;
  LabelsRun run;
  run.namesFile = namesFile;
  std::vector<StageTiming>& timings = run.timings;
  if (!o.dask.empty()) {
    // By blocks on Dask: the same files and table, no volume in this process (DaskLabels.h).
    if (kind != OutputKind::Directory)
      throw UsageError("--dask writes -o DIR/ (one file per label), not '" + o.output + "'");
    if (o.walls != "independent") throw UsageError("--walls shared is not made by blocks yet: no --dask");
    run.rows = labelRowsOnDask(o, names, staged);
    clock.lap(timings, "dask");
    const auto unwritten = std::count_if(run.rows.begin(), run.rows.end(), [](const LabelRow& r) { return !r.noFile.empty(); });
    if (unwritten && !o.out.quiet)
      std::cerr << "surftrack: warning: " << unwritten << " label" << (unwritten == 1 ? "" : "s")
                << " over --merge-budget have figures but no mesh file (the table's no_file column says why)\n";
    if (!precomputed)  // a Neuroglancer directory holds its format's files only, as the single pass writes it
      writeTextFile(staged.temporaryFor((fs::path(o.output) / "labels.csv").string()), labelTableCsv(run.rows));
    staged.commit();
    if (!o.table.empty()) writeTextFile(o.table, tableText(o.table, run.rows));
    clock.lap(timings, "write");
    return run;
  }
  const io::LoadedVolume volume = readInput(o.input);  // mapped or decoded, never copied
  if (!o.out.quiet)
    for (const std::string& w : volume.warnings) std::cerr << "surftrack: warning: " << w << "\n";
  clock.lap(timings, "read");
  const VolumeView& view = volume.view;

  LabelOptions options;
  if (o.range) options.labels = LabelSelection::range((*o.range)[0], (*o.range)[1]);
  else if (!o.labels.empty()) options.labels = LabelSelection::list(o.labels);
  options.background = o.background;
  options.boundaries = o.largest ? LabelBoundaries::Largest : LabelBoundaries::All;
  options.seeds = o.seeds;
  options.pair = o.pair;
  options.walls = o.walls == "shared" ? LabelWalls::Shared : LabelWalls::Independent;
  options.threads = o.threads;
  if (o.smoothIterations > 0) {  // the complex's smoothing (docs/theory.md §12)
    SmoothOptions so;
    so.iterations = o.smoothIterations;
    so.threads = o.threads;
    options.smooth = so;
  }
  if (o.maxError || o.reduction) {  // the complex's decimation (docs/theory.md §12, "Decimating the complex")
    DecimateOptions d;
    d.maxError = o.maxError;
    d.reduction = o.reduction;
    options.decimate = d;
  }
  const std::vector<LabelSurface> surfaces = extractLabels(view, options);
  if (!o.out.quiet) {
    // The pinches of shared walls in one line (the table has them label by label), the other
    // warnings as they are.
    std::size_t pinchedLabels = 0, copies = 0, pinchedEdges = 0, joined = 0;
    for (const LabelSurface& l : surfaces) {
      const bool pinched = l.pinchCopies || l.pinchedEdges;
      pinchedLabels += pinched, copies += l.pinchCopies, pinchedEdges += l.pinchedEdges, joined += l.joinedEdges;
      for (const std::string& w : l.surface.warnings)
        if (!pinched || w.rfind("label " + l.label.text() + " touches itself", 0) != 0)
          std::cerr << "surftrack: warning: " << w << "\n";
    }
    if (pinchedLabels)
      std::cerr << "surftrack: warning: " << pinchedLabels << " label" << (pinchedLabels == 1 ? " touches itself" : "s touch themselves")
                << " (pinches, docs/theory.md §12): " << copies << " vertex copies, " << pinchedEdges << " pinched edges, "
                << joined << " taken as joined; the table's pinch columns list them\n";
  }
  clock.lap(timings, "extract");

  // The rows, and the file of each label.
  const double voxelVolume = std::abs(view.geometry.handedness());
  std::vector<LabelRow>& rows = run.rows;
  std::set<std::string> files;
  for (const LabelSurface& ls : surfaces) {
    LabelRow r;
    r.label = ls.label;
    r.name = labelName(names, r.label);
    r.voxels = ls.voxels;
    r.voxelVolume = double(ls.voxels) * voxelVolume;
    const Surface& s = ls.surface;
    r.surfels = s.surfels.size();
    r.triangles = s.triangles.size();
    r.boundaries = s.components.size();
    r.euler = s.euler;
    r.genus = (2.0 * double(s.components.size()) - double(s.euler)) / 2.0;
    for (const ComponentFigures& c : s.components) {
      r.area += c.area;
      r.volume += c.volume;
    }
    if (ls.smooth) {
      r.smoothed = true;
      r.volumeBeforeSmoothing = ls.smooth->volumeBefore;
      r.maxDisplacement = ls.smooth->maxDisplacement;
    }
    if (ls.decimate) {
      r.decimated = true;
      r.trianglesBeforeDecimation = ls.decimate->trianglesBefore;
      r.targetTriangles = ls.decimate->targetTriangles;
      r.volumeBeforeDecimation = ls.decimate->volumeBefore;
    }
    r.pinchCopies = ls.pinchCopies;
    r.pinchedEdges = ls.pinchedEdges;
    r.joinedEdges = ls.joinedEdges;
    if (precomputed) {
      // The segment's manifest (unsharded; sharded, the shard file holds it).
      r.file = o.precomputed.sharded ? o.output
               : (fs::path(o.output) / (r.label.text() + (o.format == "precomputed" ? ":0" : ".index"))).string();
    } else if (kind != OutputKind::OnePly) {
      std::string file = kind == OutputKind::Pattern ? o.output
                         : names.empty()             ? (fs::path(o.output) / "label_{label}.ply").string()
                                                     : (fs::path(o.output) / "{label}_{name}.ply").string();
      replaceAll(file, "{label}", r.label.text());
      replaceAll(file, "{name}", fileSafe(r.name));
      if (!files.insert(file).second)
        throw UsageError("two labels give the file name '" + file + "': put {label} in the pattern");
      requireNoInput(file);
      r.file = file;
    }
    rows.push_back(std::move(r));
  }

  const bool binary = !o.ascii;
  if (precomputed) {
    std::vector<OutputSegment> segments;
    for (const LabelSurface& ls : surfaces) {  // named segments only where names were given
      const auto named = names.find(ls.label);
      segments.push_back({ls.label, &ls.surface, named == names.end() ? "" : named->second});
    }
    writePrecomputedOutput(segments, o.output, o.format, volume.view.geometry, {o.unit, volume.unit, volume.format},
                           o.precomputed);
  } else if (kind == OutputKind::OnePly) {
    writeLabelSurfaces(surfaces, o.output, binary);
  } else {
    // A mesh file holds a 2-manifold; shared walls may leave a label edges of four triangles
    // (docs/theory.md §12), which only the one PLY of every label carries.
    for (const LabelSurface& ls : surfaces)
      if (ls.unsplitEdges)
        throw InvalidInput("label " + ls.label.text() + " has " + std::to_string(ls.unsplitEdges) +
                           " edges of four triangles with --walls shared (it touches itself along them): write every "
                           "label to one .ply (-o FILE.ply) instead");
    for (std::size_t i = 0; i < surfaces.size(); ++i) writeSurface(surfaces[i].surface, staged.temporaryFor(rows[i].file), binary);
    if (kind == OutputKind::Directory) writeTextFile(staged.temporaryFor((fs::path(o.output) / "labels.csv").string()), labelTableCsv(rows));
    staged.commit();
  }
  if (!o.table.empty()) writeTextFile(o.table, tableText(o.table, rows));
  clock.lap(timings, "write");
  return run;
}

int runLabels(const std::vector<std::string>& args) {
  const LabelsOptions o = parseLabelsOptions(args);
  const LabelsRun run = writeLabelMeshes(o);
  const std::vector<LabelRow>& rows = run.rows;
  const std::string& namesFile = run.namesFile;
  if (o.out.json) {
    nlohmann::ordered_json j;
    j["input"] = o.input.path;
    j["output"] = o.output;
    j["names"] = namesFile;
    j["adjacency"] = toString(o.pair);
    j["walls"] = o.walls;
    if (o.smoothIterations > 0) j["smooth_iterations"] = o.smoothIterations;
    if (o.maxError) j["max_error"] = number(*o.maxError);
    if (o.reduction) j["reduce"] = number(*o.reduction);
    j["labels"] = labelTableJson(rows);
    nlohmann::ordered_json t = nlohmann::ordered_json::object();
    for (const StageTiming& s : run.timings) t[s.name] = number(s.seconds);
    j["seconds"] = t;
    std::cout << jsonText(j) << std::endl;
  } else if (!o.out.quiet) {
    std::size_t surfels = 0, boundaries = 0;
    for (const LabelRow& r : rows) surfels += r.surfels, boundaries += r.boundaries;
    std::cout << "surftrack labels: " << rows.size() << " label" << (rows.size() == 1 ? "" : "s") << ", "
              << boundaries << " boundaries, " << surfels << " surfels -> " << o.output << "\n";
    if (!namesFile.empty()) std::cout << "  names      " << namesFile << "\n";
    for (const StageTiming& s : run.timings)
      std::cout << "  " << std::left << std::setw(11) << s.name << std::right << num(s.seconds, 3) << " s\n";
  }
  return 0;
}

}  // namespace surftrack::cli
