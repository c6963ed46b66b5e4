// The front door's pipeline (docs/api.md): seed rule -> trackComponent -> extractLoops ->
// boundary mapping -> physical coordinates -> per-component figures; or the scanning method
// for `largest` and `all`.
#include "Extract.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "BoundaryMapping.h"
#include "FindSeed.h"
#include "HugePages.h"
#include "LoopExtraction.h"
#include "ScanIsoSurface.h"
#include "PhysicalRange.h"
#include "PlaceSurface.h"
#include "SelectionValue.h"
#include "SourceImage.h"
#include "TrackComponent.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace surftrack {

std::string toString(Mapping mapping) {
  switch (mapping) {
    case Mapping::Midpoint: return "midpoint";
    case Mapping::Linear: return "linear";
    case Mapping::Default: break;
  }
  return "default";
}

Mapping parseMapping(const std::string& text) {
  for (Mapping m : {Mapping::Default, Mapping::Midpoint, Mapping::Linear})
    if (text == toString(m)) return m;
  throw InvalidInput("unknown mapping '" + text + "': expected midpoint, linear or default");
}

namespace {

/// A boundary of at most this many surfels is a speck (a lone voxel has 6, a 2x2x2 cube 24).
constexpr std::size_t kSpeckSurfels = 48;

std::string domainText(const Dims& d) {
  std::ostringstream s;
  s << "[0," << d.nx << ")x[0," << d.ny << ")x[0," << d.nz << ")";
  return s.str();
}

/// Stage events, timings and the cancellation check, one stage after the other.
class Stages {
 public:
  Stages(const ExtractOptions& options, int count, Surface& out)
      : options_(options), count_(count), out_(out), last_(std::chrono::steady_clock::now()) {}

  void begin(const std::string& name) {
    end();
    checkCancel();
    current_ = name;
    if (options_.progress) options_.progress(ProgressEvent{name, index_, count_, 0});
    ++index_;
  }
  void end() {
    const auto now = std::chrono::steady_clock::now();
    if (!current_.empty())
      out_.timings.push_back({current_, std::chrono::duration<double>(now - last_).count()});
    current_.clear();
    last_ = now;
  }
  void surfelsFound(std::size_t n) {
    checkCancel();
    if (options_.progress) options_.progress(ProgressEvent{current_, index_ - 1, count_, n});
  }
  void checkCancel() const {
    if (options_.cancel && options_.cancel->load(std::memory_order_relaxed))
      throw Cancelled("extraction cancelled");
  }

