// `surftrack mesh INPUT -o OUTPUT [options]`.
#include <filesystem>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ChunkedSource.h"
#include "Commands.h"
#include "DaskJob.h"
#include "Extraction.h"
#include "OutputFile.h"
#include "PrecomputedOutput.h"
#include "Report.h"

namespace surftrack::cli {

namespace {

/// A seeded extraction with --iso or --label from a chunked store, read lazily: only the chunks
/// the surface crosses are decoded, through a cache of --cache MiB (docs/cli.md, "Input formats").
void extractLazily(const MeshOptions& o, Extraction& x, StageClock& clock, Progress& progress, int stages,
                   SpacingUnit& unit) {
  const io::ChunkedStore store = io::openChunkedStore(o.input.path, chunkedStoreOptions(o.input));
  const auto cache = std::make_shared<const ChunkCache>(store.provider, std::size_t(o.cacheMiB) << 20);
  const ChunkLayout& layout = cache->layout();
  ImageGeometry geometry = layout.geometry;
  x.frame = applyGeometryOptions(o.input, geometry, x.frame);
  const std::unique_ptr<VoxelSource> chunked = makeChunkedSource(cache, geometry);
  const VoxelSource& source = *chunked;
  clock.lap(x.timings, "read");
  x.input = o.input.path;
  unit.fileUnit = store.unit;
  unit.fileFormat = store.format;
  x.dims = layout.dims;
  x.type = layout.type;
  x.geometry = geometry;
  const std::string choice = store.choiceText();
  x.storage = "chunked " + store.format + " (" + store.compressor + (choice.empty() ? "" : ", " + choice) +
              "), read lazily";
  const Dims counts = layout.chunkCounts();
  x.chunkCount = std::uint64_t(counts.nx) * std::uint64_t(counts.ny) * std::uint64_t(counts.nz);
  x.voxelBytes = layout.dims.count() * sizeOf(layout.type);
  extractSurface(source, nullptr, o.surface, x, clock, progress, 1, stages);
  x.chunks = cache->counters();
  x.voxelBytesRead = std::min<std::uintmax_t>(
      x.chunks->chunksDecoded * std::uint64_t(layout.chunk.count()) * sizeOf(layout.type), x.voxelBytes);
}

/// The bytes of the files under `directory` (a Neuroglancer output).
std::uintmax_t directoryBytes(const std::string& directory) {
  std::uintmax_t total = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(directory))
    if (entry.is_regular_file()) total += entry.file_size();
  return total;
}

/// `--all -o DIR/` (a path ending in '/' or an existing directory): one file per boundary.
/// Without --all, a path ending in '/' is refused; an existing directory is the error of any
/// unwritable file (OutputFile.h).
bool perBoundaryOutput(const MeshOptions& o) {
  if (!o.format.empty() || o.output.empty()) return false;
  std::error_code ec;
  const bool all = o.surface.seedMode == SeedMode::All;
  if (o.output.back() == '/' && !all)
    throw UsageError("-o DIR/ writes one file per boundary: give --all, or -o FILE for one mesh");
  return all && (o.output.back() == '/' || std::filesystem::is_directory(o.output, ec));
}

/// The file of the k-th boundary (from 1, the components' order) in -o DIR/.
std::string boundaryFile(const std::string& directory, std::size_t k) {
  return (std::filesystem::path(directory) / ("boundary_" + std::to_string(k) + ".ply")).string();
}

/// DIR/boundaries.csv: a row per boundary (its figures, physical area and volume, its file).
std::string boundaryTableCsv(const std::vector<ComponentFigures>& boundaries, const std::string& directory) {
  std::ostringstream out;
  out << "boundary,vertices,triangles,edges,euler,genus,area,volume,file\n";
  for (std::size_t k = 0; k < boundaries.size(); ++k) {
    const ComponentFigures& c = boundaries[k];
    out << k + 1 << ',' << c.surfels << ',' << c.triangles << ',' << c.edges << ',' << c.euler << ','
        << num(c.genus()) << ',' << num(c.area, 10) << ',' << num(c.volume, 10) << ','
        << boundaryFile(directory, k + 1) << '\n';
  }
  return out.str();
}

/// The boundaries' files and table written into `staged` (-o DIR/, the single pass).
void writeBoundaryFiles(const Surface& surface, const std::string& directory, bool binary, StagedOutputs& staged) {
  std::vector<std::string> temporaries;
  for (std::size_t k = 1; k <= surface.components.size(); ++k)
    temporaries.push_back(staged.temporaryFor(boundaryFile(directory, k)));
  writeSurfaceComponents(surface, temporaries, binary);
  writeTextFile(staged.temporaryFor((std::filesystem::path(directory) / "boundaries.csv").string()),
                boundaryTableCsv(surface.components, directory));
}

}  // namespace

