// _surftrack: the Python binding of the front door (docs/python.md). It translates: numpy
// arrays to VolumeViews (no copy), Python arguments to ExtractOptions, a Surface to numpy
// arrays, the engine's errors to Python's (voxels in the caller's axes, OSError for files), and
// Ctrl-C to the engine's cancel flag (the engine runs on a thread of its own). The axis handling
// and the defaults live in surftrack/__init__.py.
#include <cmath>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cstring>
#include <system_error>

#include <surftrack/Extract.h>
#include <surftrack/LabelBlockFiles.h>
#include <surftrack/Labels.h>
#include <surftrack/Refine.h>
#include <surftrack/ThresholdBlocks.h>

#include "ChunkedSource.h"
#include <OpenMesh/Core/System/omstream.hh>

#include "ArrayChunkProvider.h"
#include "EngineCalls.h"  // arrays as views, Ctrl-C, errors in array axes
#include "MarchingCubes.h"
#include "ChunkedStore.h"  // io/: zarr, OME-Zarr, N5
#include "ReadVolume.h"    // io/: ReadError
#include "PrecomputedMesh.h"  // converter/: Neuroglancer's format
#include "MultiresolutionMeshes.h"  // refine/: its multi-resolution variant
#include "PrecomputedFrame.h"  // converter/: the CLI's frames of both
#include "PrecomputedDirectory.h"  // converter/: segment ids and properties

namespace py = pybind11;
using namespace surftrack;
using namespace surftrack::binding;

namespace {

/// A Python label as the engine's exact LabelValue: an int (or anything with __index__: numpy's
/// integer scalars), exact up to 64 bits — segment ids far above 2^53 stay themselves; a float
/// only when it is an integer of at most 2^53, where it is still exact.
LabelValue labelOf(py::handle h, const char* what) {
  const std::string text = py::repr(h).cast<std::string>();
  if (PyFloat_Check(h.ptr())) {
    const double v = PyFloat_AsDouble(h.ptr());
    if (std::fabs(v) <= 0x1p53)
      if (const auto L = LabelValue::fromDouble(v)) return *L;
    throw py::value_error(std::string(what) + " " + text + " is not an integer (labels are integers; " +
                          "give ints beyond 2^53, where floats skip integers)");
  }
  PyObject* index = PyNumber_Index(h.ptr());
  if (!index) {
    PyErr_Clear();
    throw py::type_error(std::string(what) + " must be an integer, not " + text);
  }
  const py::object n = py::reinterpret_steal<py::object>(index);
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index, &overflow);
  if (overflow == 0 && !PyErr_Occurred()) return LabelValue(v);
  PyErr_Clear();
  if (overflow > 0) {
    const unsigned long long u = PyLong_AsUnsignedLongLong(index);
    if (!PyErr_Occurred()) return LabelValue(u);
    PyErr_Clear();
  }
  throw py::value_error(std::string(what) + " " + text + " is beyond 64 bits: no voxel type holds it");
}

/// A label as a Python int, exactly.
py::int_ labelObject(const LabelValue& L) {
  if (L.negative()) return py::int_(L.as<std::int64_t>());
  return py::reinterpret_steal<py::int_>(PyLong_FromUnsignedLongLong(L.magnitude()));
}

/// An extracted surface held for Python: its vectors are the numpy arrays (no copy); normals
/// and surfels in array axes are computed on first use, without the GIL.
struct Result {
  Surface surface;
  std::array<int, 3> order{};  // engine axis e is array axis order[e]

  static py::array normals(const std::shared_ptr<Result>& r) {
    auto normals = std::make_shared<std::vector<std::array<double, 3>>>();
    {
      py::gil_scoped_release release;
      *normals = vertexNormals(r->surface);
    }
    return viewOf(normals->front().data(), {py::ssize_t(normals->size()), 3}, normals);
  }
  static py::array surfels(const std::shared_ptr<Result>& r) {
    auto out = std::make_shared<std::vector<std::int32_t>>(6 * r->surface.surfels.size());
    {
      py::gil_scoped_release release;
      std::int32_t* o = out->data();
      for (const Surfel& sv : r->surface.surfels) {
        const Voxel c = sv.inside(), d = sv.outside();
        for (int e = 0; e < 3; ++e) {  // back to array axes
          o[r->order[e]] = c[e];
          o[3 + r->order[e]] = d[e];
        }
        o += 6;
      }
    }
    return viewOf(out->data(), {py::ssize_t(r->surface.surfels.size()), 2, 3}, out);
  }
};

/// The arrays and figures of an extracted surface, as the keyword arguments of Python's Surface.
/// The figures as one (K, 7) array (a dict per component would cost more than the scan on
/// images with millions of noise specks); the Python layer makes dicts on first use.
py::array_t<double> componentsTable(const std::vector<ComponentFigures>& figures) {
  py::array_t<double> components({py::ssize_t(figures.size()), py::ssize_t(7)});
  auto c = components.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < py::ssize_t(figures.size()); ++i) {
    const ComponentFigures& f = figures[std::size_t(i)];
    const double row[7] = {double(f.surfels), double(f.triangles), double(f.edges), double(f.euler),
                           f.genus(), f.area, f.volume};
    for (int k = 0; k < 7; ++k) c(i, k) = row[k];
  }
  return components;
}

py::dict surfaceDict(const std::shared_ptr<Result>& r) {
  const Surface& s = r->surface;
  const py::ssize_t n = py::ssize_t(s.vertices.size()), m = py::ssize_t(s.triangles.size());
  static_assert(sizeof(std::array<double, 3>) == 3 * sizeof(double));
  static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::uint32_t));
  // (A surface is never empty: extract() and extractLabels() throw instead.)
  py::array vertices = viewOf(const_cast<double*>(s.vertices.front().data()), {n, 3}, r);
  py::array faces = viewOf(const_cast<std::uint32_t*>(s.triangles.front().data()), {m, 3}, r);
  py::array_t<double> components = componentsTable(s.components);
  py::dict timings;
  for (const StageTime& t : s.timings) timings[py::str(t.stage)] = t.seconds;
  py::dict out;
  out["vertices"] = vertices;
  out["faces"] = faces;
  out["result"] = r;
  out["components"] = components;
  out["euler"] = s.euler;
  out["boundaries_in_image"] = s.boundariesInImage;
  out["mapping"] = toString(s.mapping);
  out["timings"] = timings;
  return out;
}

/// Engine x is the last array axis (a zarr array's order, as numpy's C order).
constexpr std::array<int, 3> kLastAxisFirst = {2, 1, 0};

