// scanThresholdBlock and mergeThresholdFragments (docs/api.md, "Thresholds by blocks"): every
// boundary of f > s meshed block by block and merged, equal to extract() with SeedRule::all()
// over the whole volume. The proof is that of label maps (docs/theory.md, "Label maps by
// blocks", and "Thresholds by blocks"): the binary image f > s is the label map of one label,
// so a block is scanned by the label scanner (converter/ScanLabels.h) over its owned cubes, on
// its box binarised by the source's own comparison; a vertex's gray values f(c), f(d) lie in
// the box too, so the fragment carries them and the merge places the vertex by the single
// pass's expression; and the merge restores the single pass's numbering of vertices (the order
// in which ScanIsoSurface.cpp meets the cut grid edges, a function of the edge alone) and of
// triangles (by owning cube).
#include "ThresholdBlocks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/task_arena.h>

#include "BlockOwnership.h"
#include "BoundaryMapping.h"
#include "Image.h"
#include "PhysicalRange.h"
#include "PlaceSurface.h"
#include "ScanIsoSurface.h"
#include "ScanLabels.h"
#include "SelectionValue.h"

namespace surftrack {
namespace {

/// The mapping the options mean for a block scan of a threshold, or InvalidInput.
Mapping requireThresholdOptions(const ExtractOptions& o) {
  if (o.selection.isLabel())
    throw InvalidInput("a threshold block scan takes a threshold selection: label maps go by scanLabelBlock");
  if (std::isnan(o.selection.value)) throw InvalidInput("iso-value is NaN");
  if (o.seed.kind != SeedRule::Kind::All)
    throw InvalidInput("a block scan meshes every boundary (SeedRule::all()): other seed rules need the whole volume");
  if (o.threads < 0) throw InvalidInput("threads " + std::to_string(o.threads) + " is negative (0: all cores)");
  if (!(o.epsilon > 0 && o.epsilon < 0.5))
    throw InvalidInput("epsilon " + numberText(o.epsilon, 10) + " is outside ]0, 0.5[");
  return o.mapping == Mapping::Midpoint ? Mapping::Midpoint : Mapping::Linear;  // Default: linear
}

/// The label scanner's wanted labels: the one label of a binarised box, 1.
struct TheOneVoxels {
  bool operator()(std::uint8_t) const { return true; }
};

/// Where the single pass (ScanIsoSurface.cpp) numbers the vertex of surfel s, as a number that
/// increases with its vertex index. It meets the cut grid edges slab by slab: plane -1's x- and
/// y-edges first, then for each slab z, z + 1 and each row j = y + 1, the x- and y-edges of row
/// j of plane z + 1 (by 64-voxel word of the row bit set, x-edges before y-edges, then by x) and
/// then the z-edges of row j between the planes (by x). Surfel s lies on the grid edge from its
/// low voxel along its axis.
std::uint64_t scanOrder(const Surfel& s) {
  const int axis = axisOf(s.n);
  Voxel low = s.c;
  if (signOf(s.n) < 0) low[axis] -= 1;
  const auto column = std::uint64_t(low.x + scan::kRowOffset);  // the voxel's bit in its row's bit set
  const auto row = std::uint64_t(low.y + 1);
  if (axis < 2) {
    const auto group = std::uint64_t(low.z + 1);  // plane z: numbered with slab z - 1 (plane -1 first)
    return group << 42 | row << 22 | (column >> 6) << 7 | std::uint64_t(axis) << 6 | (column & 63);
  }
  const auto group = std::uint64_t(low.z + 2);  // between z and z + 1: with plane z + 1's edges
  return group << 42 | row << 22 | std::uint64_t(1) << 21 | column;
}

}  // namespace

ThresholdFragment scanThresholdBlock(const VolumeView& view, Voxel origin, Dims volume, Voxel lo, Voxel hi,
                                     const ExtractOptions& o) {
  const Mapping mapping = requireThresholdOptions(o);
  const std::unique_ptr<VoxelSource> source = makeViewSource(view);  // checks the view
  requireBlock(view, origin, volume, lo, hi);
  ThresholdFragment out;
  out.volume = volume;
  out.voxels = std::uint64_t(hi.x - lo.x) * std::uint64_t(hi.y - lo.y) * std::uint64_t(hi.z - lo.z);

  // The box binarised by the source's comparison (the single pass's), one byte a voxel: the
  // label map of label 1.
  const Dims& dims = view.dims;
  std::vector<std::uint8_t> binary(dims.count());
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y) {
      std::uint8_t* row = binary.data() + (std::size_t(z) * std::size_t(dims.ny) + std::size_t(y)) * std::size_t(dims.nx);
      for (int x0 = 0; x0 < dims.nx; x0 += 64) {
        const int count = std::min(64, dims.nx - x0);
        const std::uint64_t bits = source->binaryRow(o.selection, Voxel{x0, y, z}, count);
        for (int i = 0; i < count; ++i) row[x0 + i] = std::uint8_t(bits >> i & 1);
      }
    }
  const VolumeRef<std::uint8_t> image(binary.data(), dims, 1, dims.nx, std::ptrdiff_t(dims.nx) * dims.ny);
  const ScanOwnership own = ownedCubes(origin, lo, hi);
  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  const int parts = o.threads == 1 ? 1 : std::min(hi.z - lo.z, 4 * std::max(1, arena.max_concurrency()));
  const TheOneVoxels wanted;
  LabelSurfaceScan<std::uint8_t, TheOneVoxels> scan(image, 0, wanted, o.pair, arena, parts, own);
  const LabelCounts<std::uint8_t>& counts = scan.counts();
  if (counts.labels.empty()) return out;  // no 1-voxel in the box
  out.keys.resize(counts.surfels[0]);
  out.triangles.resize(counts.triangles[0]);
  if (o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Cancelled("extraction cancelled");
  LabelMeshArrays arrays;
  arrays.keys = out.keys.data();
  arrays.triangles = out.triangles.data();
  scan.fill({arrays}, [](const Surfel&) { return std::array<double, 3>{}; });  // keys only: never placed
  dropUnusedKeys(out.keys, out.triangles);

  if (mapping == Mapping::Linear) {
    // Both voxels of a surfel of an owned cube lie in the box or outside the volume
    // (docs/theory.md, "Thresholds by blocks").
    std::vector<Voxel> voxels;
    voxels.reserve(2 * out.keys.size());
    for (std::uint64_t key : out.keys) {
      const Surfel s = Surfel::fromKey(key);
      if (!volume.contains(s.inside()) || !volume.contains(s.outside())) continue;
      for (const Voxel v : {s.inside() - origin, s.outside() - origin}) {
        if (!dims.contains(v)) throw InternalError("a block's surfel has a voxel of the volume outside its box");
        voxels.push_back(v);
      }
    }
    std::vector<double> f(voxels.size());
    source->values(voxels.data(), voxels.size(), f.data());
    out.values.resize(out.keys.size());
    std::size_t next = 0;
    for (std::size_t v = 0; v < out.keys.size(); ++v) {
      const Surfel s = Surfel::fromKey(out.keys[v]);
      if (volume.contains(s.inside()) && volume.contains(s.outside())) {
        out.values[v] = {f[next], f[next + 1]};
        next += 2;
      } else {
        out.values[v] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
      }
    }
  }
  return out;
}

Surface mergeThresholdFragments(const std::vector<ThresholdFragment>& fragments, const ImageGeometry& geometry,
                                const ExtractOptions& o) {
  const Mapping mapping = requireThresholdOptions(o);
  if (fragments.empty()) throw InvalidInput("no fragment to merge");
  const Dims volume = fragments.front().volume;
  std::uint64_t voxels = 0;
  std::size_t keyCount = 0, triangleCount = 0;
  for (const ThresholdFragment& f : fragments) {
    if (f.volume != volume) throw InvalidInput("fragments of volumes of different dimensions in one merge");
    if (!validKeys(f.keys)) throw InvalidInput("a fragment has keys out of range or not increasing");
    for (const auto& t : f.triangles)
      for (std::uint32_t v : t)
        if (v >= f.keys.size()) throw InvalidInput("a fragment has a triangle beyond its vertices");
    if (mapping == Mapping::Linear && f.values.size() != f.keys.size())
      throw InvalidInput("a fragment has no gray values for the linear mapping: it was scanned for the midpoint one");
    voxels += f.voxels;
    keyCount += f.keys.size();
    triangleCount += f.triangles.size();
  }
  requirePhysicalDomain(geometry, volume);  // as extract() does before any voxel is read

  // The vertices: the union of the fragments' surfels (a surfel on a block's border is in both
  // blocks' fragments, with the same gray values), each with where its gray values are.
  struct Vertex {
    std::uint64_t key;
    std::uint32_t fragment, index;
  };
  std::vector<Vertex> byKey;
  byKey.reserve(keyCount);
  for (std::size_t k = 0; k < fragments.size(); ++k)
    for (std::size_t v = 0; v < fragments[k].keys.size(); ++v)
      byKey.push_back({fragments[k].keys[v], std::uint32_t(k), std::uint32_t(v)});
  std::sort(byKey.begin(), byKey.end(), [](const Vertex& a, const Vertex& b) { return a.key < b.key; });
  byKey.erase(std::unique(byKey.begin(), byKey.end(), [](const Vertex& a, const Vertex& b) { return a.key == b.key; }),
              byKey.end());
  if (byKey.empty())
    throw InvalidInput("empty selection: no voxel has " + o.selection.text() +
                       " with a 0-voxel next to it: the image has no boundary surfel");
  if (byKey.size() > std::numeric_limits<std::uint32_t>::max())
    throw InvalidInput("the surface has more than 2^32 - 1 surfels");
  // The single pass's numbering: vertexOf[i] is the vertex of byKey[i].
  std::vector<std::uint64_t> order(byKey.size());
  for (std::size_t i = 0; i < byKey.size(); ++i) order[i] = scanOrder(Surfel::fromKey(byKey[i].key));
  std::vector<std::uint32_t> byOrder(byKey.size());
  std::iota(byOrder.begin(), byOrder.end(), 0u);
  std::sort(byOrder.begin(), byOrder.end(), [&](std::uint32_t a, std::uint32_t b) { return order[a] < order[b]; });
  std::vector<std::uint32_t> vertexOf(byKey.size());
  for (std::size_t v = 0; v < byOrder.size(); ++v) vertexOf[byOrder[v]] = std::uint32_t(v);

  // The triangles renumbered, then in the single pass's order: by owning cube (the blocks own
  // disjoint cubes, each fragment in the scan's order), stably, so the table's order within a cube.
  std::vector<std::pair<std::uint64_t, std::array<std::uint32_t, 3>>> triangles;
  triangles.reserve(triangleCount);
  for (const ThresholdFragment& f : fragments) {
    std::vector<std::uint32_t> global(f.keys.size());
    auto at = byKey.begin();
    for (std::size_t v = 0; v < f.keys.size(); ++v) {  // both increasing: one walk
      at = std::lower_bound(at, byKey.end(), f.keys[v], [](const Vertex& a, std::uint64_t k) { return a.key < k; });
      global[v] = vertexOf[std::size_t(at - byKey.begin())];
    }
    for (const auto& t : f.triangles)
      triangles.push_back({owningCube({f.keys[t[0]], f.keys[t[1]], f.keys[t[2]]}),
                           {global[t[0]], global[t[1]], global[t[2]]}});
  }
  std::stable_sort(triangles.begin(), triangles.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

  Surface out;
  out.pair = o.pair;
  out.selection = o.selection;
  out.mapping = mapping;
  out.geometry = geometry;
  out.triangles.resize(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) out.triangles[t] = triangles[t].second;
  std::vector<std::pair<std::uint64_t, std::array<std::uint32_t, 3>>>().swap(triangles);
  const std::size_t n = byKey.size();
  out.surfels.resize(n);
  out.vertices.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t v = vertexOf[i];
    const Surfel s = Surfel::fromKey(byKey[i].key);
    out.surfels[v] = s;
    double t = 0.5;  // the midpoint; for the linear mapping, a voxel outside the volume (placeVertices)
    if (mapping == Mapping::Linear && volume.contains(s.inside()) && volume.contains(s.outside())) {
      const std::array<double, 2>& f = fragments[byKey[i].fragment].values[byKey[i].index];
      t = linearParameter(o.selection.value, f[0], f[1], o.epsilon);
    }
    out.vertices[v] = geometry.toPhysical(pointOnSurfel(s, t));
  }
  requirePlacedVertices(geometry, out.vertices, [&](std::size_t v) { return MidpointMapping{}(out.surfels[v]); });
  if (geometry.handedness() < 0)  // a mirrored frame: keep the normals pointing outwards (placeSurface)
    for (auto& t : out.triangles) std::swap(t[1], t[2]);
  // What extract() counts for a scan: the whole domain, and two gray values a vertex for the
  // linear mapping.
  out.voxelsRead = voxels + (mapping == Mapping::Linear ? 2 * std::uint64_t(n) : 0);
  if (o.figures) addFigures(out);
  out.boundariesInImage = out.components.size();
  return out;
}

}  // namespace surftrack