/// `mesh STORE --all --iso S --dask ADDRESS`: every boundary by blocks on Dask, the same file as
/// the single pass (DaskJob.h); the summary gives the driver's figures.
static int meshAllOnDask(const MeshOptions& o, bool binary) {
  const bool perBoundary = perBoundaryOutput(o);
  StagedOutputs staged = perBoundary ? StagedOutputs::inDirectory(o.output) : StagedOutputs();
  ImageGeometry g;
  nlohmann::json job = storeJob(o.input, o.dask, o.block, o.workDir, g);
  job["kind"] = "threshold";
  job["iso"] = *o.surface.iso;
  job["mapping"] = o.surface.mapping == MappingMode::Midpoint ? "midpoint" : "linear";
  job["adjacency"] = toString(o.surface.pair);
  const std::string output = std::filesystem::absolute(o.output).string();
  job["output"] = perBoundary ? nlohmann::json(nullptr) : nlohmann::json(output);
  // -o DIR/: the merge task writes each boundary's file into the staging directory, named as
  // the single pass names them (boundaryFile); the table is written here.
  job["output_dir"] = perBoundary ? nlohmann::json(staged.stagingDirectory()) : nlohmann::json(nullptr);
  job["binary"] = binary;
  job["quiet"] = o.out.quiet;
  const StageClock clock;
  const std::string scratch = perBoundary ? staged.stagingDirectory() : output;
  const nlohmann::json r = runDaskJob(job, scratch, perBoundary ? scratch : "");
  if (perBoundary) {
    std::vector<ComponentFigures> boundaries;
    for (const nlohmann::json& c : r.at("components")) {
      ComponentFigures f;
      f.surfels = c.at("surfels").get<std::size_t>();
      f.triangles = c.at("triangles").get<std::size_t>();
      f.edges = c.at("edges").get<std::size_t>();
      f.euler = c.at("euler").get<long long>();
      f.area = c.at("area").get<double>();
      f.volume = c.at("volume").get<double>();
      boundaries.push_back(f);
      staged.temporaryFor(boundaryFile(o.output, boundaries.size()));  // (written there by the merge task)
    }
    writeTextFile(staged.temporaryFor((std::filesystem::path(o.output) / "boundaries.csv").string()),
                  boundaryTableCsv(boundaries, o.output));
    staged.commit();
  }
  nlohmann::ordered_json j;
  j["input"] = o.input.path;
  j["output"] = o.output;
  j["dask"] = o.dask;
  j["vertices"] = r["vertices"];
  j["triangles"] = r["triangles"];
  j["boundaries"] = r["boundaries"];
  j["euler_characteristic"] = r["euler"];
  j["seconds"] = number(clock.total());
  if (o.out.json) {
    std::cout << jsonText(j) << std::endl;
  } else if (!o.out.quiet) {
    std::cout << "surftrack: " << o.input.path << " -> " << o.output << " (by blocks on Dask, " << o.dask << ")\n"
              << "  mesh        " << r["boundaries"] << " boundaries, " << r["vertices"] << " vertices, "
              << r["triangles"] << " triangles, Euler characteristic " << r["euler"] << "\n"
              << "  time        " << num(clock.total(), 3) << " s\n";
  }
  return 0;
}

int runMesh(const std::vector<std::string>& args) {
  const MeshOptions o = parseMeshOptions(args);
  Extraction x;
  x.output = o.output;
  const bool precomputed = !o.format.empty();  // a Neuroglancer directory
  const bool perBoundary = perBoundaryOutput(o);
  x.format = precomputed ? o.format : perBoundary ? "ply" : meshFormat(o.output);  // a usage error, before any work
  x.binary = !o.ascii && (x.format == "ply" || x.format == "stl");
  if (precomputed) {
    requireOutputDirectory(o.output);
  } else if (perBoundary) {
    requireNotInput(o.output, o.input.path);  // (the directory is checked as it is staged)
  } else {
    requireWritable(o.output);  // fail now rather than after the work
    requireNotInput(o.output, o.input.path);
  }
  if (!o.dask.empty()) return meshAllOnDask(o, x.binary);
  StagedOutputs staged = perBoundary ? StagedOutputs::inDirectory(o.output) : StagedOutputs();
  SpacingUnit unit{o.unit, "", ""};

  Progress progress(Progress::wanted(o.out.quiet));
  StageClock clock;
  const int stages = extractionStages(o.surface) + 2;  // + read, write
  progress.stage(0, stages, "reading " + o.input.path);
  // A seeded extraction reads bricks near one surface; Otsu's default and the scans read all.
  const bool seeded = o.surface.seedMode != SeedMode::Largest && o.surface.seedMode != SeedMode::All;
  const bool sparse = seeded && (o.surface.iso || o.surface.label);
  if (sparse && isChunkedInput(o.input)) {
    extractLazily(o, x, clock, progress, stages, unit);
  } else {
    const io::LoadedVolume volume = readInput(o.input);
    clock.lap(x.timings, "read");
    describeInput(volume, o.input.path, x);
    unit.fileUnit = volume.unit;
    unit.fileFormat = volume.format;
    if (sparse) volume.advise(io::LoadedVolume::Access::Sparse);
    extractSurface(volume.view, o.surface, x, clock, progress, 1, stages);
    if (volume.mapped) x.voxelBytesResident = volume.residentBytes();
  }

  progress.stage(stages - 1, stages, "writing " + o.output);
  if (precomputed) {
    writePrecomputedOutput({{o.id, &x.surface, ""}}, o.output, o.format, x.surface.geometry, unit, o.precomputed);
    x.bytes = directoryBytes(o.output);
  } else if (perBoundary) {
    writeBoundaryFiles(x.surface, o.output, x.binary, staged);
    staged.commit();
    x.bytes = directoryBytes(o.output);
  } else {
    x.bytes = writeMeshFile(x.surface, o.output, x.binary);
  }
  clock.lap(x.timings, "write");
  x.totalSeconds = clock.total();
  progress.finish();
  if (!o.out.quiet)
    for (const std::string& w : x.warnings) std::cerr << "surftrack: warning: " << w << "\n";

  if (o.out.json) {
    std::cout << jsonText(extractionJson(x)) << std::endl;
  } else if (!o.out.quiet) {
    printSummary(std::cout, x);
  }
  return 0;
}

}  // namespace surftrack::cli
