// `surftrack mesh INPUT -o OUTPUT [options]`.
#include <filesystem>
#include <iostream>

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

}  // namespace

/// `mesh STORE --all --iso S --dask ADDRESS`: every boundary by blocks on Dask, the same file as
/// the single pass (DaskJob.h); the summary gives the driver's figures.
static int meshAllOnDask(const MeshOptions& o, bool binary) {
  ImageGeometry g;
  nlohmann::json job = storeJob(o.input, o.dask, o.block, o.workDir, g);
  job["kind"] = "threshold";
  job["iso"] = *o.surface.iso;
  job["mapping"] = o.surface.mapping == MappingMode::Midpoint ? "midpoint" : "linear";
  job["adjacency"] = toString(o.surface.pair);
  const std::string output = std::filesystem::absolute(o.output).string();
  job["output"] = output;
  job["binary"] = binary;
  job["quiet"] = o.out.quiet;
  const StageClock clock;
  const nlohmann::json r = runDaskJob(job, output, "");
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
  x.format = precomputed ? o.format : meshFormat(o.output);  // a usage error, before any work
  x.binary = !o.ascii && (x.format == "ply" || x.format == "stl");
  if (precomputed) {
    requireOutputDirectory(o.output);
  } else {
    requireWritable(o.output);  // fail now rather than after the work
    requireNotInput(o.output, o.input.path);
  }
  if (!o.dask.empty()) return meshAllOnDask(o, x.binary);
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
