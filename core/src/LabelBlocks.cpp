// scanLabelBlock and mergeLabelFragments (docs/api.md, "Label maps by blocks"): every label's
// surface meshed block by block and merged, equal to the single pass of extractLabels. The proof
// is docs/theory.md, "Label maps by blocks": the blocks' owned cubes partition the cubes of the
// scanning method (paper §5.1); a cube's triangles depend on its 8 voxels only, which a block
// reads (its box has a one-voxel apron on the high sides); a vertex is a surfel, named by its key
// in the volume, so the fragments' vertices need no welding; and the single pass's order is that
// of the keys for the vertices and of the owning cubes for the triangles, which the merge
// restores.
#include <algorithm>
#include <functional>
#include <limits>
#include <sstream>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "BlockOwnership.h"
#include "BoundaryMapping.h"
#include "Image.h"
#include "LabelSelection.h"
#include "Labels.h"
#include "PhysicalRange.h"
#include "ScanLabels.h"
#include "ScannedLabel.h"

namespace surftrack {
namespace {

template <class T>
std::vector<LabelFragment> scanBlockTyped(const VolumeView& view, Voxel origin, Voxel lo, Voxel hi,
                                          const LabelOptions& o) {
  if (!o.background.fits<T>())
    throw InvalidInput("background " + o.background.text() + " is not a value of " + toString(scalarTypeOf<T>()) +
                       " voxels");
  if (o.labels.kind == LabelSelection::Kind::List) requireListable<T>(o.labels, o.background);
  if (o.labels.kind == LabelSelection::Kind::Range) requireNonEmptyRange(o.labels);
  const VolumeRef<T> image(static_cast<const T*>(view.data), view.dims, view.strides[0], view.strides[1],
                           view.strides[2]);
  const ScanOwnership own = ownedCubes(origin, lo, hi);
  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  const int parts = o.threads == 1 ? 1 : std::min(hi.z - lo.z, 4 * std::max(1, arena.max_concurrency()));
  const WantedLabel<T> wanted(o.labels);
  LabelSurfaceScan<T, WantedLabel<T>> scan(image, o.background.as<T>(), wanted, o.pair, arena, parts, own);
  const LabelCounts<T>& counts = scan.counts();

  const std::size_t n = counts.labels.size();
  std::vector<LabelFragment> all(n);
  std::vector<LabelMeshArrays> arrays(n);
  for (std::size_t i = 0; i < n; ++i) {
    LabelFragment& f = all[i];
    f.label = LabelValue(counts.labels[i]);
    f.voxels = counts.voxels[i];
    f.keys.resize(counts.surfels[i]);
    f.triangles.resize(counts.triangles[i]);
    arrays[i].keys = f.keys.data();
    arrays[i].triangles = f.triangles.data();
  }
  if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
  scan.fill(arrays, [](const Surfel&) { return std::array<double, 3>{}; });  // keys only: never placed

  // Only the surfels of the owned cubes' triangles (BlockOwnership.h).
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { dropUnusedKeys(all[i].keys, all[i].triangles); });
  });
  // Labels met only in the apron with no triangle in the owned cubes belong to other blocks.
  std::erase_if(all, [](const LabelFragment& f) { return f.voxels == 0 && f.triangles.empty(); });
  return all;
}

/// Sorts `v`, made of sorted runs [runs[i], runs[i + 1]), by merging the runs pairwise:
/// O(n log k) for k runs, and stable (an earlier run's element first on ties), so the result is
/// exactly std::stable_sort's.
template <class T, class Less>
void mergeSortedRuns(std::vector<T>& v, const std::vector<std::size_t>& runs, Less less) {
  const std::size_t k = runs.size() - 1;
  for (std::size_t width = 1; width < k; width *= 2)
    for (std::size_t r = 0; r + width < k; r += 2 * width)
      std::inplace_merge(v.begin() + std::ptrdiff_t(runs[r]), v.begin() + std::ptrdiff_t(runs[r + width]),
                         v.begin() + std::ptrdiff_t(runs[std::min(r + 2 * width, k)]), less);
}

}  // namespace

std::vector<LabelFragment> scanLabelBlock(const VolumeView& view, Voxel origin, Dims volume, Voxel lo, Voxel hi,
                                          const LabelOptions& options) {
  if (!isInteger(view.type))
    throw InvalidInput("a label image needs integer voxels: this one has " + toString(view.type) + " voxels");
  if (options.threads < 0)
    throw InvalidInput("threads " + std::to_string(options.threads) + " is negative (0: all cores)");
  if (!options.seeds.empty())
    throw InvalidInput("a block scan meshes every boundary: seeds select boundaries of the whole volume");
  if (options.walls != LabelWalls::Independent)
    throw InvalidInput("a block scan gives independent walls only: shared walls are not split into blocks yet");
  if (options.smooth) throw InvalidInput("a block scan does not smooth: smoothing needs the whole complex (shared walls)");
  if (options.decimate)
    throw InvalidInput("a block scan does not decimate: decimation needs the whole complex (shared walls)");
  if (options.boundaries != LabelBoundaries::All)
    throw InvalidInput("a block scan meshes every boundary: the largest is a property of the whole volume");
  makeViewSource(view);  // checks the view
  requireBlock(view, origin, volume, lo, hi);
  return visitScalarType(view.type, [&](auto zero) -> std::vector<LabelFragment> {
    using T = decltype(zero);
    if constexpr (std::is_integral_v<T>)
      return scanBlockTyped<T>(view, origin, lo, hi, options);
    else
      throw InternalError("scanLabelBlock: a float type passed the integer check");
  });
}

