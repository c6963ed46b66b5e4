// surftrack.marching_cubes (docs/python.md, "surftrack.marching_cubes"): the scan of every
// boundary (paper §5.1, the linear mapping of §3.1), then exactly the four arrays scikit-image's
// marching_cubes returns — verts float32 (N, 3), faces int32 (M, 3) wound for the gradient
// direction, normals float32 (N, 3), values float32 (N) — each written once, in parallel, and
// handed to numpy without a copy. The same bits as converting the Surface that extract() gives
// with numpy, for any number of threads (python/tests/test_marching_cubes.py keeps that numpy
// conversion as its oracle).
#include "MarchingCubes.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "EngineCalls.h"
#include "HugePages.h"      // lib/: freshArray, the mesh-sized arrays on huge pages
#include "VertexNormals.h"  // refine/: the triangle normals vertexNormals() sums

namespace surftrack::binding {
namespace {

/// Runs body(begin, end) over [0, n) in blocks, on the arena's threads.
template <class Body>
void inBlocks(tbb::task_arena& arena, std::size_t n, Body&& body) {
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, std::size_t(1) << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  });
}

/// Unit outward vertex normals as float32: the bits of vertexNormals() (core/src/Figures.cpp)
/// converted, computed in parallel. That function adds the triangles' normals into their
/// vertices' sums in triangle order (refine::sumTriangleNormals); so does this, from the same
/// zero — the same additions, so the same doubles, for any number of threads. The triangles are
/// cut into consecutive chunks, one thread each; a vertex that only one chunk's range of vertex
/// indices covers is summed by that chunk alone, in order; the few others (where the ranges of
/// two chunks overlap: the scan numbers vertices and triangles slab by slab, so those of a
/// chunk are near each other) are summed afterwards, chunk after chunk, on one thread.
void vertexNormalsInto(const Surface& s, float* out, tbb::task_arena& arena) {
  const std::size_t n = s.vertices.size(), m = s.triangles.size();
  const auto& points = s.vertices;
  const auto& triangles = s.triangles;
  auto normalOf = [&](const std::array<std::uint32_t, 3>& t) {
    return refine::triangleNormal({points[t[0]], points[t[1]], points[t[2]]});
  };
  const std::size_t chunkCount =
      std::clamp<std::size_t>(m / (std::size_t(1) << 12), 1, 4 * std::size_t(arena.max_concurrency()));
  auto chunkBegin = [&](std::size_t k) { return m * k / chunkCount; };
  // Each chunk's range of vertex indices; covers[v]: how many ranges hold v.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> range(chunkCount, {~0u, 0u});
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), chunkCount, [&](std::size_t k) {
      auto& [low, high] = range[k];
      for (std::size_t f = chunkBegin(k); f < chunkBegin(k + 1); ++f)
        for (std::uint32_t v : triangles[f]) low = std::min(low, v), high = std::max(high, v);
    });
  });
  std::vector<int> steps(n + 1, 0);
  for (const auto& [low, high] : range)
    if (low <= high) ++steps[low], --steps[std::size_t(high) + 1];
  FreshArray<std::uint8_t> shared = freshArray<std::uint8_t>(n);  // covered by two ranges or more
  int covering = 0;
  for (std::size_t v = 0; v < n; ++v) shared[v] = (covering += steps[v]) > 1;
  steps = {};
  FreshArray<refine::Point3> sums = freshArray<refine::Point3>(n);
  inBlocks(arena, n, [&](std::size_t b, std::size_t e) { std::fill(sums.get() + b, sums.get() + e, refine::Point3{0, 0, 0}); });
  std::vector<std::vector<std::uint32_t>> later(chunkCount);  // triangles with a shared vertex
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), chunkCount, [&](std::size_t k) {
      for (std::size_t f = chunkBegin(k); f < chunkBegin(k + 1); ++f) {
        const refine::Point3 normal = normalOf(triangles[f]);
        bool defer = false;
        for (std::uint32_t v : triangles[f]) {
          if (shared[v]) {
            defer = true;
            continue;
          }
          for (int i = 0; i < 3; ++i) sums[v][i] += normal[i];
        }
        if (defer) later[k].push_back(std::uint32_t(f));
      }
    });
  });
  for (const std::vector<std::uint32_t>& chunk : later)
    for (std::uint32_t f : chunk) {
      const refine::Point3 normal = normalOf(triangles[f]);
      for (std::uint32_t v : triangles[f])
        if (shared[v])
          for (int i = 0; i < 3; ++i) sums[v][i] += normal[i];
    }
  inBlocks(arena, n, [&](std::size_t b, std::size_t e) {
    for (std::size_t v = b; v < e; ++v) {
      refine::Point3 sum = sums[v];
      const double length = std::sqrt(refine::dot(sum, sum));
      if (length > 0)
        for (double& x : sum) x /= length;
      for (int i = 0; i < 3; ++i) out[3 * v + i] = float(sum[i]);
    }
  });
}

/// A numpy array over a fresh array, which the array then owns (freed by std::free).
template <class T>
py::array_t<T> arrayOwning(FreshArray<T>& data, std::vector<py::ssize_t> shape) {
  py::capsule owner(data.get(), [](void* p) { std::free(p); });
  T* p = data.release();
  return py::array_t<T>(std::move(shape), p, owner);
}