/// Runs `run` (extract() on a view or a source whose engine axes x, y, z are the array axes
/// order[0..2]) with the options of Python's extract(), then the refinement.
py::dict extractWith(const std::function<Surface(const ExtractOptions&)>& run, std::array<int, 3> order,
                     const std::string& selectionKind, py::object value, const std::string& seedKind,
                     std::array<double, 6> seed, const std::string& adjacency, const std::string& mapping,
                     double epsilon, int threads, bool figures, py::object progress, int smoothIterations,
                     std::optional<double> maxError, std::optional<double> reduction, double maxSeedDistance) {
  ExtractOptions o;
  o.selection = selectionKind == "label" ? Selection::label(labelOf(value, "label"))
                                         : Selection::threshold(value.cast<double>());
  o.pair = parseAdjacencyPair(adjacency);
  o.mapping = parseMapping(mapping);
  o.epsilon = epsilon;
  o.threads = threads;
  o.figures = figures;
  o.maxSeedDistance = maxSeedDistance;
  auto engineVoxel = [&](int first) {
    Voxel v;
    for (int e = 0; e < 3; ++e) v[e] = int(seed[first + order[e]]);
    return v;
  };
  if (seedKind == "voxel") o.seed = SeedRule::fromVoxel(engineVoxel(0));
  else if (seedKind == "ray") o.seed = SeedRule::ray(engineVoxel(0));
  else if (seedKind == "surfel") {
    const Voxel c = engineVoxel(0), d = engineVoxel(3), n = d - c;
    if (std::abs(n.x) + std::abs(n.y) + std::abs(n.z) != 1)
      throw py::value_error("a seed surfel is a pair of 6-adjacent voxels (c, d)");
    Direction dir = 0;
    for (Direction k = 0; k < 6; ++k)
      if (unitVector(k) == n) dir = k;
    o.seed = SeedRule::fromSurfel(Surfel{c, dir});
  } else if (seedKind == "point") o.seed = SeedRule::point({seed[0], seed[1], seed[2]});
  else if (seedKind == "largest") o.seed = SeedRule::largest();
  else o.seed = SeedRule::all();
  // Ctrl-C: the caller's thread watches for it while the engine runs (runWatchingSignals).
  std::atomic<bool> cancel{false};
  o.cancel = &cancel;
  // Progress: the engine runs without the GIL on its own thread and takes it back only here.
  if (!progress.is_none())
    o.progress = [&](const ProgressEvent& e) {
      py::gil_scoped_acquire gil;
      progress(e.stage, e.index, e.stages, e.surfels);
    };

  auto r = std::make_shared<Result>();
  r->order = order;
  RefineOptions ro;
  if (smoothIterations > 0) {
    SmoothOptions so;
    so.iterations = smoothIterations;
    so.threads = threads;
    so.cancel = &cancel;
    ro.smooth = so;
  }
  ro.progress = o.progress;  // stages "smooth" and "decimate", numbered among themselves
  if (maxError || reduction) {
    DecimateOptions d;
    d.maxError = maxError;
    d.reduction = reduction;
    d.cancel = &cancel;
    ro.decimate = d;
  }
  RefineReport refined;
  runEngine(order, cancel, [&] {
    r->surface = run(o);
    refined = refineSurface(r->surface, ro);
  });
  py::dict out = surfaceDict(r);
  const Surface& s = r->surface;
  if (s.seed.surfel) {
    py::list c, d;
    std::array<int, 3> ci{}, di{};
    for (int e = 0; e < 3; ++e) {
      ci[order[e]] = s.seed.surfel->inside()[e];
      di[order[e]] = s.seed.surfel->outside()[e];
    }
    out["seed_surfel"] = py::make_tuple(py::make_tuple(ci[0], ci[1], ci[2]), py::make_tuple(di[0], di[1], di[2]));
    out["seed_walk_steps"] = s.seed.walkSteps;
    if (s.seed.distance) out["seed_distance"] = *s.seed.distance;
  }
  out["warnings"] = s.warnings;
  if (refined.smooth || refined.decimate) {
    py::dict summary;
    if (const auto& smoothed = refined.smooth) {
      summary["smooth_iterations"] = smoothed->iterations;
      summary["max_vertex_displacement"] = smoothed->maxDisplacement;
      summary["steps_back"] = smoothed->stepsBack;
      summary["unguarded_cubes"] = smoothed->unguardedCubes;
    }
    if (const auto& decimated = refined.decimate) {
      summary["triangles_before"] = decimated->trianglesBefore;
      summary["triangles_after"] = decimated->trianglesAfter;
    }
    summary["volume_before"] = refined.volumeBefore;
    summary["volume_after"] = refined.volumeAfter;
    out["refine"] = summary;
  }
  return out;
}

/// Runs extract() on `volume` whose engine axes x, y, z are the array axes order[0..2].
py::dict extractArray(py::array volume, std::array<int, 3> order, const std::string& selectionKind,
                      py::object value, const std::string& seedKind, std::array<double, 6> seed,
                      const std::string& adjacency, const std::string& mapping, double epsilon,
                      std::array<double, 3> spacing, std::array<double, 3> origin,
                      std::array<std::array<double, 3>, 3> direction, int threads, bool figures,
                      py::object progress, int smoothIterations, std::optional<double> maxError,
                      std::optional<double> reduction, double maxSeedDistance) {
  const VolumeView view = viewOfArray(volume, order, spacing, origin, direction);
  return extractWith([&](const ExtractOptions& o) { return extract(view, o); }, order, selectionKind, value,
                     seedKind, seed, adjacency, mapping, epsilon, threads, figures, progress, smoothIterations,
                     maxError, reduction, maxSeedDistance);
}

/// What a chunk cache did, as Surface.chunks.
py::dict chunkFigures(const ChunkCache& cache) {
  const ChunkCacheCounters c = cache.counters();
  const Dims n = cache.layout().chunkCounts();
  py::dict chunks;
  chunks["chunks"] = std::uint64_t(n.nx) * std::uint64_t(n.ny) * std::uint64_t(n.nz);
  chunks["chunks_decoded"] = c.chunksDecoded;
  chunks["bytes_read"] = c.bytesRead;
  chunks["cache_hits"] = c.hits;
  return chunks;
}

