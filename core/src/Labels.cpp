// extractLabels (docs/api.md, "Label maps"). Every boundary: one scan of the cubes for all the
// labels (converter/ScanLabels.h), which writes each label's mesh, placed by the midpoint
// mapping (paper §3.1), straight into its Surface. Some boundaries: one scan for every label's
// seeds (tracker/LabelSeeds.h), then, labels in parallel, each label's boundaries tracked
// (tracker/TrackBoundaries.h), converted (converter/LoopExtraction.h) and placed like
// extract()'s.
#include "Labels.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "BoundaryMapping.h"
#include "FindSeed.h"
#include "HugePages.h"
#include "Image.h"
#include "LabelSeeds.h"
#include "LabelSelection.h"
#include "LoopExtraction.h"
#include "MeshComponents.h"
#include "PhysicalRange.h"
#include "PlaceSurface.h"
#include "ScanLabels.h"
#include "ScannedLabel.h"
#include "SelectionValue.h"
#include "SharedWallLabels.h"
#include "SourceImage.h"
#include "TrackBoundaries.h"

namespace surftrack {
namespace {

std::string voxelText(Voxel v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// f(i) for i in [0, n), on the arena's threads.
template <class F>
void forEachIndex(tbb::task_arena& arena, std::size_t n, F&& f) {
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i < r.end(); ++i) f(i);
    });
  });
}

