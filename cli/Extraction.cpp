#include "Extraction.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "BoundaryMapping.h"
#include "FindSeed.h"
#include "LoopExtraction.h"
#include "ScanIsoSurface.h"
#include "TrackComponent.h"
#include "VolumeStats.h"

namespace surftrack::cli {

namespace {

std::string formatNumber(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string domainText(const Dims& d) {
  std::ostringstream s;
  s << "[0," << d.nx << ")x[0," << d.ny << ")x[0," << d.nz << ")";
  return s.str();
}

/// The label as a value of T; throws if T cannot hold it exactly.
template <class T>
T labelValue(double label, const std::string& input) {
  if constexpr (std::is_integral_v<T>) {
    if (label != std::floor(label) || label < double(std::numeric_limits<T>::min()) ||
        label > double(std::numeric_limits<T>::max()))
      throw std::runtime_error("label " + formatNumber(label) + " is not a value of the integer image '" +
                               input + "'");
    return T(label);
  } else {
    return T(label);
  }
}

/// The seed rule for a voxel: a 1-voxel walks to the first 1->0 step, a 0-voxel to the first
/// 0->1 step, along +x, then -x, +y, -y, +z, -z (seedAlongRay).
template <class Binary>
void resolveVoxelSeed(const Binary& binary, Voxel v, Extraction& x) {
  const Dims& dims = binary.dims();
  if (!dims.contains(v)) {
    std::ostringstream msg;
    msg << "seed voxel " << v << " lies outside the image domain " << domainText(dims);
    if (x.seedPoint)
      msg << " (the seed point (" << formatNumber((*x.seedPoint)[0]) << ","
          << formatNumber((*x.seedPoint)[1]) << "," << formatNumber((*x.seedPoint)[2])
          << ") is outside the image)";
    throw std::runtime_error(msg.str());
  }
  x.seedVoxel = v;
  x.seedVoxelInside = binary(v);
  for (Direction d = 0; d < 6; ++d) {
    if (auto s = seedAlongRay(binary, v, d)) {
      x.walkDirection = d;
      const Voxel delta = s->inside() - v;
      x.walkSteps = std::abs(delta.x) + std::abs(delta.y) + std::abs(delta.z);
      x.seedSurfel = *s;
      return;
    }
  }
  std::ostringstream msg;
  msg << "seed voxel " << v << " is not on any boundary: it is a 0-voxel and no 1-voxel lies on "
      << "the six axis rays from it";
  throw std::runtime_error(msg.str());
}

template <class T, class Binary>
void run(const DenseImage<T>& gray, const Binary& binary, const SurfaceOptions& o, Extraction& x,
         StageClock& clock, Progress& progress, int stage, int stageCount) {
  const ImageGeometry& geometry = gray.geometry();
  TriangleMesh triangles;
  if (o.seedMode == SeedMode::All) {
    progress.stage(stage++, stageCount, "scanning every boundary");
    triangles = scanIsoSurface(binary, o.pair);
    std::size_t count = 0;
    meshComponents(triangles, count);
    x.boundaries = count;
    clock.lap(x.timings, "scan");
    if (triangles.surfels.empty())
      throw std::runtime_error("empty selection: the image has no boundary surfel");
    progress.stage(stage++, stageCount, "building the mesh");
  } else {
    progress.stage(stage++, stageCount, "finding the seed");
    switch (o.seedMode) {
      case SeedMode::Largest: {
        const TriangleMesh all = scanIsoSurface(binary, o.pair);
        std::size_t count = 0;
        const std::vector<std::uint32_t> component = meshComponents(all, count);
        if (count == 0) throw std::runtime_error("empty selection: the image has no boundary surfel");
        std::vector<std::size_t> size(count, 0);
        for (std::uint32_t c : component) ++size[c];
        std::size_t best = 0;
        for (std::size_t c = 1; c < count; ++c)
          if (size[c] > size[best]) best = c;
        for (std::size_t v = 0; v < component.size(); ++v)
          if (component[v] == best) {
            x.seedSurfel = all.surfels[v];
            break;
          }
        x.boundaries = count;
        x.surfels = size[best];  // checked against the tracked count below
        break;
      }
      case SeedMode::Voxel:
        resolveVoxelSeed(binary, o.seedVoxel, x);
        break;
      case SeedMode::Point: {
        x.seedPoint = o.seedPoint;
        const auto index = io::toIndex(geometry, o.seedPoint);
        Voxel v;
        for (int a = 0; a < 3; ++a) {
          const double r = std::round(index[a]);
          v[a] = int(std::clamp(r, -1e9, 1e9));
        }
        resolveVoxelSeed(binary, v, x);
        break;
      }
      case SeedMode::Surfel: {
        const Surfel s{o.seedVoxel, o.seedDirection};
        if (!binary.dims().contains(s.inside())) {
          std::ostringstream msg;
          msg << "seed " << s << " lies outside the image domain " << domainText(binary.dims());
          throw std::runtime_error(msg.str());
        }
        try {
          requireTrackableSeed(binary, s);  // "surfel[...] is not a boundary surfel: ..."
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(std::string("seed ") + e.what());
        }
        x.seedSurfel = s;
        break;
      }
      case SeedMode::All:
        break;
    }
    clock.lap(x.timings, "seed");

    progress.stage(stage++, stageCount, "tracking");
    const SurfaceGraph graph = trackComponent(binary, *x.seedSurfel, o.pair, [&](std::size_t n) {
      progress.count(n, "surfels");
    });
    if (o.seedMode == SeedMode::Largest && graph.surfelCount() != x.surfels) {
      std::ostringstream msg;
      msg << "internal error: tracking from " << *x.seedSurfel << " found " << graph.surfelCount()
          << " surfels, the scan " << x.surfels;
      throw std::logic_error(msg.str());
    }
    clock.lap(x.timings, "track");
    progress.stage(stage++, stageCount, "converting to triangles");
    triangles = extractLoops(graph);  // from the bricks the tracker read: the same image
  }
  x.surfels = triangles.surfels.size();

  // Vertices: the boundary mapping, then the image geometry; then the OpenMesh mesh.
  std::vector<std::array<double, 3>> positions;
  if (x.mapping == "linear")
    positions = mapVertices(triangles, IsoValueMapping<T>(gray, x.value), geometry);
  else
    positions = mapVertices(triangles, MidpointMapping{}, geometry);
  clock.lap(x.timings, o.seedMode == SeedMode::All ? "place" : "convert");
  x.mesh = toSurfaceMesh(triangles, positions);
  triangles = {};
  x.stats = computeMeshStats(x.mesh);
  clock.lap(x.timings, "mesh");
}

template <class T>
void extractTyped(const DenseImage<T>& gray, const SurfaceOptions& o, Extraction& x, StageClock& clock,
                  Progress& progress, int stage, int stageCount) {
  if (x.byLabel) {
    const LabelImage<T> binary(gray, labelValue<T>(x.value, x.input));
    run(gray, binary, o, x, clock, progress, stage, stageCount);
  } else {
    const ThresholdImage<T> binary(gray, x.value);
    run(gray, binary, o, x, clock, progress, stage, stageCount);
  }
}

}  // namespace

void describeInput(const io::AnyVolume& volume, const std::string& path, Extraction& x) {
  x.input = path;
  x.dims = io::dimsOf(volume);
  x.type = io::scalarTypeOf(volume);
  x.geometry = io::geometryOf(volume);
}

io::AnyVolume readInput(const InputOptions& input) {
  io::AnyVolume volume = input.raw ? io::readRawVolume(input.path, input.rawLayout)
                                   : io::readVolume(input.path);
  ImageGeometry& g = io::geometryOf(volume);
  if (input.spacing) g.spacing = *input.spacing;
  if (input.origin) g.origin = *input.origin;
  return volume;
}

void extractSurface(const io::AnyVolume& volume, const SurfaceOptions& o, Extraction& x,
                    StageClock& clock, Progress& progress, int stage, int stageCount) {
  progress.stage(stage, stageCount, "checking values");
  const VolumeStats stats = computeStats(volume);
  x.dataMin = stats.min;
  x.dataMax = stats.max;
  x.pair = o.pair;
  x.seedMode = o.seedMode;
  if (stats.voxels == 0)
    throw std::runtime_error("'" + x.input + "' holds no finite value: nothing to extract");
  if (o.label) {
    x.byLabel = true;
    x.value = *o.label;
    x.insideVoxels = countEqual(volume, x.value);
    if (x.insideVoxels == 0) {
      std::ostringstream msg;
      msg << "empty selection: label " << formatNumber(x.value) << " does not occur in '" << x.input
          << "'";
      if (!stats.labels.empty()) {
        msg << " (labels present: ";
        std::size_t shown = 0;
        for (auto [value, count] : stats.labels) {
          if (shown == 12) {
            msg << ", ...";
            break;
          }
          msg << (shown++ ? ", " : "") << value;
        }
        msg << ")";
      } else {
        msg << " (values in [" << formatNumber(stats.min) << ", " << formatNumber(stats.max) << "])";
      }
      throw std::runtime_error(msg.str());
    }
  } else {
    x.value = o.iso ? *o.iso : stats.otsu;
    x.valueFromOtsu = !o.iso;
    const std::string range = "[" + formatNumber(stats.min) + ", " + formatNumber(stats.max) + "]";
    if (stats.min == stats.max)
      throw std::runtime_error("'" + x.input + "' is constant (every voxel is " +
                               formatNumber(stats.min) + "): there is no surface to extract");
    if (x.value < stats.min)
      throw std::runtime_error("iso-value " + formatNumber(x.value) + " is outside the data range " +
                               range + " of '" + x.input + "': every voxel would be inside");
    if (x.value >= stats.max)
      throw std::runtime_error("iso-value " + formatNumber(x.value) + " is outside the data range " +
                               range + " of '" + x.input + "': no voxel is above it");
    x.insideVoxels = countAbove(volume, x.value);
  }
  x.mapping = o.mapping == MappingMode::Midpoint ? "midpoint"
              : o.mapping == MappingMode::Linear ? "linear"
              : x.byLabel                        ? "midpoint"
                                                 : "linear";
  clock.lap(x.timings, "values");
  std::visit([&](const auto& gray) { extractTyped(gray, o, x, clock, progress, stage + 1, stageCount); },
             volume);
}

}  // namespace surftrack::cli