py::dict extractStore(const std::string& path, int level, std::optional<std::int64_t> channel,
                      std::optional<std::int64_t> time, std::size_t cacheBytes, const std::string& selectionKind,
                      py::object value, const std::string& seedKind, std::array<double, 6> seed,
                      const std::string& adjacency, const std::string& mapping, double epsilon,
                      std::optional<std::array<double, 3>> spacing, std::optional<std::array<double, 3>> origin,
                      std::optional<std::array<std::array<double, 3>, 3>> direction, int threads, bool figures,
                      py::object progress, int smoothIterations, std::optional<double> maxError,
                      std::optional<double> reduction, double maxSeedDistance) {
  io::ChunkedStoreOptions chosen;
  chosen.level = level;
  chosen.channel = channel;
  chosen.time = time;
  io::ChunkedStore store;
  try {
    store = io::openChunkedStore(path, chosen);
  } catch (const io::ReadError& e) {
    throw py::value_error(e.what());
  }
  const auto cache = std::make_shared<const ChunkCache>(store.provider, cacheBytes);
  // Python's coordinates follow the array's axes (z, y, x for a store): the store's physical
  // rows (x, y, z) reversed.
  const ImageGeometry stored = cache->layout().geometry;
  ImageGeometry g = stored;
  for (int k = 0; k < 3; ++k) {
    g.origin[k] = stored.origin[2 - k];
    for (int e = 0; e < 3; ++e) g.direction[k][e] = stored.direction[2 - k][e];
  }
  for (int e = 0; e < 3; ++e) {  // engine axis e is array axis 2 - e
    const int a = kLastAxisFirst[e];
    if (spacing) g.spacing[e] = (*spacing)[a];
    if (direction)
      for (int k = 0; k < 3; ++k) g.direction[k][e] = (*direction)[k][a];
  }
  if (origin) g.origin = *origin;
  const std::unique_ptr<VoxelSource> chunked = makeChunkedSource(cache, g);
  const VoxelSource& source = *chunked;
  py::dict out;
  try {
    out = extractWith([&](const ExtractOptions& o) { return extract(source, o); }, kLastAxisFirst, selectionKind,
                      value, seedKind, seed, adjacency, mapping, epsilon, threads, figures, progress,
                      smoothIterations, maxError, reduction, maxSeedDistance);
  } catch (const io::ReadError& e) {
    throw py::value_error(e.what());  // a chunk that cannot be decoded
  }
  out["chunks"] = chunkFigures(*cache);
  return out;
}

/// extract() on an array that only Python reads (python/src/ArrayChunkProvider.h): `shape`
/// and `chunks` in the array's axes [z, y, x], `dtype` the native type each slice becomes;
/// spacing, origin and direction as extractArray's.
py::dict extractChunked(py::object array, std::array<std::int64_t, 3> shape, std::array<std::int64_t, 3> chunks,
                        py::dtype dtype, std::size_t cacheBytes, const std::string& selectionKind,
                        py::object value, const std::string& seedKind, std::array<double, 6> seed,
                        const std::string& adjacency, const std::string& mapping, double epsilon,
                        std::array<double, 3> spacing, std::array<double, 3> origin,
                        std::array<std::array<double, 3>, 3> direction, int threads, bool figures,
                        py::object progress, int smoothIterations, std::optional<double> maxError,
                        std::optional<double> reduction, double maxSeedDistance) {
  ChunkLayout layout;
  layout.type = scalarTypeOfDtype(dtype);
  for (int e = 0; e < 3; ++e) {
    const int a = kLastAxisFirst[e];
    if (shape[a] < 1 || shape[a] > kMaxDimension)
      throw py::value_error("volume shape: each dimension must be 1 to " + std::to_string(kMaxDimension));
    if (chunks[a] < 1) throw py::value_error("chunk shape: each dimension must be at least 1");
    (e == 0 ? layout.dims.nx : e == 1 ? layout.dims.ny : layout.dims.nz) = int(shape[a]);
    (e == 0 ? layout.chunk.nx : e == 1 ? layout.chunk.ny : layout.chunk.nz) = int(std::min(chunks[a], shape[a]));
    layout.geometry.spacing[e] = spacing[a];
    for (int k = 0; k < 3; ++k) layout.geometry.direction[k][e] = direction[k][a];
  }
  layout.geometry.origin = origin;
  const auto provider = std::make_shared<const python::ArrayChunkProvider>(std::move(array), layout, dtype);
  const auto cache = std::make_shared<const ChunkCache>(provider, cacheBytes);
  const std::unique_ptr<VoxelSource> source = makeChunkedSource(cache);
  py::dict out;
  try {
    out = extractWith([&](const ExtractOptions& o) { return extract(*source, o); }, kLastAxisFirst, selectionKind,
                      value, seedKind, seed, adjacency, mapping, epsilon, threads, figures, progress,
                      smoothIterations, maxError, reduction, maxSeedDistance);
  } catch (const io::ReadError& e) {
    throw py::value_error(e.what());  // a slice that failed or came back wrong
  }
  out["chunks"] = chunkFigures(*cache);
  return out;
}

/// The chunked store at `path` (its level, channel and time chosen), for the block tasks of the
/// command line's --dask (python/surftrack/_cli_dask.py).
io::ChunkedStore openStore(const std::string& path, int level, std::optional<std::int64_t> channel,
                           std::optional<std::int64_t> time) {
  io::ChunkedStoreOptions chosen;
  chosen.level = level;
  chosen.channel = channel;
  chosen.time = time;
  try {
    return io::openChunkedStore(path, chosen);
  } catch (const io::ReadError& e) {
    throw py::value_error(e.what());
  }
}

/// numpy's name of a voxel type, native byte order (toString's but for the float types, which
/// numpy would read as float64 both).
std::string dtypeName(ScalarType type) {
  return type == ScalarType::Float32 ? "float32" : type == ScalarType::Float64 ? "float64" : toString(type);
}

/// (shape [z, y, x], dtype name) of a store's chosen array.
py::tuple storeLayout(const std::string& path, int level, std::optional<std::int64_t> channel,
                      std::optional<std::int64_t> time) {
  const io::ChunkedStore store = openStore(path, level, channel, time);  // (alive while its layout is read)
  const ChunkLayout& l = store.provider->layout();
  return py::make_tuple(py::make_tuple(l.dims.nz, l.dims.ny, l.dims.nx), dtypeName(l.type));
}

/// The voxels [lo, hi) (array axes [z, y, x]) of a store's chosen array, each chunk decoded once.
py::array readStoreBox(const std::string& path, int level, std::optional<std::int64_t> channel,
                       std::optional<std::int64_t> time, std::array<int, 3> lo, std::array<int, 3> hi) {
  const io::ChunkedStore store = openStore(path, level, channel, time);
  const ChunkCache cache(store.provider, 0);  // (copyBox visits each chunk once)
  const Voxel at{lo[2], lo[1], lo[0]};
  const Dims extent{hi[2] - lo[2], hi[1] - lo[1], hi[0] - lo[0]};
  py::array out(py::dtype(dtypeName(store.provider->layout().type)),
                {py::ssize_t(std::max(extent.nz, 0)), py::ssize_t(std::max(extent.ny, 0)), py::ssize_t(std::max(extent.nx, 0))});
  void* data = out.mutable_data();
  try {
    py::gil_scoped_release release;
    copyBox(cache, at, extent, data);
  } catch (const io::ReadError& e) {
    throw py::value_error(e.what());
  } catch (const InvalidInput& e) {
    throw py::value_error(e.what());
  }
  return out;
}