LabelSurface mergeLabelFragments(const std::vector<LabelFragment>& fragments, const ImageGeometry& geometry,
                                 const LabelOptions& options) {
  if (fragments.empty()) throw InvalidInput("no fragment to merge");
  const LabelValue label = fragments.front().label;
  std::uint64_t voxels = 0;
  std::size_t keyCount = 0, triangleCount = 0;
  for (const LabelFragment& f : fragments) {
    if (f.label != label)
      throw InvalidInput("fragments of labels " + label.text() + " and " + f.label.text() + " in one merge");
    if (!validKeys(f.keys))
      throw InvalidInput("a fragment of label " + label.text() + " has keys out of range or not increasing");
    for (const auto& t : f.triangles)
      for (std::uint32_t v : t)
        if (v >= f.keys.size())
          throw InvalidInput("a fragment of label " + label.text() + " has a triangle beyond its vertices");
    voxels += f.voxels;
    keyCount += f.keys.size();
    triangleCount += f.triangles.size();
  }

  // The vertices: the union of the fragments' surfels, by increasing key, the order in which the
  // single pass numbers them (plane, row, voxel, direction).
  std::vector<std::uint64_t> keys;
  keys.reserve(keyCount);
  std::vector<std::size_t> keyRuns{0};
  for (const LabelFragment& f : fragments) {
    keys.insert(keys.end(), f.keys.begin(), f.keys.end());
    keyRuns.push_back(keys.size());
  }
  mergeSortedRuns(keys, keyRuns, std::less<>());  // each fragment's keys increase (validKeys)
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  if (keys.size() > std::numeric_limits<std::uint32_t>::max())
    throw InvalidInput("label " + label.text() + " has more than 2^32 - 1 surfels");

  // The triangles renumbered, then in the single pass's order: by owning cube (the blocks own
  // disjoint cubes, each fragment in the scan's order), stably, so the table's order within a cube.
  using OwnedTriangle = std::pair<std::uint64_t, std::array<std::uint32_t, 3>>;
  const auto byCube = [](const OwnedTriangle& a, const OwnedTriangle& b) { return a.first < b.first; };
  std::vector<OwnedTriangle> triangles;
  triangles.reserve(triangleCount);
  std::vector<std::size_t> runs{0};  // each fragment's triangles, [runs[i], runs[i + 1])
  std::vector<std::uint32_t> global;
  for (const LabelFragment& f : fragments) {
    global.resize(f.keys.size());
    std::size_t at = 0;
    for (std::size_t v = 0; v < f.keys.size(); ++v) {  // both increasing: one galloping walk
      std::size_t step = 1, hi = at;
      while (hi < keys.size() && keys[hi] < f.keys[v]) {
        at = hi + 1;
        hi += step;
        step *= 2;
      }
      at = std::size_t(std::lower_bound(keys.begin() + std::ptrdiff_t(at), keys.begin() + std::ptrdiff_t(std::min(hi, keys.size())),
                                        f.keys[v]) - keys.begin());
      global[v] = std::uint32_t(at);
    }
    for (const auto& t : f.triangles)
      triangles.push_back({owningCube({f.keys[t[0]], f.keys[t[1]], f.keys[t[2]]}),
                           {global[t[0]], global[t[1]], global[t[2]]}});
    // A block's scan meets its cubes in increasing order, so a run is sorted already; stably
    // sorted here if not, so the merges below give exactly a stable sort of the whole.
    const auto first = triangles.begin() + std::ptrdiff_t(runs.back());
    if (!std::is_sorted(first, triangles.end(), byCube)) std::stable_sort(first, triangles.end(), byCube);
    runs.push_back(triangles.size());
  }
  // (An earlier run first on ties: there are none, the blocks' cubes being disjoint.)
  mergeSortedRuns(triangles, runs, byCube);

  LabelSurface out = labelFields(geometry, label, voxels, options);
  Surface& s = out.surface;
  s.triangles.resize(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) s.triangles[t] = triangles[t].second;
  std::vector<std::pair<std::uint64_t, std::array<std::uint32_t, 3>>>().swap(triangles);
  s.surfels.resize(keys.size());
  s.vertices.resize(keys.size());
  for (std::size_t v = 0; v < keys.size(); ++v) {
    s.surfels[v] = Surfel::fromKey(keys[v]);
    s.vertices[v] = geometry.toPhysical(MidpointMapping{}(s.surfels[v]));  // the single pass's expression
  }
  requirePlacedVertices(geometry, s.vertices, [&](std::size_t v) { return MidpointMapping{}(s.surfels[v]); });
  finishScannedLabel(s, geometry.handedness() < 0, options);
  return out;
}

}  // namespace surftrack
