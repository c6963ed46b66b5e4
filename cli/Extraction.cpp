#include "Extraction.h"

#include <cmath>
#include <unistd.h>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "ChunkedStore.h"
#include "Extract.h"
#include "VolumeStats.h"

namespace surftrack::cli {

namespace {

std::string formatNumber(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

SeedRule seedRuleOf(const SurfaceOptions& o) {
  switch (o.seedMode) {
    case SeedMode::All: return SeedRule::all();
    case SeedMode::Largest: return SeedRule::largest();
    case SeedMode::Voxel: return SeedRule::fromVoxel(o.seedVoxel);
    case SeedMode::Ray: return SeedRule::ray(o.seedVoxel);
    case SeedMode::Point: return SeedRule::point(o.seedPoint);
    case SeedMode::Surfel: break;
  }
  return SeedRule::fromSurfel(Surfel{o.seedVoxel, o.seedDirection});
}

std::string stageText(const std::string& stage) {
  if (stage == "seed") return "finding the seed";
  if (stage == "track") return "tracking";
  if (stage == "convert") return "converting to triangles";
  if (stage == "scan") return "scanning every boundary";
  if (stage == "place") return "placing the vertices";
  return "measuring the components";
}

}  // namespace

void describeInput(const io::LoadedVolume& volume, const std::string& path, Extraction& x) {
  x.input = path;
  x.dims = volume.view.dims;
  x.type = volume.view.type;
  x.geometry = volume.view.geometry;
  x.storage = volume.format.empty() ? std::string("in memory")
                                    : (volume.mapped ? "memory-mapped " : "loaded ") + volume.format;
  x.mapped = volume.mapped;
  x.decodeReason = volume.decodeReason;
  x.frame = volume.frame;
  x.warnings.insert(x.warnings.end(), volume.warnings.begin(), volume.warnings.end());
  x.voxelBytes = volume.view.dims.count() * sizeOf(volume.view.type);
}

io::ChunkedStoreOptions chunkedStoreOptions(const InputOptions& input) {
  io::ChunkedStoreOptions chosen;
  chosen.level = input.level.value_or(0);
  chosen.channel = input.channel;
  chosen.time = input.time;
  return chosen;
}

std::optional<std::string> wholeReadRefusal(const io::ChunkedStore& store, const std::string& path) {
  const ChunkLayout& layout = store.provider->layout();
  const double bytes = double(layout.dims.count()) * double(sizeOf(layout.type));
  const double memory = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
  auto gib = [](double b) {
    std::ostringstream s;
    s.precision(3);
    s << b / double(1 << 30);
    return s.str();
  };
  if (memory > 0 && bytes > memory / 2)
    return "cannot read '" + path + "' whole: its voxels take " + gib(bytes) +
           " GiB, more than half of this machine's " + gib(memory) +
           " GiB; `mesh` with a seed rule and --iso or --label reads only the chunks its surface "
           "crosses, and surftrack.distributed meshes every label by blocks";
  return std::nullopt;
}

bool isChunkedInput(const InputOptions& input) {
  const bool store = !input.raw && io::isChunkedStore(input.path);
  if (!store && (input.level || input.time))
    throw io::ReadError("cannot read '" + input.path + "': --level and --time choose in a chunked store (zarr, OME-Zarr, N5), which it is not");
  return store;
}

std::string applyGeometryOptions(const InputOptions& input, ImageGeometry& g, const std::string& frame) {
  std::string out = frame;
  if (input.ras) {
    // RAS = diag(-1, -1, 1) LPS: the origin and the direction's x and y rows negated. The
    // handedness flips with them; the engine keeps the normals outwards (Extract.h, Surface).
    for (int r = 0; r < 2; ++r) {
      g.origin[r] = -g.origin[r];
      for (double& d : g.direction[r]) d = -d;
    }
    out = "RAS";
  }
  if (input.spacing) g.spacing = *input.spacing;
  if (input.origin) g.origin = *input.origin;  // in the chosen frame
  return out;
}

namespace {

/// The store's voxels decoded whole, or the error that refuses it.
void requireLoadable(const io::ChunkedStore& store, const std::string& path) {
  if (const auto refusal = wholeReadRefusal(store, path)) throw io::ReadError(*refusal);
}

}  // namespace

io::LoadedVolume readInput(const InputOptions& input) {
  io::ReadOptions options;
  options.channel = input.channel;
  io::LoadedVolume volume;
  if (isChunkedInput(input)) {
    // Every chunk decoded into one buffer (docs/cli.md, "Input formats"); a seeded `mesh` reads
    // a store lazily instead (MeshCommand.cpp).
    const io::ChunkedStore store = io::openChunkedStore(input.path, chunkedStoreOptions(input));
    requireLoadable(store, input.path);
    volume = io::loadChunkedStore(store);
  } else {
    volume = input.raw ? io::loadRawVolume(input.path, input.rawLayout) : io::loadVolume(input.path, options);
  }
  if (input.raw && input.channel && *input.channel != 0)
    throw io::ReadError("cannot read '" + input.path + "': there is no channel " + std::to_string(*input.channel) +
                        " (--channel): a raw file has one channel, 0");
  volume.frame = applyGeometryOptions(input, volume.view.geometry, volume.frame);
  return volume;
}

io::LoadedVolume inMemory(const io::AnyVolume& volume) {
  io::LoadedVolume loaded;
  loaded.view = std::visit(
      [](const auto& image) { return VolumeView::of(image.data().data(), image.dims(), image.geometry()); },
      volume);
  return loaded;
}

int extractionStages(const SurfaceOptions& o) {
  return (o.seedMode == SeedMode::All ? 5 : 7) + (o.refine.smoothIterations > 0) + o.refine.decimate();
}

namespace {

/// The values of `volume`, for Otsu's default or for an error message.
VolumeStats valueStats(const VolumeView& volume, const Extraction& x) {
  VolumeStats stats = computeStats(volume);
  if (stats.voxels == 0)
    throw std::runtime_error("'" + x.input + "' holds no finite value: nothing to extract");
  return stats;
}

/// After the front door found no surface: the message, made precise by the data's values (an
/// O(volume) pass, paid only on this error path and by Otsu's default).
[[noreturn]] void explainNoSurface(const VolumeView& volume, const Extraction& x,
                                   const std::string& message) {
  const VolumeStats stats = valueStats(volume, x);
  const std::string range = "[" + formatNumber(stats.min) + ", " + formatNumber(stats.max) + "]";
  if (x.byLabel) {
    if (countEqual(volume, x.label) == 0) {
      std::ostringstream msg;
      msg << "empty selection: label " << x.label.text() << " does not occur in '" << x.input << "'";
      if (!stats.labels.empty()) {
        msg << " (labels present: ";
        std::size_t shown = 0;
        for (auto [value, count] : stats.labels) {
          if (shown == 12) {
            msg << ", ...";
            break;
          }
          msg << (shown++ ? ", " : "") << value.text();
        }
        msg << ")";
      } else {
        msg << " (values in " << range << ")";
      }
      throw std::runtime_error(msg.str());
    }
  } else {
    if (stats.min == stats.max)
      throw std::runtime_error("'" + x.input + "' is constant (every voxel is " + formatNumber(stats.min) +
                               "): there is no surface to extract");
    if (x.value < stats.min)
      throw std::runtime_error("iso-value " + formatNumber(x.value) + " is outside the data range " + range +
                               " of '" + x.input + "': every voxel would be inside");
    if (x.value >= stats.max)
      throw std::runtime_error("iso-value " + formatNumber(x.value) + " is outside the data range " + range +
                               " of '" + x.input + "': no voxel is above it");
  }
  throw std::runtime_error(message);
}

}  // namespace

void extractSurface(const VolumeView& volume, const SurfaceOptions& o, Extraction& x,
                    StageClock& clock, Progress& progress, int stage, int stageCount) {
  const std::unique_ptr<VoxelSource> source = makeViewSource(volume);
  extractSurface(*source, &volume, o, x, clock, progress, stage, stageCount);
}

void extractSurface(const VoxelSource& source, const VolumeView* whole, const SurfaceOptions& o, Extraction& x,
                    StageClock& clock, Progress& progress, int stage, int stageCount) {
  // What needs every voxel (the data range of the scans, Otsu's default, the explanation of an
  // empty selection) needs `whole`; a lazy source is only ever seeded, with --iso or --label.
  auto everyVoxel = [&]() -> const VolumeView& {
    if (!whole) throw std::logic_error("extractSurface: every voxel asked of a lazy source");
    return *whole;
  };
  progress.stage(stage, stageCount, "choosing the voxels");
  x.pair = o.pair;
  x.seedMode = o.seedMode;
  x.byLabel = o.label.has_value();
  if (o.label) {
    x.label = *o.label;
  } else if (o.iso) {
    x.value = *o.iso;
    // The scanning rules read every voxel anyway: one more pass checks the iso-value against
    // the data range (a seeded extraction leaves that to its seed rule's own error).
    if (o.seedMode == SeedMode::Largest || o.seedMode == SeedMode::All) {
      const auto range = valueRange(everyVoxel());
      if (!range) throw std::runtime_error("'" + x.input + "' holds no finite value: nothing to extract");
      x.dataRange = range;
      const std::string text = "[" + formatNumber((*range)[0]) + ", " + formatNumber((*range)[1]) + "]";
      if (x.value < (*range)[0])
        throw std::runtime_error("iso-value " + formatNumber(x.value) + " is outside the data range " + text +
                                 " of '" + x.input + "': every voxel would be inside");
      if (x.value >= (*range)[1])
        throw std::runtime_error("iso-value " + formatNumber(x.value) + " is outside the data range " + text +
                                 " of '" + x.input + "': no voxel is above it");
    }
  } else {
    // Otsu's threshold is the one default that needs every value.
    const VolumeStats stats = valueStats(everyVoxel(), x);
    if (stats.min == stats.max)
      throw std::runtime_error("'" + x.input + "' is constant (every voxel is " + formatNumber(stats.min) +
                               "): there is no surface to extract");
    x.dataRange = {stats.min, stats.max};
    x.value = stats.otsu;
    x.valueFromOtsu = true;
  }
  clock.lap(x.timings, "values");

  ExtractOptions eo;
  eo.selection = x.byLabel ? Selection::label(x.label) : Selection::threshold(x.value);
  eo.seed = seedRuleOf(o);
  eo.maxSeedDistance = o.maxSeedDistance;
  eo.pair = o.pair;
  eo.threads = o.threads;
  eo.mapping = o.mapping == MappingMode::Midpoint ? Mapping::Midpoint
               : o.mapping == MappingMode::Linear ? Mapping::Linear
                                                  : Mapping::Default;
  eo.progress = [&](const ProgressEvent& e) {
    if (e.surfels) progress.count(e.surfels, "surfels");
    else progress.stage(stage + 1 + e.index, stageCount, stageText(e.stage));
  };
  if (o.seedMode == SeedMode::Point) x.seedPoint = o.seedPoint;
  Surface surface;
  try {
    surface = whole ? extract(*whole, eo) : extract(source, eo);
  } catch (const SeedTooFar& e) {
    throw std::runtime_error(e.what());  // no pass over the volume: the search read only near the seed
  } catch (const InvalidInput& e) {
    if (!whole) throw std::runtime_error(e.what());  // (a lazy source is not read whole to say more)
    explainNoSurface(*whole, x, e.what());
  }
  x.warnings.insert(x.warnings.end(), surface.warnings.begin(), surface.warnings.end());
  x.seedDistance = surface.seed.distance;
  for (const StageTime& t : surface.timings) x.timings.push_back({t.stage, t.seconds});
  clock.skip();  // the core timed its own stages
  x.mapping = toString(surface.mapping);
  x.seedSurfel = surface.seed.surfel;
  x.seedVoxel = surface.seed.voxel;
  x.seedVoxelInside = surface.seed.voxelInside;
  x.walkDirection = surface.seed.walkDirection;
  x.walkSteps = surface.seed.walkSteps;
  x.boundaries = surface.boundariesInImage;
  x.surfels = surface.surfels.size();
  x.voxelBytesRead = x.mapped ? std::min<std::uintmax_t>(surface.voxelsRead * sizeOf(source.type()), x.voxelBytes)
                             : x.voxelBytes;
  for (const ComponentFigures& c : surface.components) x.extractedVolume += c.volume;
  const int next = stage + extractionStages(o) - 1 - (o.refine.smoothIterations > 0) - o.refine.decimate();
  surftrack::RefineOptions ro;
  if (o.refine.smoothIterations > 0) {
    SmoothOptions so;
    so.iterations = o.refine.smoothIterations;
    so.threads = o.threads;
    ro.smooth = so;
  }
  if (o.refine.decimate()) {
    DecimateOptions d;
    d.maxError = o.refine.maxError;
    d.reduction = o.refine.reduction;
    ro.decimate = d;
  }
  const char* running = nullptr;  // the step whose time the clock is measuring
  ro.progress = [&](const ProgressEvent& e) {
    if (running) clock.lap(x.timings, running);
    running = e.stage == "smooth" ? "smooth" : "decimate";
    progress.stage(next + e.index, stageCount, e.stage == "smooth" ? "smoothing" : "decimating");
  };
  const RefineReport refined = refineSurface(surface, ro);
  if (running) clock.lap(x.timings, running);
  x.smooth = refined.smooth;
  x.decimate = refined.decimate;

  // The files need no half-edge operation: the triangles are checked to be a closed oriented
  // 2-manifold (what building the OpenMesh mesh would check) and written from the list.
  progress.stage(stage + extractionStages(o) - 1, stageCount, "checking the mesh");
  try {
    requireClosedOrientedManifold(surface.vertices.size(), surface.triangles);
  } catch (const std::logic_error& e) {
    throw InternalError(e.what());
  }
  x.stats = meshStats(surface);
  x.surface = std::move(surface);
  clock.lap(x.timings, "check");
}

}  // namespace surftrack::cli