/// Runs extractLabels() on `volume` (engine axes order[0..2]): a dict label -> surfaceDict.
py::dict labelSurfacesArray(py::array volume, std::array<int, 3> order, const std::string& selectionKind,
                            py::list labels, py::list range, py::object background,
                            const std::string& boundaries, std::vector<std::array<int, 3>> seeds,
                            const std::string& adjacency, std::array<double, 3> spacing,
                            std::array<double, 3> origin, std::array<std::array<double, 3>, 3> direction,
                            int threads, bool figures, const std::string& walls, int smoothIterations,
                            std::optional<double> maxError, std::optional<double> reduction) {
  const VolumeView view = viewOfArray(volume, order, spacing, origin, direction);
  LabelOptions o;
  if (maxError || reduction) {  // the complex's decimation (docs/theory.md §12, "Decimating the complex"), shared walls only
    DecimateOptions d;
    d.maxError = maxError;
    d.reduction = reduction;
    o.decimate = d;
  }
  if (smoothIterations > 0) {  // the complex's smoothing (docs/theory.md §12), shared walls only
    SmoothOptions so;
    so.iterations = smoothIterations;
    so.threads = threads;
    o.smooth = so;
  }
  if (walls != "independent" && walls != "shared")
    throw InvalidInput("unknown walls '" + walls + "': expected 'independent' or 'shared'");
  o.walls = walls == "shared" ? LabelWalls::Shared : LabelWalls::Independent;
  if (selectionKind == "list") {
    std::vector<LabelValue> list;
    for (py::handle L : labels) list.push_back(labelOf(L, "label"));
    o.labels = LabelSelection::list(std::move(list));
  } else if (selectionKind == "range") {
    o.labels = LabelSelection::range(labelOf(range[0], "label_range's first"), labelOf(range[1], "label_range's last"));
  }
  o.background = labelOf(background, "background");
  o.boundaries = boundaries == "largest" ? LabelBoundaries::Largest : LabelBoundaries::All;
  for (const auto& a : seeds) {
    Voxel v;
    for (int e = 0; e < 3; ++e) v[e] = a[order[e]];
    o.seeds.push_back(v);
  }
  o.pair = parseAdjacencyPair(adjacency);
  o.threads = threads;
  o.figures = figures;
  std::vector<LabelSurface> surfaces;
  std::atomic<bool> cancel{false};
  o.cancel = &cancel;
  runEngine(order, cancel, [&] { surfaces = extractLabels(view, o); });
  py::dict out;
  for (LabelSurface& ls : surfaces) {
    auto r = std::make_shared<Result>();
    r->order = order;
    r->surface = std::move(ls.surface);
    py::dict d = surfaceDict(r);
    d["voxels"] = ls.voxels;
    if (ls.smooth || ls.decimate) {  // as extract()'s "refine", this label's figures
      py::dict summary;
      if (const auto& smoothed = ls.smooth) {
        summary["smooth_iterations"] = smoothed->iterations;
        summary["max_vertex_displacement"] = smoothed->maxDisplacement;
        summary["steps_back"] = smoothed->stepsBack;
        summary["unguarded_cubes"] = smoothed->unguardedCubes;
        summary["volume_before"] = smoothed->volumeBefore;
        summary["volume_after"] = smoothed->volumeAfter;
      }
      if (const auto& decimated = ls.decimate) {
        summary["triangles_before"] = decimated->trianglesBefore;
        summary["triangles_after"] = decimated->trianglesAfter;
        summary["target_triangles"] = decimated->targetTriangles;
        if (!ls.smooth) summary["volume_before"] = decimated->volumeBefore;
        summary["volume_after"] = decimated->volumeAfter;
      }
      d["refine"] = summary;
    }
    out[labelObject(ls.label)] = d;
  }
  return out;
}

/// Array axes (z, y, x) as the engine's voxel (x, y, z): engine x is the last array axis, as
/// the block functions below read the array (order {2, 1, 0}).
Voxel engineVoxel(const std::array<int, 3>& zyx) { return Voxel{zyx[2], zyx[1], zyx[0]}; }