 private:
  const ExtractOptions& options_;
  int count_, index_ = 0;
  Surface& out_;
  std::string current_;
  std::chrono::steady_clock::time_point last_;
};

[[noreturn]] void throwEmpty(const VoxelSource&, const Selection& selection) {
  throw InvalidInput("empty selection: no voxel has " + selection.text() +
                     " with a 0-voxel next to it: the image has no boundary surfel");
}

/// The nearest-surfel rule (FindSeed.h) for a point in index coordinates, up to maxVoxels
/// voxels of the smallest spacing (ExtractOptions::maxSeedDistance); `what` names the seed in
/// messages.
Surfel resolveNearestSeed(const SourceImage& binary, const std::array<double, 3>& index,
                          const ImageGeometry& geometry, double maxVoxels, const std::string& what,
                          SeedReport& seed) {
  const auto& sp = geometry.spacing;
  const double minSpacing = std::min({std::abs(sp[0]), std::abs(sp[1]), std::abs(sp[2])});
  const double maxSpacing = std::max({std::abs(sp[0]), std::abs(sp[1]), std::abs(sp[2])});
  const std::optional<NearestSurfel> nearest =
      nearestBoundarySurfel(binary, index, geometry, maxVoxels * minSpacing);
  if (nearest) {
    seed.distance = nearest->distance;
    return nearest->surfel;
  }
  // Did the bound cover every midpoint of the domain ([-0.5, n - 0.5] on each axis)?
  const Dims& dims = binary.dims();
  double farthest = 0;  // index-space distance to the farthest corner of that box
  for (int a = 0; a < 3; ++a) {
    const double gap = std::max(std::abs(index[a] + 0.5), std::abs(dims[a] - 0.5 - index[a]));
    farthest += gap * gap;
  }
  if (maxVoxels * minSpacing >= std::sqrt(farthest) * maxSpacing)
    throw InvalidInput(what + " has no boundary surfel near it: the selection is empty");
  throw SeedTooFar(what + " has no boundary surfel within " + numberText(maxVoxels, 10) +
                   " voxels, the maximum seed distance (ExtractOptions::maxSeedDistance; " +
                   "--max-seed-distance on the command line, max_seed_distance in Python): the object " +
                   "lies farther or the selection is empty; raise the distance, or give a seed nearer the object");
}

/// The ray rule for a voxel: a 1-voxel walks to the first 1->0 step, a 0-voxel to the first
/// 0->1 step, along +x, then -x, +y, -y, +z, -z (seedAlongRay).
Surfel resolveVoxelSeed(const SourceImage& binary, Voxel v, SeedReport& seed) {
  const Dims& dims = binary.dims();
  if (!dims.contains(v)) {
    std::ostringstream msg;
    msg << "seed voxel " << v << " lies outside the image domain " << domainText(dims);
    throw InvalidInput(msg.str());
  }
  seed.voxel = v;
  seed.voxelInside = binary(v);
  for (Direction d = 0; d < 6; ++d)
    if (auto s = seedAlongRay(binary, v, d)) {
      seed.walkDirection = d;
      const Voxel delta = s->inside() - v;
      seed.walkSteps = std::abs(delta.x) + std::abs(delta.y) + std::abs(delta.z);
      return *s;
    }
  std::ostringstream msg;
  msg << "seed voxel " << v << " is not on any boundary: it is a 0-voxel and no 1-voxel lies on "
      << "the six axis rays from it";
  throw InvalidInput(msg.str());
}

Surfel resolveSurfelSeed(const SourceImage& binary, const Surfel& s) {
  if (!binary.dims().contains(s.inside())) {
    std::ostringstream msg;
    msg << "seed " << s << " lies outside the image domain " << domainText(binary.dims());
    throw InvalidInput(msg.str());
  }
  try {
    requireTrackableSeed(binary, s);  // "surfel[...] is not a boundary surfel: ..."
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(std::string("seed ") + e.what());
  }
  return s;
}

}  // namespace

/// Vertex positions of surfels [begin, end) in index space by the boundary mapping (paper
/// §3.1); the linear one reads the gray values of both voxels of each surfel, in one batch, from
/// the source.
static void placeVertices(const VoxelSource& source, const std::vector<Surfel>& surfels, Mapping mapping,
                          const Selection& selection, double epsilon, std::size_t begin, std::size_t end,
                          std::array<double, 3>* points) {
  if (mapping == Mapping::Midpoint) {
    for (std::size_t v = begin; v < end; ++v) points[v] = MidpointMapping{}(surfels[v]);
    return;
  }
  const Dims dims = source.dims();
  std::vector<Voxel> voxels;
  voxels.reserve(2 * (end - begin));
  for (std::size_t v = begin; v < end; ++v) {
    const Surfel& s = surfels[v];
    if (dims.contains(s.inside()) && dims.contains(s.outside())) {
      voxels.push_back(s.inside());
      voxels.push_back(s.outside());
    }
  }
  std::vector<double> f(voxels.size());
  source.values(voxels.data(), voxels.size(), f.data());
  std::size_t next = 0;
  for (std::size_t v = begin; v < end; ++v) {
    const Surfel& s = surfels[v];
    double t = 0.5;  // a voxel outside the domain: no gray value to interpolate
    if (dims.contains(s.inside()) && dims.contains(s.outside())) {
      t = linearParameter(selection.value, f[next], f[next + 1], epsilon);
      next += 2;
    }
    points[v] = pointOnSurfel(s, t);
  }
}