/// The indices in `labels` (increasing: those that occur) of the labels `selection` asks for,
/// in increasing order.
template <class T>
std::vector<std::size_t> selectLabels(const std::vector<T>& labels, const LabelSelection& selection,
                                      const LabelValue& background) {
  std::vector<std::size_t> out;
  switch (selection.kind) {
    case LabelSelection::Kind::All:
      out.resize(labels.size());
      std::iota(out.begin(), out.end(), std::size_t(0));
      if (out.empty())
        throw InvalidInput("empty selection: every voxel has the background label " + background.text());
      break;
    case LabelSelection::Kind::List:
      requireListable<T>(selection, background);
      for (const LabelValue& L : selection.labels) {
        const auto at = std::lower_bound(labels.begin(), labels.end(), L.as<T>());
        if (at == labels.end() || *at != L.as<T>())
          throw InvalidInput("label " + L.text() + " does not occur in the image");
        out.push_back(std::size_t(at - labels.begin()));
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      break;
    case LabelSelection::Kind::Range:
      requireNonEmptyRange(selection);
      for (std::size_t i = 0; i < labels.size(); ++i)
        if (LabelValue(labels[i]) >= selection.first && LabelValue(labels[i]) <= selection.last) out.push_back(i);
      if (out.empty())
        throw InvalidInput("empty selection: no label in [" + selection.first.text() + ", " +
                           selection.last.text() + "] occurs in the image (background " + background.text() +
                           ")");
      break;
  }
  return out;
}

/// For each label index, the seeds (indices into its x-surfels) of the boundaries wanted.
template <class T>
std::vector<std::vector<std::size_t>> wantedSeeds(const VolumeRef<T>& image, const LabelSeeds<T>& seeds,
                                                  const std::vector<std::size_t>& selected,
                                                  const LabelOptions& o) {
  std::vector<std::vector<std::size_t>> wanted(seeds.labels.size());
  if (o.seeds.empty()) {
    for (std::size_t i : selected) {
      wanted[i].resize(seeds.surfels[i].size());
      std::iota(wanted[i].begin(), wanted[i].end(), std::size_t(0));
    }
    return wanted;
  }
  const Dims& dims = image.dims;
  for (const Voxel& v : o.seeds) {
    if (!dims.contains(v)) {
      std::ostringstream msg;
      msg << "seed voxel " << v << " lies outside the image domain [0," << dims.nx << ")x[0," << dims.ny
          << ")x[0," << dims.nz << ")";
      throw InvalidInput(msg.str());
    }
    const T L = image.at(v);
    if (LabelValue(L) == o.background)
      throw InvalidInput("seed voxel " + voxelText(v) + " is on the background label " + o.background.text());
    const std::size_t i = std::size_t(std::lower_bound(seeds.labels.begin(), seeds.labels.end(), L) - seeds.labels.begin());
    if (!std::binary_search(selected.begin(), selected.end(), i))
      throw InvalidInput("seed voxel " + voxelText(v) + " has label " + LabelValue(L).text() +
                         ", which is not selected");
    // The +x ray from the seed: its first 1 -> 0 step, the surfel (c, c + x) of the last voxel c
    // of L on it (the ray leaves the domain, so there is one).
    const std::optional<Surfel> ray = seedAlongRay(LabelImage<T>(image, L), v, directionOf(0, +1));
    if (!ray) throw InternalError("no boundary on the +x ray of seed voxel " + voxelText(v));
    const std::uint64_t key = ray->key();
    const auto& keys = seeds.surfels[i];
    const auto at = std::lower_bound(keys.begin(), keys.end(), key);
    if (at == keys.end() || *at != key) throw InternalError("the scan missed the seed surfel of seed voxel " + voxelText(v));
    wanted[i].push_back(std::size_t(at - keys.begin()));
  }
  return wanted;
}

void append(TriangleMesh& to, TriangleMesh&& from) {
  if (to.surfels.empty()) {
    to = std::move(from);
    return;
  }
  const auto offset = std::uint32_t(to.surfels.size());
  to.surfels.insert(to.surfels.end(), from.surfels.begin(), from.surfels.end());
  for (auto t : from.triangles) to.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

/// A label's result from its converted mesh, placed by the midpoint mapping.
LabelSurface labelSurface(const VoxelSource& source, LabelValue label, std::uint64_t voxels, TriangleMesh&& mesh,
                          const LabelOptions& o) {
  LabelSurface result = labelFields(source.geometry(), label, voxels, o);
  Surface& s = result.surface;
  placeSurface(source, std::move(mesh), Mapping::Midpoint, s.selection, 0.25, s);
  if (o.figures) addFigures(s);
  return result;
}

/// Every boundary of the selected labels: the count pass of one scan of the cubes
/// (converter/ScanLabels.h) sizes each label's Surface, its fill pass writes the surfels, their
/// points (the midpoint mapping, then the geometry, as placeSurface places them) and the
/// triangles into it; then each label's figures, labels in parallel.
template <class T>
std::vector<LabelSurface> scanAll(const VolumeRef<T>& image, const VoxelSource& source, const LabelOptions& o,
                                  tbb::task_arena& arena, int parts) {
  if (o.labels.kind == LabelSelection::Kind::List) requireListable<T>(o.labels, o.background);
  if (o.labels.kind == LabelSelection::Kind::Range) requireNonEmptyRange(o.labels);
  const WantedLabel<T> wanted(o.labels);
  LabelSurfaceScan<T, WantedLabel<T>> scan(image, o.background.as<T>(), wanted, o.pair, arena, parts);
  const LabelCounts<T>& counts = scan.counts();

  const std::vector<std::size_t> selected = selectLabels(counts.labels, o.labels, o.background);
  // The scan kept the wanted labels only, and selectLabels checked that each listed one occurs.
  if (selected.size() != counts.labels.size()) throw InternalError("the label scan kept labels not selected");
  const std::size_t n = counts.labels.size();
  auto cancelled = [&] {
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
  };
  const ImageGeometry geometry = source.geometry();
  std::vector<LabelSurface> out(n);
  std::vector<LabelMeshArrays> arrays(n);
  forEachIndex(arena, n, [&](std::size_t i) {
    out[i] = labelFields(geometry, LabelValue(counts.labels[i]), counts.voxels[i], o);
    Surface& s = out[i].surface;
    // (Huge pages for a label's arrays of 2 MiB and more only: most labels' are smaller.)
    resizeHugePages(s.vertices, counts.surfels[i]);
    resizeHugePages(s.surfels, counts.surfels[i]);
    resizeHugePages(s.triangles, counts.triangles[i]);
    arrays[i] = {s.surfels.data(), s.vertices.data(), s.triangles.data()};
  });
  cancelled();
  scan.fill(arrays, [&](const Surfel& s) { return geometry.toPhysical(MidpointMapping{}(s)); });
  for (const LabelSurface& l : out) {  // (as placeSurface checks its vertices: PhysicalRange.h)
    const Surface& s = l.surface;
    requirePlacedVertices(geometry, s.vertices, [&](std::size_t v) { return MidpointMapping{}(s.surfels[v]); });
  }
  const bool mirrored = geometry.handedness() < 0;  // keep the normals pointing outwards (placeSurface)

  // Largest first, so that the last to finish are small.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return counts.surfels[a] > counts.surfels[b]; });
  forEachIndex(arena, n, [&](std::size_t k) {
    cancelled();
    finishScannedLabel(out[order[k]].surface, mirrored, o);
  });
  return out;
}

template <class T>
std::vector<LabelSurface> extractTyped(const VolumeView& view, const VoxelSource& source, const LabelOptions& o) {
  if (!o.background.fits<T>())
    throw InvalidInput("background " + o.background.text() + " is not a value of " +
                       toString(scalarTypeOf<T>()) + " voxels");
  const Dims dims = view.dims;
  const VolumeRef<T> image(static_cast<const T*>(view.data), dims, view.strides[0], view.strides[1], view.strides[2]);
  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  const int parts = o.threads == 1 ? 1 : std::min(dims.nz, 4 * std::max(1, arena.max_concurrency()));
  const bool fromSeeds = !o.seeds.empty();
  if (fromSeeds && o.boundaries == LabelBoundaries::Largest)
    throw InvalidInput("seeds select their own boundaries: give seeds or the largest boundary, not both");
  if (o.smooth && o.walls != LabelWalls::Shared)
    throw InvalidInput("smoothing a label map needs shared walls: each label smoothed on its own would pull the "
                       "vertices it shares with its neighbours apart (docs/theory.md §12)");
  if (o.decimate && o.walls != LabelWalls::Shared)
    throw InvalidInput("decimating a label map needs shared walls: each label decimated on its own would no "
                       "longer share its walls with its neighbours (docs/theory.md §12)");
  if (o.walls == LabelWalls::Shared) {
    if (fromSeeds || o.boundaries != LabelBoundaries::All)
      throw InvalidInput("shared walls partition the whole image: every boundary of every label, no seeds or largest");
    if (o.pair != AdjacencyPair::k26_6 && o.pair != AdjacencyPair::k6_26)
      throw InvalidInput("shared walls take the adjacency pair 26-6 or 6-26, not " + toString(o.pair));
    return sharedWallSurfaces(image, source, o, [&](const std::vector<T>& labels) {
      return selectLabels(labels, o.labels, o.background);
    });
  }
  if (!fromSeeds && o.boundaries == LabelBoundaries::All) return scanAll(image, source, o, arena, parts);

  // Some boundaries of each label: one scan of the rows for seeds, slabs of planes in
  // parallel, then each label's boundaries tracked.
  std::vector<LabelSeeds<T>> slabs(std::size_t(std::max(parts, 1)));
  forEachIndex(arena, slabs.size(), [&](std::size_t k) {
    const int z0 = int(std::int64_t(dims.nz) * std::int64_t(k) / std::int64_t(slabs.size()));
    const int z1 = int(std::int64_t(dims.nz) * std::int64_t(k + 1) / std::int64_t(slabs.size()));
    slabs[k] = scanLabelSeeds(image, o.background.as<T>(), z0, z1);
  });
  LabelSeeds<T> seeds = mergeLabelSeeds(std::move(slabs));

  std::vector<std::size_t> selected = selectLabels(seeds.labels, o.labels, o.background);
  const std::vector<std::vector<std::size_t>> wanted = wantedSeeds(image, seeds, selected, o);
  if (fromSeeds)  // only the labels of the seeds
    std::erase_if(selected, [&](std::size_t i) { return wanted[i].empty(); });

  // 2. The labels, largest first so that the last to finish are small.
  std::vector<std::size_t> order(selected.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return seeds.surfels[selected[a]].size() > seeds.surfels[selected[b]].size();
  });
  std::vector<LabelSurface> out(selected.size());
  forEachIndex(arena, order.size(), [&](std::size_t k) {
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
    const std::size_t r = order[k], i = selected[r];
    const Selection selection = Selection::label(LabelValue(seeds.labels[i]));
    const SourceImage binary(source, selection);
    TriangleMesh mesh;
    std::optional<SurfaceGraph> largest;
    std::size_t boundaries = 0;
    // Loops from the bricks the tracker read: the same image. A logic_error of the tracker or
    // the converter is an engine bug; the front door's own errors pass through as they are
    // (InvalidInput is a std::logic_error too).
    try {
      trackBoundaries(binary, seeds.surfels[i], wanted[i], o.pair, [&](SurfaceGraph&& graph) {
        ++boundaries;
        if (o.boundaries != LabelBoundaries::Largest)
          append(mesh, extractLoops(graph));
        else if (!largest || graph.surfelCount() > largest->surfelCount())
          largest = std::move(graph);
      });
      if (largest) mesh = extractLoops(*largest);
    } catch (const InvalidInput&) {
      throw;
    } catch (const InternalError&) {
      throw;
    } catch (const std::logic_error& e) {
      throw InternalError(e.what());
    }
    std::vector<std::uint64_t>().swap(seeds.surfels[i]);  // done with them: the output grows
    out[r] = labelSurface(source, selection.labelValue, seeds.voxels[i], std::move(mesh), o);
    out[r].surface.boundariesInImage = fromSeeds ? 0 : boundaries;
  });
  return out;
}

}  // namespace

LabelWalls defaultLabelWalls(bool everyBoundaryInOnePass, AdjacencyPair pair, bool refined) {
  const bool made = everyBoundaryInOnePass && (pair == AdjacencyPair::k26_6 || pair == AdjacencyPair::k6_26);
  return made || refined ? LabelWalls::Shared : LabelWalls::Independent;
}

std::vector<LabelSurface> extractLabels(const VolumeView& view, const LabelOptions& options) {
  if (!isInteger(view.type))
    throw InvalidInput("a label image needs integer voxels: this one has " + toString(view.type) + " voxels");
  if (options.threads < 0)
    throw InvalidInput("threads " + std::to_string(options.threads) + " is negative (0: all cores)");
  const std::unique_ptr<VoxelSource> source = makeViewSource(view);  // checks the view
  requirePhysicalDomain(view.geometry, view.dims);                   // before any voxel is read
  return visitScalarType(view.type, [&](auto zero) -> std::vector<LabelSurface> {
    using T = decltype(zero);
    if constexpr (std::is_integral_v<T>)
      return extractTyped<T>(view, *source, options);
    else
      throw InternalError("extractLabels: a float type passed the integer check");
  });
}

}  // namespace surftrack