/// scanLabelBlock (docs/theory.md, "Label maps by blocks") on `box`, the voxels [origin,
/// origin + box.shape) of a volume of shape `volume`, owning the cubes of [lo, hi) (all in array
/// axes), with the pair and background given.
std::vector<LabelFragment> scanBlockOfArray(py::array box, std::array<int, 3> origin, std::array<int, 3> volume,
                                            std::array<int, 3> lo, std::array<int, 3> hi, py::object background,
                                            const std::string& adjacency) {
  const VolumeView view = viewOfArray(box, kLastAxisFirst, {1, 1, 1}, {0, 0, 0}, {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
  LabelOptions o;
  o.background = labelOf(background, "background");
  o.pair = parseAdjacencyPair(adjacency);
  o.figures = false;
  const Voxel v = engineVoxel(volume);
  std::vector<LabelFragment> fragments;
  std::atomic<bool> cancel{false};
  runEngine(kLastAxisFirst, cancel, [&] {
    fragments = scanLabelBlock(view, engineVoxel(origin), Dims{v.x, v.y, v.z}, engineVoxel(lo), engineVoxel(hi), o);
  });
  return fragments;
}

/// scanBlockOfArray: per label, (label, voxels, keys (uint64), triangles ((M, 3) uint32)).
py::list scanLabelBlockArray(py::array box, std::array<int, 3> origin, std::array<int, 3> volume,
                             std::array<int, 3> lo, std::array<int, 3> hi, py::object background,
                             const std::string& adjacency) {
  std::vector<LabelFragment> fragments = scanBlockOfArray(box, origin, volume, lo, hi, background, adjacency);
  py::list out;
  for (LabelFragment& f : fragments) {
    py::array_t<std::uint64_t> keys(py::ssize_t(f.keys.size()));
    std::copy(f.keys.begin(), f.keys.end(), keys.mutable_data());
    py::array_t<std::uint32_t> triangles({py::ssize_t(f.triangles.size()), py::ssize_t(3)});
    if (!f.triangles.empty()) std::memcpy(triangles.mutable_data(), f.triangles.data(), f.triangles.size() * 12);
    out.append(py::make_tuple(labelObject(f.label), f.voxels, keys, triangles));
  }
  return out;
}

/// A geometry given in array axes (spacing per array axis, direction columns per array axis) as
/// the engine's, whose x, y, z are the array's last, middle, first axes (kLastAxisFirst).
ImageGeometry geometryOfArrayAxes(const std::array<double, 3>& spacing, const std::array<double, 3>& origin,
                                  const std::array<std::array<double, 3>, 3>& direction) {
  ImageGeometry geometry;
  for (int e = 0; e < 3; ++e) {
    const int a = kLastAxisFirst[e];
    geometry.spacing[e] = spacing[a];
    for (int k = 0; k < 3; ++k) geometry.direction[k][e] = direction[k][a];
  }
  geometry.origin = origin;
  return geometry;
}

/// A merged label (`merge()`, run as engine work) as surfaceDict with its voxels; written to
/// `path` too when one is given (writeSurface: the bytes of Surface.write, without the arrays'
/// round trip through Python).
template <class Merge>
py::dict mergedLabelDict(Merge&& merge, const std::string& path = "", bool binary = true) {
  auto r = std::make_shared<Result>();
  r->order = kLastAxisFirst;
  std::uint64_t voxels = 0;
  std::atomic<bool> cancel{false};
  runEngine(kLastAxisFirst, cancel, [&] {
    LabelSurface merged = merge();
    voxels = merged.voxels;
    r->surface = std::move(merged.surface);
    if (!path.empty()) writeSurface(r->surface, path, binary, &cancel);
  });
  py::dict d = surfaceDict(r);
  d["voxels"] = voxels;
  return d;
}

/// The options of a label's merge (its pair and figures; the background as the blocks').
LabelOptions labelMergeOptions(py::object background, const std::string& adjacency, bool figures) {
  LabelOptions o;
  o.background = labelOf(background, "background");
  o.pair = parseAdjacencyPair(adjacency);
  o.figures = figures;
  return o;
}

/// mergeLabelFragments: the fragments (voxels, keys, triangles) of `label` from every block of a
/// partition, as label_surfaces_array gives that label (geometry in array axes).
py::dict mergeLabelFragmentsArrays(py::object label, py::list fragments, std::array<double, 3> spacing,
                                   std::array<double, 3> origin, std::array<std::array<double, 3>, 3> direction,
                                   py::object background, const std::string& adjacency, bool figures) {
  const ImageGeometry geometry = geometryOfArrayAxes(spacing, origin, direction);
  const LabelOptions o = labelMergeOptions(background, adjacency, figures);
  const LabelValue L = labelOf(label, "label");
  std::vector<LabelFragment> parts;
  for (py::handle h : fragments) {
    const py::tuple t = h.cast<py::tuple>();
    const auto keys = t[1].cast<py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>>();
    const auto triangles = t[2].cast<py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>>();
    if (keys.ndim() != 1 || triangles.ndim() != 2 || triangles.shape(1) != 3)
      throw py::value_error("a fragment is (voxels, keys (K,), triangles (M, 3))");
    LabelFragment f;
    f.label = L;
    f.voxels = t[0].cast<std::uint64_t>();
    f.keys.assign(keys.data(), keys.data() + keys.shape(0));
    f.triangles.resize(std::size_t(triangles.shape(0)));
    if (!f.triangles.empty()) std::memcpy(f.triangles.data(), triangles.data(), f.triangles.size() * 12);
    parts.push_back(std::move(f));
  }
  return mergedLabelDict([&] { return mergeLabelFragments(parts, geometry, o); });
}

/// scanLabelBlock written to the fragment file `path` (writeLabelFragmentFile): per label,
/// (label, keys, triangles) counts.
py::list scanLabelBlockFile(py::array box, std::array<int, 3> origin, std::array<int, 3> volume,
                            std::array<int, 3> lo, std::array<int, 3> hi, py::object background,
                            const std::string& adjacency, const std::string& path) {
  const std::vector<LabelFragment> fragments = scanBlockOfArray(box, origin, volume, lo, hi, background, adjacency);
  const Voxel v = engineVoxel(volume);
  std::atomic<bool> cancel{false};
  runWatchingSignals(cancel, [&] {
    writeLabelFragmentFile(path, Dims{v.x, v.y, v.z}, engineVoxel(lo), engineVoxel(hi), fragments);
  });
  py::list out;
  for (const LabelFragment& f : fragments)
    out.append(py::make_tuple(labelObject(f.label), f.keys.size(), f.triangles.size()));
  return out;
}

/// The index of a fragment file (readFragmentFileIndex): per label, (label, keys, triangles).
py::list fragmentFileSummary(const std::string& path) {
  FragmentFileIndex index;
  std::atomic<bool> cancel{false};
  runEngine(kLastAxisFirst, cancel, [&] { index = readFragmentFileIndex(path); });
  py::list out;
  for (const auto& e : index.entries) out.append(py::make_tuple(labelObject(e.label), e.keys, e.triangles));
  return out;
}

/// mergeLabelFragmentFiles: `label` from its blocks' fragment files, as merge_label_fragments;
/// written to `path` too when one is given (mergedLabelDict).
py::dict mergeLabelFilesArrays(py::object label, const std::vector<std::string>& paths, std::array<double, 3> spacing,
                               std::array<double, 3> origin, std::array<std::array<double, 3>, 3> direction,
                               py::object background, const std::string& adjacency, bool figures,
                               const std::string& path, bool binary) {
  const ImageGeometry geometry = geometryOfArrayAxes(spacing, origin, direction);
  const LabelOptions o = labelMergeOptions(background, adjacency, figures);
  const LabelValue L = labelOf(label, "label");
  return mergedLabelDict([&] { return mergeLabelFragmentFiles(L, paths, geometry, o); }, path, binary);
}

/// writeLabelMeshStreamed: `label`'s mesh written from its fragment files to `path` (binary PLY)
/// with bounded memory, the bytes merge_label_files writes (geometry in array axes): (vertices,
/// triangles).
py::tuple writeLabelMeshStreamedFile(py::object label, const std::vector<std::string>& paths,
                                     std::array<double, 3> spacing, std::array<double, 3> origin,
                                     std::array<std::array<double, 3>, 3> direction, const std::string& path,
                                     std::uint64_t budget) {
  const ImageGeometry geometry = geometryOfArrayAxes(spacing, origin, direction);
  const LabelValue L = labelOf(label, "label");
  LabelMeshCounts counts;
  std::atomic<bool> cancel{false};
  runEngine(kLastAxisFirst, cancel, [&] { counts = writeLabelMeshStreamed(L, paths, geometry, path, budget, &cancel); });
  return py::make_tuple(counts.vertices, counts.triangles);
}

/// labelFiguresByTree: `label`'s figures from the fragment files of a grid of `block` voxels
/// (array axes): voxels, the (K, 7) components table of surfaceDict, euler, vertices,
/// triangles, levels, leaves.
py::dict labelFiguresByTreeArrays(py::object label, const std::vector<std::string>& paths, std::array<int, 3> volume,
                                  std::array<int, 3> block, std::array<double, 3> spacing,
                                  std::array<double, 3> origin, std::array<std::array<double, 3>, 3> direction,
                                  const std::string& adjacency, std::uint64_t budget) {
  const ImageGeometry geometry = geometryOfArrayAxes(spacing, origin, direction);
  LabelOptions o;
  o.pair = parseAdjacencyPair(adjacency);
  const LabelValue L = labelOf(label, "label");
  const Voxel v = engineVoxel(volume), b = engineVoxel(block);
  LabelFigures f;
  std::atomic<bool> cancel{false};
  runEngine(kLastAxisFirst, cancel, [&] {
    f = labelFiguresByTree(L, paths, Dims{v.x, v.y, v.z}, Dims{b.x, b.y, b.z}, geometry, o, budget);
  });
  long long euler = 0;
  std::uint64_t vertices = 0, triangles = 0;
  for (const ComponentFigures& k : f.components) {
    euler += k.euler;
    vertices += k.surfels;
    triangles += k.triangles;
  }
  py::dict d;
  d["voxels"] = f.voxels;
  d["components"] = componentsTable(f.components);
  d["euler"] = euler;
  d["vertices"] = vertices;
  d["triangles"] = triangles;
  d["levels"] = f.levels;
  d["leaves"] = f.leaves;
  return d;
}

/// The options of a threshold block scan and its merge: every boundary of f > level.
ExtractOptions thresholdBlockOptions(double level, const std::string& adjacency, const std::string& mapping,
                                     double epsilon, bool figures) {
  ExtractOptions o;
  o.selection = Selection::threshold(level);
  o.seed = SeedRule::all();
  o.pair = parseAdjacencyPair(adjacency);
  o.mapping = parseMapping(mapping);
  o.epsilon = epsilon;
  o.figures = figures;
  return o;
}

/// scanThresholdBlock (docs/theory.md, "Thresholds by blocks") on `box`, the voxels [origin,
/// origin + box.shape) of a volume of shape `volume`, owning the cubes of [lo, hi) (all in array
/// axes): (voxels, keys (K,) uint64, values (K, 2) float64 — f(c), f(d), (0, 2) for the midpoint
/// mapping —, triangles (M, 3) uint32).
py::tuple scanThresholdBlockArray(py::array box, std::array<int, 3> origin, std::array<int, 3> volume,
                                  std::array<int, 3> lo, std::array<int, 3> hi, double level,
                                  const std::string& adjacency, const std::string& mapping, double epsilon) {
  const VolumeView view = viewOfArray(box, kLastAxisFirst, {1, 1, 1}, {0, 0, 0}, {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
  ExtractOptions o = thresholdBlockOptions(level, adjacency, mapping, epsilon, false);
  const Voxel v = engineVoxel(volume);
  ThresholdFragment f;
  std::atomic<bool> cancel{false};
  o.cancel = &cancel;
  runEngine(kLastAxisFirst, cancel, [&] {
    f = scanThresholdBlock(view, engineVoxel(origin), Dims{v.x, v.y, v.z}, engineVoxel(lo), engineVoxel(hi), o);
  });
  py::array_t<std::uint64_t> keys(py::ssize_t(f.keys.size()));
  std::copy(f.keys.begin(), f.keys.end(), keys.mutable_data());
  py::array_t<double> values({py::ssize_t(f.values.size()), py::ssize_t(2)});
  if (!f.values.empty()) std::memcpy(values.mutable_data(), f.values.data(), f.values.size() * 16);
  py::array_t<std::uint32_t> triangles({py::ssize_t(f.triangles.size()), py::ssize_t(3)});
  if (!f.triangles.empty()) std::memcpy(triangles.mutable_data(), f.triangles.data(), f.triangles.size() * 12);
  return py::make_tuple(f.voxels, keys, values, triangles);
}

/// mergeThresholdFragments: the fragments (voxels, keys, values, triangles) of every block of a
/// partition of a volume of shape `volume`, as extract_array gives mode "all" (geometry in array
/// axes).
py::dict mergeThresholdFragmentsArrays(py::list fragments, std::array<int, 3> volume, double level,
                                       std::array<double, 3> spacing, std::array<double, 3> origin,
                                       std::array<std::array<double, 3>, 3> direction, const std::string& adjacency,
                                       const std::string& mapping, double epsilon, bool figures) {
  const ImageGeometry geometry = geometryOfArrayAxes(spacing, origin, direction);
  const ExtractOptions o = thresholdBlockOptions(level, adjacency, mapping, epsilon, figures);
  const Voxel v = engineVoxel(volume);
  std::vector<ThresholdFragment> parts;
  for (py::handle h : fragments) {
    const py::tuple t = h.cast<py::tuple>();
    if (t.size() != 4) throw py::value_error("a fragment is (voxels, keys (K,), values (K, 2), triangles (M, 3))");
    const auto keys = t[1].cast<py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>>();
    const auto values = t[2].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
    const auto triangles = t[3].cast<py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>>();
    if (keys.ndim() != 1 || values.ndim() != 2 || values.shape(1) != 2 || triangles.ndim() != 2 ||
        triangles.shape(1) != 3)
      throw py::value_error("a fragment is (voxels, keys (K,), values (K, 2), triangles (M, 3))");
    ThresholdFragment f;
    f.volume = Dims{v.x, v.y, v.z};
    f.voxels = t[0].cast<std::uint64_t>();
    f.keys.assign(keys.data(), keys.data() + keys.shape(0));
    f.values.resize(std::size_t(values.shape(0)));
    if (!f.values.empty()) std::memcpy(f.values.data(), values.data(), f.values.size() * 16);
    f.triangles.resize(std::size_t(triangles.shape(0)));
    if (!f.triangles.empty()) std::memcpy(f.triangles.data(), triangles.data(), f.triangles.size() * 12);
    parts.push_back(std::move(f));
  }
  auto r = std::make_shared<Result>();
  r->order = kLastAxisFirst;
  std::atomic<bool> cancel{false};
  runEngine(kLastAxisFirst, cancel, [&] { r->surface = mergeThresholdFragments(parts, geometry, o); });
  py::dict d = surfaceDict(r);
  d["warnings"] = r->surface.warnings;
  return d;
}

Surface surfaceOfArrays(py::array_t<double, py::array::c_style | py::array::forcecast> vertices,
                        py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> faces,
                        py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> surfels) {
  if (vertices.ndim() != 2 || vertices.shape(1) != 3) throw py::value_error("vertices must be (N, 3)");
  if (faces.ndim() != 2 || faces.shape(1) != 3) throw py::value_error("faces must be (M, 3)");
  Surface s;
  const std::size_t n = std::size_t(vertices.shape(0));
  s.vertices.resize(n);
  s.surfels.resize(n);
  auto v = vertices.unchecked<2>();
  auto sf = surfels.unchecked<3>();
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) s.vertices[i][k] = v(py::ssize_t(i), k);
    const Voxel c{int(sf(i, 0, 0)), int(sf(i, 0, 1)), int(sf(i, 0, 2))};
    const Voxel d{int(sf(i, 1, 0)), int(sf(i, 1, 1)), int(sf(i, 1, 2))};
    for (Direction k = 0; k < 6; ++k)
      if (unitVector(k) == d - c) s.surfels[i] = Surfel{c, k};
  }
  auto f = faces.unchecked<2>();
  s.triangles.resize(std::size_t(faces.shape(0)));
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::int64_t idx = f(py::ssize_t(t), k);
      if (idx < 0 || std::size_t(idx) >= n) throw py::value_error("a face refers to a vertex that does not exist");
      s.triangles[t][k] = std::uint32_t(idx);
    }
  return s;
}

void writeArrays(py::array_t<double, py::array::c_style | py::array::forcecast> vertices,
                 py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> faces,
                 py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> surfels,
                 const std::string& path, bool binary) {
  const Surface s = surfaceOfArrays(vertices, faces, surfels);
  std::atomic<bool> cancel{false};
  runWatchingSignals(cancel, [&] { writeSurface(s, path, binary, &cancel); });
}

/// writeSurfaceComponents: each connected component to its own file, paths in the order of the
/// surface's components table.
void writeComponentArrays(py::array_t<double, py::array::c_style | py::array::forcecast> vertices,
                          py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> faces,
                          py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> surfels,
                          const std::vector<std::string>& paths, bool binary) {
  const Surface s = surfaceOfArrays(vertices, faces, surfels);
  std::atomic<bool> cancel{false};
  runWatchingSignals(cancel, [&] { writeSurfaceComponents(s, paths, binary, &cancel); });
}

/// A mesh's (N, 3) vertices and (M, 3) faces copied into the writers' arrays.
void meshOf(py::handle vertexArray, py::handle faceArray, std::vector<std::array<double, 3>>& vertices,
            std::vector<std::array<std::uint32_t, 3>>& triangles) {
  const auto v = vertexArray.cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
  const auto f = faceArray.cast<py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>>();
  if (v.ndim() != 2 || v.shape(1) != 3) throw py::value_error("vertices must be (N, 3)");
  if (f.ndim() != 2 || f.shape(1) != 3) throw py::value_error("faces must be (M, 3)");
  vertices.resize(std::size_t(v.shape(0)));
  std::memcpy(vertices.data(), v.data(), vertices.size() * sizeof(vertices[0]));
  triangles.resize(std::size_t(f.shape(0)));
  const std::int64_t* fp = f.data();
  for (std::size_t k = 0; k < 3 * triangles.size(); ++k) {
    if (fp[k] < 0 || std::size_t(fp[k]) >= vertices.size())
      throw py::value_error("a face refers to a vertex that does not exist");
    triangles[k / 3][k % 3] = std::uint32_t(fp[k]);
  }
}

/// The multi-resolution options of write_precomputed's arguments (sharding 1:
/// murmurhash3_x86_128, 2: identity, 0: unsharded).
refine::MultiresolutionOptions multiresOptions(int lods, int quantizationBits, int sharding) {
  refine::MultiresolutionOptions o;
  o.lods = lods;
  o.quantizationBits = quantizationBits;
  o.sharded = sharding != 0;
  o.identityHash = sharding == 2;
  return o;
}

/// Writes (label, vertices, faces, name) tuples as a Neuroglancer precomputed mesh directory
/// (converter/PrecomputedMesh.h, or with lods > 0 the multi-resolution format of
/// refine/MultiresolutionMeshes.h); `linear` and `offset` map the vertices to nanometres.
void writePrecomputed(const py::list& segments, const std::string& path, std::array<std::array<double, 3>, 3> linear,
                      std::array<double, 3> offset, int lods, int quantizationBits, int sharding) {
  std::vector<std::vector<std::array<double, 3>>> vertices(segments.size());
  std::vector<std::vector<std::array<std::uint32_t, 3>>> triangles(segments.size());
  std::vector<PrecomputedSegment> out;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const py::tuple t = segments[i].cast<py::tuple>();
    meshOf(t[1], t[2], vertices[i], triangles[i]);
    out.push_back({labelOf(t[0], "label"), &vertices[i], &triangles[i], t[3].cast<std::string>()});
  }
  try {
    if (lods == 0) {
      writePrecomputedMeshes(out, path, ToNanometres{linear, offset});
    } else {
      refine::MultiresolutionOptions o = multiresOptions(lods, quantizationBits, sharding);
      std::atomic<bool> cancel{false};
      o.cancel = &cancel;
      runWatchingSignals(cancel, [&] { refine::writeMultiresolutionMeshes(out, path, ToNanometres{linear, offset}, o); });
    }
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

// The pieces of write_precomputed for a writer that encodes its segments in many tasks
// (python/surftrack/distributed.py, docs/python.md "Neuroglancer output on Dask"): each the
// function the whole writer calls, so that the files are the same bytes.

/// One segment's files: (manifest, data) = (`<id>:0`, `<id>.mesh`) for lods 0, else (`<id>.index`,
/// `<id>`), the sharded layout's value and prefix. With `geometry` (spacing, origin, direction),
/// the vertices are the command line's physical coordinates and lods > 0 stores their voxel
/// indices as its single pass does (converter/PrecomputedFrame.h).
py::tuple encodePrecomputedSegment(py::handle label, py::handle vertexArray, py::handle faceArray,
                                   std::array<std::array<double, 3>, 3> linear, std::array<double, 3> offset, int lods,
                                   int quantizationBits, std::optional<py::tuple> geometry) {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  meshOf(vertexArray, faceArray, vertices, triangles);
  const LabelValue id = labelOf(label, "label");
  try {
    const std::string none;
    checkSegmentIds({{id, &none}});
    const ToNanometres m{linear, offset};
    if (!std::isfinite(m.determinant()) || m.determinant() == 0)
      throw std::invalid_argument("the map of the meshes to nanometres is singular or not finite");
    if (lods == 0) {
      const PrecomputedSegment s{id, &vertices, &triangles, ""};
      return py::make_tuple(py::bytes(legacyManifestBytes(id)), py::bytes(legacyFragmentBytes(s, m)));
    }
    if (geometry) {
      ImageGeometry g;
      g.spacing = (*geometry)[0].cast<std::array<double, 3>>();
      g.origin = (*geometry)[1].cast<std::array<double, 3>>();
      g.direction = (*geometry)[2].cast<std::array<std::array<double, 3>, 3>>();
      toVoxelIndices(g, vertices, triangles);
    }
    refine::MultiresolutionOptions o = multiresOptions(lods, quantizationBits, 0);
    refine::checkMultiresolutionOptions(o);
    std::atomic<bool> cancel{false};
    o.cancel = &cancel;
    EncodedMultiresSegment e;
    runWatchingSignals(cancel, [&] {
      e = encodeMultiresSegment(refine::multiresolutionSegment({id, &vertices, &triangles, ""}, o), quantizationBits,
                                m.determinant() < 0);
    });
    return py::make_tuple(py::bytes(e.manifest), py::bytes(e.data));
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

/// The `info` file of `count` segments (the sharding layout depends on the count).
py::bytes precomputedInfo(std::array<std::array<double, 3>, 3> linear, std::array<double, 3> offset, int lods,
                          int quantizationBits, int sharding, std::size_t count, bool named) {
  if (lods == 0) return py::bytes(legacyInfoBytes(named));
  const refine::MultiresolutionOptions o = multiresOptions(lods, quantizationBits, sharding);
  return py::bytes(multiresInfoBytes(ToNanometres{linear, offset}, refine::multiresolutionFormat(count, o), named));
}

/// `segment_properties/info` of (label, name) pairs, in their order.
py::bytes segmentProperties(const py::list& pairs) {
  std::vector<std::pair<LabelValue, std::string>> names;
  for (py::handle p : pairs) {
    const py::tuple t = p.cast<py::tuple>();
    names.emplace_back(labelOf(t[0], "label"), t[1].cast<std::string>());
  }
  return py::bytes(segmentPropertiesBytes(names));
}

/// The sharded layout (sharding 1 or 2) of `count` segments.
ShardingSpec shardingOf(int sharding, std::size_t count) {
  if (sharding != 1 && sharding != 2) throw py::value_error("sharding must be 1 (murmurhash3_x86_128) or 2 (identity)");
  return *refine::multiresolutionFormat(count, multiresOptions(1, 16, sharding)).sharding;
}

/// The shard number of each label in the sharded layout of `count` segments.
std::vector<std::uint64_t> precomputedShards(const py::list& labels, int sharding, std::size_t count) {
  const ShardingSpec spec = shardingOf(sharding, count);
  std::vector<std::uint64_t> out;
  for (py::handle L : labels) out.push_back(spec.shardOf(labelOf(L, "label").magnitude()));
  return out;
}

/// The shard file(s) of (label, manifest, data) triples, as (name, bytes): all of one shard
/// give one file, the same bytes as the whole writer's.
py::list buildPrecomputedShard(const py::list& segments, int sharding, std::size_t count) {
  const ShardingSpec spec = shardingOf(sharding, count);
  std::vector<ShardChunk> chunks;
  for (py::handle p : segments) {
    const py::tuple t = p.cast<py::tuple>();
    chunks.push_back({labelOf(t[0], "label").magnitude(), t[2].cast<std::string>(), t[1].cast<std::string>()});
  }
  py::list out;
  for (auto& [name, bytes] : buildShards(spec, std::move(chunks))) out.append(py::make_tuple(name, py::bytes(bytes)));
  return out;
}

/// The command line's map to nanometres of `geometry` and `nanometres` per unit
/// (converter/PrecomputedFrame.h): (linear, offset).
py::tuple cliPrecomputedFrame(std::array<double, 3> spacing, std::array<double, 3> origin,
                              std::array<std::array<double, 3>, 3> direction, double nanometres, bool multires) {
  ImageGeometry g;
  g.spacing = spacing;
  g.origin = origin;
  g.direction = direction;
  const ToNanometres m = multires ? multiresFrame(g, nanometres) : legacyFrame(g, nanometres);
  return py::make_tuple(m.linear, m.offset);
}

}  // namespace

PYBIND11_MODULE(_surftrack, m) {
  m.doc() = "surftrack's C++ front door (see surftrack.extract)";
  // OpenMesh's writers log to stderr ("[OBJWriter] : write file"); errors reach Python as
  // exceptions with their own one-line messages, as in the CLI (cli/main.cpp).
  omerr().disable();
  omlog().disable();
  omout().disable();
  py::register_exception<InvalidInput>(m, "InvalidInput", PyExc_ValueError);
  py::register_exception<InternalError>(m, "InternalError", PyExc_RuntimeError);
  py::register_exception<Cancelled>(m, "Cancelled", PyExc_KeyboardInterrupt);
  // A file that cannot be written (writeSurface): OSError with the system's errno, so Python
  // picks its subclass (FileNotFoundError, PermissionError, IsADirectoryError, ...).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::system_error& e) {
      if (e.code().category() != std::generic_category() && e.code().category() != std::system_category()) throw;
      py::object error = py::reinterpret_steal<py::object>(
          PyObject_CallFunction(PyExc_OSError, "is", e.code().value(), e.what()));
      if (!error) return;  // the call failed: its error is set
      PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
    }
  });
  m.attr("__version__") = SURFTRACK_VERSION;
  m.attr("MAX_SMOOTH_ITERATIONS") = kMaxSmoothIterations;
  m.attr("MAX_DIMENSION") = kMaxDimension;
  py::class_<Result, std::shared_ptr<Result>>(m, "Result")
      .def("normals", &Result::normals)
      .def("surfels", &Result::surfels);
  m.def("extract_array", &extractArray);
  defineMarchingCubes(m);
  m.def("extract_store", &extractStore);
  m.def("extract_chunked", &extractChunked);
  m.def("store_layout", &storeLayout);
  m.def("read_store_box", &readStoreBox);
  m.def("label_surfaces_array", &labelSurfacesArray);
  m.def(
      "default_label_walls",
      [](bool everyBoundaryInOnePass, const std::string& adjacency, bool refined) -> std::string {
        return defaultLabelWalls(everyBoundaryInOnePass, parseAdjacencyPair(adjacency), refined) == LabelWalls::Shared
                   ? "shared"
                   : "independent";
      },
      "The walls label_surfaces gets when none are asked (docs/theory.md §12).");
  m.def("write_arrays", &writeArrays);
  m.def("write_component_arrays", &writeComponentArrays);
  m.def("write_precomputed", &writePrecomputed);
  m.def("encode_precomputed_segment", &encodePrecomputedSegment);
  m.def("precomputed_info", &precomputedInfo);
  m.def("segment_properties", &segmentProperties);
  m.def("precomputed_shards", &precomputedShards);
  m.def("build_precomputed_shard", &buildPrecomputedShard);
  m.def("cli_precomputed_frame", &cliPrecomputedFrame);
  m.def("scan_label_block", &scanLabelBlockArray);
  m.def("merge_label_fragments", &mergeLabelFragmentsArrays);
  m.def("scan_label_block_file", &scanLabelBlockFile);
  m.def("fragment_file_summary", &fragmentFileSummary);
  m.def("merge_label_files", &mergeLabelFilesArrays, py::arg("label"), py::arg("paths"), py::arg("spacing"),
        py::arg("origin"), py::arg("direction"), py::arg("background"), py::arg("adjacency"), py::arg("figures"),
        py::arg("path") = "", py::arg("binary") = true);
  m.def("label_figures_by_tree", &labelFiguresByTreeArrays);
  m.def("write_label_mesh_streamed", &writeLabelMeshStreamedFile, py::arg("label"), py::arg("paths"),
        py::arg("spacing"), py::arg("origin"), py::arg("direction"), py::arg("path"), py::arg("budget"));
  m.def("scan_threshold_block", &scanThresholdBlockArray);
  m.def("merge_threshold_fragments", &mergeThresholdFragmentsArrays);
}