void placeSurface(const VoxelSource& source, TriangleMesh&& mesh, Mapping mapping,
                  const Selection& selection, double epsilon, Surface& out, int threads) {
  const ImageGeometry geometry = source.geometry();
  const std::size_t n = mesh.surfels.size();
  resizeHugePages(out.vertices, n);  // written once (lib/HugePages.h)
  // Runs of up to 2^15 vertices, each placed on its own (the source may be read from several
  // threads at once); the same points for any number of threads.
  const std::size_t kRun = std::clamp<std::size_t>(n / 64, 1024, std::size_t(1) << 15);
  auto place = [&](std::size_t r) {
    const std::size_t begin = r * kRun, end = std::min(n, begin + kRun);
    placeVertices(source, mesh.surfels, mapping, selection, epsilon, begin, end, out.vertices.data());
    for (std::size_t v = begin; v < end; ++v) out.vertices[v] = geometry.toPhysical(out.vertices[v]);
  };
  const std::size_t runs = (n + kRun - 1) / kRun;
  if (threads == 1 || runs < 2 || (threads == 0 && n < (std::size_t(1) << 16))) {
    for (std::size_t r = 0; r < runs; ++r) place(r);
  } else {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] { tbb::parallel_for(std::size_t(0), runs, place); });
  }
  requirePlacedVertices(geometry, out.vertices, [&](std::size_t v) { return MidpointMapping{}(mesh.surfels[v]); });
  out.surfels = std::move(mesh.surfels);
  out.triangles = std::move(mesh.triangles);
  if (geometry.handedness() < 0)  // a mirrored frame: keep the normals pointing outwards
    for (auto& t : out.triangles) std::swap(t[1], t[2]);
}

void addFigures(Surface& out, bool connected) {
  if (connected && !out.triangles.empty())
    out.components = {connectedMeshFigures(out.vertices, out.triangles)};
  else
    out.components = componentFigures(out.vertices, out.triangles);
  out.euler = 0;
  for (const ComponentFigures& c : out.components) out.euler += c.euler;
}