/// The four arrays, written while the GIL is free.
struct Arrays {
  std::size_t vertexCount = 0;
  FreshArray<float> verts, normals, values;
  std::shared_ptr<std::vector<std::array<std::uint32_t, 3>>> faces;  // the scan's own, rewound
  std::vector<StageTime> timings;  // the core's stages, then "arrays": the four written
};

/// The mesh of `view` at `level` as scikit-image's arrays. `descent`: faces wound clockwise
/// seen from where the normals point (scikit-image's default gradient_direction), else
/// counter-clockwise as the engine winds them.
Arrays meshArrays(const VolumeView& view, double level, AdjacencyPair pair, bool descent, int threads,
                  const std::atomic<bool>& cancel) {
  ExtractOptions o;
  o.selection = Selection::threshold(level);
  o.seed = SeedRule::all();
  o.pair = pair;
  o.mapping = Mapping::Linear;
  o.epsilon = 1e-9;  // as close to the voxels as scikit-image's interpolation goes
  o.threads = threads;
  o.figures = false;
  o.cancel = &cancel;
  Surface s = extract(view, o);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = s.vertices.size(), m = s.triangles.size();
  if (n > std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw InvalidInput("the surface has " + std::to_string(n) + " vertices: more than int32 faces can index "
                       "(scikit-image's dtype); surftrack.extract() gives uint32 faces");
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  Arrays a;
  a.vertexCount = n;
  a.verts = freshArray<float>(3 * n);
  a.values = freshArray<float>(n);
  // values: the larger of the two voxel values of each vertex's grid edge (its surfel's c and
  // d; c alone where d lies outside the array), each converted to float32 first, as numpy's
  // maximum of the two converted arrays (a NaN d gives NaN).
  visitScalarType(view.type, [&](auto zero) {
    using T = decltype(zero);
    const T* data = static_cast<const T*>(view.data);
    auto at = [&](Voxel v) {
      return float(data[v.x * view.strides[0] + v.y * view.strides[1] + v.z * view.strides[2]]);
    };
    inBlocks(arena, n, [&](std::size_t b, std::size_t e) {
      for (std::size_t v = b; v < e; ++v) {
        for (int k = 0; k < 3; ++k) a.verts[3 * v + k] = float(s.vertices[v][k]);
        const Voxel c = s.surfels[v].inside(), d = s.surfels[v].outside();
        const float fc = at(c), fd = view.dims.contains(d) ? at(d) : fc;
        a.values[v] = fc >= fd || std::isnan(fc) ? fc : fd;
      }
    });
  });
  a.normals = freshArray<float>(3 * n);
  if (m > std::numeric_limits<std::uint32_t>::max()) {  // beyond the chunks' uint32 indices: the core's sum
    const std::vector<std::array<double, 3>> normals = vertexNormals(s);
    for (std::size_t v = 0; v < n; ++v)
      for (int k = 0; k < 3; ++k) a.normals[3 * v + k] = float(normals[v][k]);
  } else {
    vertexNormalsInto(s, a.normals.get(), arena);
  }
  // The faces are the scan's array (on huge pages), rewound in place and read as int32 (every
  // index is below 2^31, checked above).
  a.faces = std::make_shared<std::vector<std::array<std::uint32_t, 3>>>(std::move(s.triangles));
  if (descent)
    inBlocks(arena, m, [&](std::size_t b, std::size_t e) {
      for (std::size_t f = b; f < e; ++f) std::swap((*a.faces)[f][0], (*a.faces)[f][2]);
    });
  a.timings = std::move(s.timings);
  a.timings.push_back({"arrays", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()});
  return a;
}

/// (verts, faces, normals, values, timings): the stage times in seconds, as Surface.timings.
py::tuple marchingCubesArray(py::array volume, double level, const std::string& adjacency,
                             std::array<double, 3> spacing, bool descent, int threads) {
  // Engine x, y, z: the array's last, middle, first axes (surftrack/__init__.py, extract()).
  constexpr std::array<int, 3> order = {2, 1, 0};
  const VolumeView view =
      viewOfArray(volume, order, spacing, {0, 0, 0}, {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
  const AdjacencyPair pair = parseAdjacencyPair(adjacency);
  std::atomic<bool> cancel{false};
  Arrays a;
  runEngine(order, cancel, [&] { a = meshArrays(view, level, pair, descent, threads, cancel); });
  const auto n = py::ssize_t(a.vertexCount), m = py::ssize_t(a.faces->size());
  static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::int32_t));
  // (int32 and uint32 may alias each other: the same memory read as the signed type.)
  auto* faces = reinterpret_cast<std::int32_t*>(a.faces->data());
  py::dict timings;
  for (const StageTime& t : a.timings) timings[py::str(t.stage)] = t.seconds;
  return py::make_tuple(arrayOwning(a.verts, {n, 3}), viewOf(faces, {m, 3}, a.faces),
                        arrayOwning(a.normals, {n, 3}), arrayOwning(a.values, {n}), timings);
}

}  // namespace

void defineMarchingCubes(py::module_& m) {
  m.def("marching_cubes_array", &marchingCubesArray, py::arg("volume"), py::arg("level"), py::arg("adjacency"),
        py::arg("spacing"), py::arg("descent"), py::arg("threads"));
}

}  // namespace surftrack::binding