Surface extract(const VoxelSource& source, const ExtractOptions& o) {
  using Kind = SeedRule::Kind;
  Surface out;
  out.pair = o.pair;
  out.selection = o.selection;
  requireSelectable(source.type(), o.selection);
  out.mapping = o.mapping != Mapping::Default ? o.mapping
                : o.selection.isLabel()       ? Mapping::Midpoint
                                              : Mapping::Linear;
  if (out.mapping == Mapping::Linear && o.selection.isLabel())
    throw InvalidInput("the linear mapping interpolates an iso-value: a label selection takes the "
                       "midpoint mapping");
  if (o.threads < 0) throw InvalidInput("threads " + std::to_string(o.threads) + " is negative (0: all cores)");
  if (!(o.epsilon > 0 && o.epsilon < 0.5))
    throw InvalidInput("epsilon " + numberText(o.epsilon, 10) + " is outside ]0, 0.5[");
  if (!(o.maxSeedDistance > 0))
    throw InvalidInput("maxSeedDistance " + numberText(o.maxSeedDistance, 10) + " is not a positive number of voxels");
  requirePhysicalDomain(source.geometry(), source.dims());  // before any voxel is read

  const bool scanning = o.seed.kind == Kind::All;
  Stages stages(o, scanning ? 3 : 5, out);  // (the last, "figures", is empty without figures)
  const SourceImage binary(source, o.selection);
  const ImageGeometry geometry = source.geometry();
  out.geometry = geometry;
  TriangleMesh mesh;
  if (scanning) {
    stages.begin("scan");
    mesh = scanIsoSurface(binary, o.pair, o.threads);
    if (mesh.surfels.empty()) throwEmpty(source, o.selection);
  } else {
    stages.begin("seed");
    Surfel seed;
    std::size_t expected = 0;
    switch (o.seed.kind) {
      case Kind::Largest: {
        // Every boundary's surfel count from a scan that builds no triangle; ties go to the
        // boundary met first, as in the components of the scanned mesh.
        const std::vector<BoundaryCount> boundaries = scanBoundaryCounts(binary, o.pair, o.threads);
        if (boundaries.empty()) throwEmpty(source, o.selection);
        const auto best = std::max_element(boundaries.begin(), boundaries.end(),
                                           [](const BoundaryCount& a, const BoundaryCount& b) { return a.surfels < b.surfels; });
        seed = best->seed;
        out.boundariesInImage = boundaries.size();
        expected = best->surfels;
        break;
      }
      case Kind::Ray: seed = resolveVoxelSeed(binary, o.seed.voxel, out.seed); break;
      case Kind::Voxel: {
        const Voxel v = o.seed.voxel;
        if (!binary.dims().contains(v)) {
          std::ostringstream msg;
          msg << "seed voxel " << v << " lies outside the image domain " << domainText(binary.dims());
          throw InvalidInput(msg.str());
        }
        out.seed.voxel = v;
        out.seed.voxelInside = binary(v);
        std::ostringstream what;
        what << "seed voxel " << v;
        seed = resolveNearestSeed(binary, {double(v.x), double(v.y), double(v.z)}, geometry, o.maxSeedDistance,
                                  what.str(), out.seed);
        break;
      }
      case Kind::Point: {
        std::array<double, 3> index;
        try {
          index = geometry.toIndex(o.seed.physical);
        } catch (const std::invalid_argument& e) {
          throw InvalidInput(e.what());
        }
        const std::string what = "seed point (" + numberText(o.seed.physical[0], 10) + "," +
                                 numberText(o.seed.physical[1], 10) + "," + numberText(o.seed.physical[2], 10) + ")";
        // A point off the image is most often a point in another frame (RAS for LPS, mm for
        // voxels): say so rather than take the nearest surfel of the image's border.
        for (int a = 0; a < 3; ++a)
          if (!(index[a] >= -0.5 && index[a] <= binary.dims()[a] - 0.5)) {
            std::ostringstream msg;
            msg << what << " lies outside the image: its voxel index (" << numberText(index[0], 10) << ","
                << numberText(index[1], 10) << "," << numberText(index[2], 10) << ") is outside the domain "
                << domainText(binary.dims());
            throw InvalidInput(msg.str());
          }
        seed = resolveNearestSeed(binary, index, geometry, o.maxSeedDistance, what, out.seed);
        break;
      }
      case Kind::Surfel: seed = resolveSurfelSeed(binary, o.seed.surfel); break;
      case Kind::All: break;
    }
    out.seed.surfel = seed;

    stages.begin("track");
    const SurfaceGraph graph =
        trackComponent(binary, seed, o.pair, [&](std::size_t n) { stages.surfelsFound(n); }, o.threads);
    if (expected && graph.surfelCount() != expected) {
      std::ostringstream msg;
      msg << "tracking from " << seed << " found " << graph.surfelCount() << " surfels, the scan "
          << expected;
      throw InternalError(msg.str());
    }
    stages.begin("convert");
    try {
      mesh = extractLoops(graph, o.threads);  // from the bricks the tracker read: the same image
    } catch (const std::logic_error& e) {
      throw InternalError(e.what());
    }
  }

  stages.begin("place");
  placeSurface(source, std::move(mesh), out.mapping, o.selection, o.epsilon, out, o.threads);
  // A scan (all, largest) reads the whole domain; the rest is what the seed rule, the tracker and
  // the linear mapping asked for.
  out.voxelsRead = binary.voxelsRead() + (out.mapping == Mapping::Linear ? 2 * out.surfels.size() : 0) +
                   (o.seed.kind == Kind::All || o.seed.kind == Kind::Largest ? binary.dims().count() : 0);

  stages.begin("figures");
  if (o.figures) addFigures(out, /*connected=*/!scanning);  // one tracked boundary, unless scanning
  if (scanning) out.boundariesInImage = out.components.size();
  stages.end();
  // A seeded surface of a handful of voxels in a large image is most likely noise reached by
  // the seed rule, not the object the caller meant.
  const Dims dims = source.dims();
  if (o.seed.kind != Kind::All && o.seed.kind != Kind::Largest && out.surfels.size() <= kSpeckSurfels &&
      dims.count() >= 1000 * out.surfels.size()) {
    std::ostringstream msg;
    msg << "the surface found is a speck: " << out.surfels.size() << " surfels in a " << dims.nx << "x"
        << dims.ny << "x" << dims.nz << " image; the seed may have reached noise (take the largest "
        << "boundary, or a seed nearer the object)";
    out.warnings.push_back(msg.str());
  }
  return out;
}

Surface extract(const VolumeView& view, const ExtractOptions& options) {
  return extract(*makeViewSource(view), options);
}

}  // namespace surftrack
