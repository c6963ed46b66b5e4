// Every boundary of every label of a label image in one scan of its digital 3-cubes
// (docs/theory.md §11). For a label L the 1-voxels are f = L (paper §3.1), and the
// kappa-lambda-iso-surface of that binary image is the union of its boundaries (§5.1, the
// scanning method): the triangles of each cube's configuration-table entry. A cube whose 8
// corners hold labels L1, L2, ... has one configuration per label (bit i: corner i = Lk), so
// one visit of each cube triangulates all the labels it holds at once: the cost is one pass
// over the volume plus the output, whatever the number of labels, and the triangles are those
// the scanner (ScanIsoSurface.h) gives each label alone.
//
// Vertices are numbered without a hash map of surfels: a plane of voxels is numbered once,
// each voxel of label L taking the next indices of L for its surfels (its faces towards a voxel
// that is not L, in direction order), and a cube finds the surfel of an edge from the numbers
// of its L-corner. Each label's vertices come in the order of the scan (plane, row, voxel,
// direction) and its triangles in the order of the cubes: the same for any number of threads.
//
// Count, prefix sum, fill (as ScanIsoSurface.cpp does, after OpenVDB's VolumeToMesh): slabs of
// planes run in parallel twice. The count pass finds each slab's labels and counts each label's
// voxels, surfels and triangles in it; the prefix sums over the slabs give where each slab's
// part of each label's mesh starts; the fill pass numbers every surfel with its final index,
// writes it and its point (a boundary mapping, §3.1) and every triangle straight into the
// arrays the caller allocated from the counts. A slab's last cubes reach the first plane of the
// next slab, which it numbers from that slab's starts.
//
// A block of a larger volume (docs/theory.md, "Label maps by blocks") is scanned the same way,
// over the cubes it owns only (ScanOwnership): its image is the block's box with a one-voxel
// apron on the high sides, its surfels are written as keys in the volume's coordinates, and
// the border of its box never acts as the domain's border, because no owned cube reads a voxel
// beyond the box that lies in the domain.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "AdjacencyPair.h"
#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "Image.h"
#include "Surfel.h"

namespace surftrack {

/// What the count pass of a label scan finds: the labels wanted that occur, increasing, and
/// for each its voxels, its surfels (the vertices of its mesh) and its triangles.
template <class T>
struct LabelCounts {
  std::vector<T> labels;
  std::vector<std::uint64_t> voxels, surfels, triangles;
};

/// Where the fill pass writes one label's mesh, arrays of the counted sizes: vertex v is the
/// surfel surfels[v], placed at points[v]; triangles as vertex indices, oriented so that the
/// normal (right-hand rule) points from L to the other voxels (as TriangleMesh's). A block scan
/// gives `keys` instead of surfels and points: vertex v is the surfel of key keys[v]
/// (Surfel::key, in the volume's coordinates).
struct LabelMeshArrays {
  Surfel* surfels = nullptr;
  std::array<double, 3>* points = nullptr;
  std::array<std::uint32_t, 3>* triangles = nullptr;
  std::uint64_t* keys = nullptr;
};

/// The cubes a scan owns and where its image lies (docs/theory.md, "Label maps by blocks"), in
/// the image's coordinates: the cubes whose min corner m has m_a in [lo_a, hi_a) on every axis,
/// lo_a = -1 on an axis whose low face is the domain's (the cubes over it, which only the block
/// at the domain's low face owns), and the voxels in [max(lo_a, 0), hi_a), which it counts.
/// Every corner of an owned cube must lie in the image or outside the volume: hi_a < n_a, or
/// hi_a = n_a where the image ends at the volume's high face. `origin`: the image's voxel
/// (0, 0, 0) in the volume, added to the surfels' keys.
struct ScanOwnership {
  std::array<int, 3> lo{-1, -1, -1}, hi{};
  Voxel origin{};

  /// A whole image: every cube of the scanning method (paper §5.1), min corners in [-1, n).
  static ScanOwnership whole(const Dims& dims) { return {{-1, -1, -1}, {dims.nx, dims.ny, dims.nz}, {}}; }
};

namespace scanlabels {

inline constexpr std::uint32_t kNone = ~std::uint32_t(0);  ///< background, unwanted, outside

/// A configuration's triangles over its distinct vertices: each vertex as the L-corner c of
/// its cube edge (bits 0-2) and the directions of that corner's surfels numbered before it
/// (bits 3-8: those below the edge's direction), so that a vertex is first + popcount(directions
/// & mask) of its corner; each triangle as three indices into the vertices.
struct Config {
  int triangles = 0, vertices = 0;
  std::array<std::uint16_t, 12> vertex{};
  std::array<std::array<std::uint8_t, 3>, CubeTriangulation::kMaxTriangles> triangle{};
};

inline std::array<Config, 256> configTable(AdjacencyPair pair) {
  std::array<Config, 256> out;
  for (int config = 0; config < 256; ++config) {
    const CubeTriangulation& t = configurationTable(pair, std::uint8_t(config));
    Config& c = out[config];
    c.triangles = t.triangleCount;
    std::array<int, 12> indexOfEdge;
    indexOfEdge.fill(-1);
    for (int i = 0; i < t.triangleCount; ++i)
      for (int j = 0; j < 3; ++j) {
        const int edge = t.triangles[i][j];
        if (indexOfEdge[edge] < 0) {
          const int low = cube::edgeLowCorner(edge), high = cube::edgeHighCorner(edge);
          const bool lowIsL = config >> low & 1;
          const int n = directionOf(cube::edgeAxis(edge), lowIsL ? +1 : -1);
          indexOfEdge[edge] = c.vertices;
          c.vertex[std::size_t(c.vertices++)] = std::uint16_t((lowIsL ? low : high) | ((1u << n) - 1) << 3);
        }
        c.triangle[i][j] = std::uint8_t(indexOfEdge[edge]);
      }
  }
  return out;
}

/// One slab of planes [z0, z1): its cubes are those with min corner z in [z0, z1) (and -1 for
/// the first slab when the scan owns the cubes below the domain), its surfels those of the
/// planes [z0, planesEnd): z1, or for a block's last slab also the apron plane z1 its cubes
/// reach, which no next slab numbers. The count pass fills the label map and the counts; the
/// fill pass reads the map (then holding global label indices) and the starts.
template <class T>
struct Slab {
  int z0 = 0, z1 = 0, planesEnd = 0;
  bool first = false;
  /// Each value met (on the planes the slab reads) -> its local index (count pass) or its
  /// global index (fill pass); kNone for the background and unwanted values.
  std::unordered_map<T, std::uint32_t> indexOf;
  std::vector<T> labels;  ///< local index -> value
  std::vector<std::uint64_t> voxels, surfels, triangles;  ///< per local index, on its own planes / cubes
  /// Fill pass, per global index: the first vertex of this slab's planes and of the next slab's
  /// first plane, and the first triangle of this slab's cubes.
  std::vector<std::uint32_t> surfelStart, nextSurfelStart;
  std::vector<std::uint64_t> triangleStart;
};

/// f(i) for every i in [0, n) with bytes[i] != 0, in order, eight zero bytes at a time skipped.
template <class F>
inline void forEachNonZero(const std::uint8_t* bytes, int n, F&& f) {
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + i, 8);
    while (word) {
      const int byte = std::countr_zero(word) >> 3;
      f(i + byte);
      word &= ~(std::uint64_t(0xFF) << (8 * byte));
    }
  }
  for (; i < n; ++i)
    if (bytes[i]) f(i);
}

/// The end of a run of `value` in a contiguous row of n values, from x on: the first i >= x
/// with row[i] != value, or n; 16 bytes at a time.
template <class T>
inline int runEnd(const T* row, int x, int n, T value) {
#if defined(__SSE2__)
  constexpr int kLanes = int(16 / sizeof(T));
  T lanes[kLanes];
  std::fill(lanes, lanes + kLanes, value);
  const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(lanes));
  for (; x + kLanes <= n; x += kLanes) {
    const __m128i r = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + x));
    const auto same = unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(r, v)));  // bit b: byte b equal
    if (same != 0xFFFFu) return x + std::countr_zero(~same) / int(sizeof(T));
  }
#endif
  while (x < n && row[x] == value) ++x;
  return x;
}

/// dirs[x] for x in [0, nx): the surfel directions of voxel x of a row (bit n: its neighbour
/// along direction n holds another label; n = 2 axis + (sign < 0): +x, -x, +y, -y, +z, -z),
/// 0 for a voxel of no label. `here`, `above`, `below`: the row in its plane and in the planes
/// z + 1 and z - 1, rows w apart. Without a branch (the compiler vectorises it).
inline void rowDirections(const std::uint32_t* __restrict here, const std::uint32_t* __restrict above,
                          const std::uint32_t* __restrict below, std::size_t w, int nx,
                          std::uint8_t* __restrict dirs) {
  for (int x = 0; x < nx; ++x) {
    const std::uint32_t L = here[x];
    const unsigned mask = unsigned(here[x + 1] != L) | unsigned(here[x - 1] != L) << 1 |
                          unsigned(here[x + w] != L) << 2 | unsigned(here[x - w] != L) << 3 |
                          unsigned(above[x] != L) << 4 | unsigned(below[x] != L) << 5;
    dirs[x] = std::uint8_t(L == kNone ? 0u : mask);
  }
}

/// mixed[i] for i in [0, w - 1): whether the cube between columns i and i + 1 of two rows of
/// plane lo (w apart) and the same rows of plane hi holds two labels (or a label and none):
/// its corner column i or i + 1 does, or the two columns differ. Without a branch (vectorised).
inline void rowMixed(const std::uint32_t* __restrict lo, const std::uint32_t* __restrict hi, std::size_t w,
                     std::uint8_t* __restrict mixed) {
  for (std::size_t i = 0; i < w; ++i) {
    const std::uint32_t a = lo[i];
    mixed[i] = std::uint8_t((a != lo[i + w]) | (a != hi[i]) | (a != hi[i + w]));
  }
  for (std::size_t i = 0; i + 1 < w; ++i) mixed[i] = std::uint8_t(mixed[i] | mixed[i + 1] | (lo[i] != lo[i + 1]));
}

/// f(L, config) for each label L (not kNone) on the corners of the cube at index p of two
/// planes `lo` and `hi` (corner i: plane bit 2, row bit 1, column bit 0; rows w apart), in the
/// order of their first corner; config: bit i set where corner i holds L.
template <class F>
inline void forEachCubeLabel(const std::uint32_t* lo, const std::uint32_t* hi, std::size_t p, std::size_t w, F&& f) {
#if defined(__SSE2__)
  const __m128i low = _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(lo + p)),
                                         _mm_loadl_epi64(reinterpret_cast<const __m128i*>(lo + p + w)));
  const __m128i high = _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(hi + p)),
                                          _mm_loadl_epi64(reinterpret_cast<const __m128i*>(hi + p + w)));
  auto holding = [&](std::uint32_t L) {
    const __m128i v = _mm_set1_epi32(int(L));
    return unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(low, v)))) |
           unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(high, v)))) << 4;
  };
  std::uint32_t corner[8];
  _mm_storeu_si128(reinterpret_cast<__m128i*>(corner), low);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(corner + 4), high);
  for (unsigned todo = ~holding(kNone) & 0xFFu; todo;) {
    const std::uint32_t L = corner[std::countr_zero(todo)];
    const unsigned config = holding(L);
    todo &= ~config;
    f(L, config);
  }
#else
  const std::uint32_t corner[8] = {lo[p], lo[p + 1], lo[p + w], lo[p + w + 1],
                                   hi[p], hi[p + 1], hi[p + w], hi[p + w + 1]};
  unsigned done = 0;
  for (int i = 0; i < 8; ++i) {
    const std::uint32_t L = corner[i];
    if (L == kNone || (done >> i & 1)) continue;
    unsigned config = 0;
    for (int j = i; j < 8; ++j) config |= unsigned(corner[j] == L) << j;
    done |= config;
    f(L, config);
  }
#endif
}

/// One pass over one slab (kFill: the fill pass, else the count pass). Per-voxel planes: labels
/// of the planes around the one being numbered (a ring of four), and for the two planes of the
/// current cubes the first surfel number of each voxel and its surfel directions (bit n: a
/// surfel of normal n).
template <class T, class Wanted, bool kFill, class Mapping = void*>
class SlabScanner {
 public:
  SlabScanner(const VolumeRef<T>& image, T background, const Wanted& wanted, const std::array<Config, 256>& table,
              const ScanOwnership& own, Slab<T>& slab, const std::vector<LabelMeshArrays>* out = nullptr,
              const Mapping* mapping = nullptr)
      : image_(image), background_(background), wanted_(wanted), table_(table), own_(own), slab_(slab), out_(out),
        mapping_(mapping), width_(image.dims.nx + 2),
        plane_(std::size_t(image.dims.nx + 2) * std::size_t(image.dims.ny + 2)) {
    for (auto& p : labelPlanes_) p.assign(plane_, kNone);
    for (int k = 0; k < 2; ++k) {
      if constexpr (kFill) first_[k].assign(plane_, 0);
      directions_[k].assign(plane_, 0);
    }
    if constexpr (kFill) {
      counters_ = slab.surfelStart;
      triangles_.resize(out->size());
      for (std::size_t g = 0; g < out->size(); ++g) triangles_[g] = (*out)[g].triangles + slab.triangleStart[g];
    }
  }

  void run() {
    const int c0 = slab_.first ? -1 : slab_.z0;
    fillLabels(c0 - 1);
    fillLabels(c0);
    fillLabels(c0 + 1);
    numberPlane(c0, 0);
    for (int c = c0; c < slab_.z1; ++c) {
      fillLabels(c + 2);
      numberPlane(c + 1, 1);
      marchPlane(c);
      std::swap(first_[0], first_[1]);
      std::swap(directions_[0], directions_[1]);
    }
  }

 private:
  std::vector<std::uint32_t>& labels(int z) { return labelPlanes_[std::size_t(z + 4) & 3]; }

  /// The index of a value: a new local index in the count pass, the global one of the count
  /// pass's merge in the fill pass (which reads the same planes).
  std::uint32_t labelIndex(T value) {
    if (value == background_) return kNone;
    if (hasLast_ && value == lastValue_) return lastIndex_;
    std::uint32_t index;
    if constexpr (kFill) {
      const auto it = slab_.indexOf.find(value);
      if (it == slab_.indexOf.end()) throw std::logic_error("the fill pass met a value the count pass did not");
      index = it->second;
    } else {
      auto [it, added] = slab_.indexOf.try_emplace(value, kNone);
      if (added && wanted_(value)) {
        it->second = std::uint32_t(slab_.labels.size());
        slab_.labels.push_back(value);
        slab_.voxels.push_back(0);
        slab_.surfels.push_back(0);
        slab_.triangles.push_back(0);
      }
      index = it->second;
    }
    hasLast_ = true;
    lastValue_ = value;
    lastIndex_ = index;
    return index;
  }

  /// The label indices of plane z (kNone outside the domain), by runs of equal values.
  void fillLabels(int z) {
    std::vector<std::uint32_t>& plane = labels(z);
    const Dims& dims = image_.dims;
    if (z < 0 || z >= dims.nz) {
      std::fill(plane.begin(), plane.end(), kNone);
      return;
    }
    const bool owned = z >= slab_.z0 && z < slab_.z1;
    const int x0 = std::max(own_.lo[0], 0), x1 = own_.hi[0];  // the voxels counted: the owned ones
    for (int y = 0; y < dims.ny; ++y) {
      const bool rowOwned = owned && y >= std::max(own_.lo[1], 0) && y < own_.hi[1];
      const T* row = &image_.at(0, y, z);
      const std::ptrdiff_t sx = image_.sx;
      std::uint32_t* out = plane.data() + std::size_t(y + 1) * width_ + 1;
      int x = 0;
      while (x < dims.nx) {
        const T value = row[x * sx];
        const int start = x;
        if (sx == 1) {
          x = runEnd(row, x + 1, dims.nx, value);
        } else {
          while (++x < dims.nx && row[x * sx] == value) {
          }
        }
        const std::uint32_t L = labelIndex(value);
        std::fill(out + start, out + x, L);
        if constexpr (!kFill)
          if (rowOwned && L != kNone && std::min(x, x1) > std::max(start, x0))
            slab_.voxels[L] += std::uint64_t(std::min(x, x1) - std::max(start, x0));
      }
    }
  }

  /// The surfels of plane z: their directions into directions_[k]; the count pass counts
  /// those of its own planes, the fill pass numbers them into first_[k] (from the slab's starts
  /// on its own planes, from the next slab's on the next slab's first plane) and writes those
  /// of its own planes with their points.
  void numberPlane(int z, int k) {
    const Dims& dims = image_.dims;
    if (z < 0 || z >= dims.nz) return;  // no voxel of any label: never read
    const bool owned = z < slab_.planesEnd;
    if (!kFill && !owned) return;  // the count pass needs no surfel of the next slab
    std::uint32_t* first = first_[k].data();
    std::uint8_t* dirs = directions_[k].data();
    if (kFill && !owned) nextCounters_ = slab_.nextSurfelStart;
    const std::uint32_t* below = labels(z - 1).data();
    const std::uint32_t* here = labels(z).data();
    const std::uint32_t* above = labels(z + 1).data();
    const std::size_t w = width_;
    for (int y = 0; y < dims.ny; ++y) {
      const std::size_t rowStart = std::size_t(y + 1) * w + 1;
      rowDirections(here + rowStart, above + rowStart, below + rowStart, w, dims.nx, dirs + rowStart);
      if constexpr (!kFill) {
        forEachNonZero(dirs + rowStart, dims.nx, [&](int x) {
          const std::size_t i = rowStart + std::size_t(x);
          slab_.surfels[here[i]] += std::uint64_t(std::popcount(unsigned(dirs[i])));
        });
      } else {
        std::uint32_t* counters = owned ? counters_.data() : nextCounters_.data();
        const Mapping mapping = *mapping_;  // a local copy: the stores below cannot alias it
        forEachNonZero(dirs + rowStart, dims.nx, [&](int x) {
          const std::size_t i = rowStart + std::size_t(x);
          const std::uint32_t L = here[i];
          const unsigned mask = dirs[i];
          std::uint32_t n = counters[L];
          first[i] = n;
          counters[L] = n + std::uint32_t(std::popcount(mask));
          if (owned && (*out_)[L].keys) {  // a block: the keys in the volume
            std::uint64_t* keys = (*out_)[L].keys;
            const Voxel c = Voxel{x, y, z} + own_.origin;
            for (unsigned m = mask; m; m &= m - 1, ++n) keys[n] = Surfel{c, Direction(std::countr_zero(m))}.key();
          } else if (owned) {
            const LabelMeshArrays& to = (*out_)[L];
            __builtin_prefetch(to.surfels + n + 16, 1);
            __builtin_prefetch(to.points + n + 12, 1);
            for (unsigned m = mask; m; m &= m - 1, ++n) {
              const Surfel s{Voxel{x, y, z}, Direction(std::countr_zero(m))};
              to.surfels[n] = s;
              to.points[n] = mapping(s);
            }
          }
        });
      }
    }
  }

  /// The triangles of every owned cube with min corner z (planes z and z + 1: first_[0],
  /// first_[1]): counted, or written.
  void marchPlane(int z) {
    const std::uint32_t* lo = labels(z).data();
    const std::uint32_t* hi = labels(z + 1).data();
    const std::size_t w = width_;
    // Corner i of the cube at index p (x + 1, y + 1): plane bit 2, row bit 1, column bit 0.
    const std::size_t offset[8] = {0, 1, w, w + 1, 0, 1, w, w + 1};
    const std::uint32_t* first[2] = {first_[0].data(), first_[1].data()};
    const std::uint8_t* dirs[2] = {directions_[0].data(), directions_[1].data()};
    mixed_.resize(width_ + 8);
    const int firstColumn = own_.lo[0] + 1;  // column x + 1: the cube of min corner x
    for (int y = own_.lo[1]; y < own_.hi[1]; ++y) {
      const std::size_t rowStart = std::size_t(y + 1) * w;
      std::uint8_t* mixed = mixed_.data();
      rowMixed(lo + rowStart, hi + rowStart, w, mixed);
      forEachNonZero(mixed + firstColumn, own_.hi[0] - own_.lo[0], [&](int i) {
        const std::size_t p = rowStart + std::size_t(firstColumn + i);
        forEachCubeLabel(lo, hi, p, w, [&](std::uint32_t L, unsigned config) {
          const Config& entry = table_[config];
          if constexpr (!kFill) {
            slab_.triangles[L] += std::uint64_t(entry.triangles);
          } else {
            std::uint32_t vertex[12];
            for (int v = 0; v < entry.vertices; ++v) {
              const unsigned code = entry.vertex[std::size_t(v)];
              const unsigned c = code & 7, k = c >> 2;
              const std::size_t at = p + offset[c];
              vertex[v] = first[k][at] + std::uint32_t(std::popcount(unsigned(dirs[k][at]) & (code >> 3)));
            }
            std::array<std::uint32_t, 3>*& to = triangles_[L];
            __builtin_prefetch(to + 24, 1);  // the arrays were zeroed long ago: fetch ahead for writing
            for (int t = 0; t < entry.triangles; ++t) {
              const auto& corners = entry.triangle[std::size_t(t)];
              *to++ = {vertex[corners[0]], vertex[corners[1]], vertex[corners[2]]};
            }
          }
        });
      });
    }
  }

  const VolumeRef<T>& image_;
  T background_;
  const Wanted& wanted_;
  const std::array<Config, 256>& table_;
  const ScanOwnership& own_;
  Slab<T>& slab_;
  const std::vector<LabelMeshArrays>* out_;
  const Mapping* mapping_;
  std::size_t width_, plane_;
  std::array<std::vector<std::uint32_t>, 4> labelPlanes_;
  std::array<std::vector<std::uint32_t>, 2> first_;
  std::array<std::vector<std::uint8_t>, 2> directions_;
  std::vector<std::uint32_t> counters_, nextCounters_;  ///< fill: the next vertex of each label
  std::vector<std::array<std::uint32_t, 3>*> triangles_;  ///< fill: where each label's next triangle goes
  std::vector<std::uint8_t> mixed_;
  bool hasLast_ = false;
  T lastValue_{};
  std::uint32_t lastIndex_ = kNone;
};

}  // namespace scanlabels

/// Every boundary of every label L != background of `image` with wanted(L), on the arena's
/// threads (`parts` slabs of planes): the constructor runs the count pass, fill() the fill
/// pass. The result does not depend on `parts`. With `own`, the triangles of the owned cubes
/// only, and the voxels of the owned ones (a block, ScanOwnership); the surfels counted and
/// numbered are still all those of the image's planes [lo_z, hi_z] it reads, so a block's
/// caller drops those no owned triangle uses.
template <class T, class Wanted>
class LabelSurfaceScan {
 public:
  LabelSurfaceScan(const VolumeRef<T>& image, T background, const Wanted& wanted, AdjacencyPair pair,
                   tbb::task_arena& arena, int parts, const std::optional<ScanOwnership>& own = std::nullopt)
      : image_(image), background_(background), wanted_(wanted), table_(scanlabels::configTable(pair)),
        own_(own ? *own : ScanOwnership::whole(image.dims)), arena_(arena) {
    using namespace scanlabels;
    const Dims& dims = image.dims;
    const int z0 = std::max(own_.lo[2], 0), z1 = own_.hi[2];
    for (int a = 0; a < 3; ++a) {
      const int n = a == 0 ? dims.nx : a == 1 ? dims.ny : dims.nz;
      if (own_.lo[a] < -1 || own_.lo[a] > own_.hi[a] || own_.hi[a] > n)
        throw std::invalid_argument("LabelSurfaceScan: owned cubes beyond the image");
    }
    parts = std::clamp(parts, 1, std::max(1, z1 - z0));
    slabs_.resize(std::size_t(parts));
    for (int k = 0; k < parts; ++k) {
      Slab<T>& s = slabs_[std::size_t(k)];
      s.z0 = z0 + int(std::int64_t(z1 - z0) * k / parts);
      s.z1 = z0 + int(std::int64_t(z1 - z0) * (k + 1) / parts);
      s.planesEnd = k + 1 < parts ? s.z1 : std::min(s.z1 + 1, dims.nz);
      s.first = k == 0 && own_.lo[2] == -1;
    }
    arena_.execute([&] {
      tbb::parallel_for(std::size_t(0), slabs_.size(), [&](std::size_t k) {
        SlabScanner<T, Wanted, false>(image_, background_, wanted_, table_, own_, slabs_[k]).run();
      });
    });
    merge();
  }

  const LabelCounts<T>& counts() const { return counts_; }

  /// Writes every label's mesh into out[i] (arrays of counts().surfels[i] vertices and
  /// counts().triangles[i] triangles), vertex points by mapping(surfel) (any callable
  /// std::array<double, 3>(const Surfel&), BoundaryMapping.h), called from several threads.
  template <class Mapping>
  void fill(const std::vector<LabelMeshArrays>& out, const Mapping& mapping) {
    using namespace scanlabels;
    if (out.size() != counts_.labels.size()) throw std::invalid_argument("LabelSurfaceScan::fill: one array set per label");
    arena_.execute([&] {
      tbb::parallel_for(std::size_t(0), slabs_.size(), [&](std::size_t k) {
        SlabScanner<T, Wanted, true, Mapping>(image_, background_, wanted_, table_, own_, slabs_[k], &out, &mapping)
            .run();
      });
    });
  }

 private:
  /// The labels of all slabs; each slab's map rewritten to global indices; the counts summed
  /// and their prefix sums over the slabs.
  void merge() {
    using namespace scanlabels;
    std::vector<T>& labels = counts_.labels;
    for (const Slab<T>& s : slabs_) labels.insert(labels.end(), s.labels.begin(), s.labels.end());
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
    const std::size_t n = labels.size();
    counts_.voxels.assign(n, 0);
    counts_.surfels.assign(n, 0);
    counts_.triangles.assign(n, 0);
    for (Slab<T>& s : slabs_) {
      // This slab's part of each label starts after those of the slabs before it.
      s.surfelStart.resize(n);
      for (std::size_t g = 0; g < n; ++g) s.surfelStart[g] = std::uint32_t(counts_.surfels[g]);  // checked below
      s.triangleStart = counts_.triangles;
      std::vector<std::uint32_t> global(s.labels.size());
      for (std::size_t i = 0; i < s.labels.size(); ++i) {
        const auto g = std::size_t(std::lower_bound(labels.begin(), labels.end(), s.labels[i]) - labels.begin());
        global[i] = std::uint32_t(g);
        counts_.voxels[g] += s.voxels[i];
        counts_.surfels[g] += s.surfels[i];
        counts_.triangles[g] += s.triangles[i];
        if (counts_.surfels[g] > std::numeric_limits<std::uint32_t>::max())
          throw std::length_error("a label has more than 2^32 - 1 surfels");
      }
      for (auto& [value, index] : s.indexOf)
        if (index != kNone) index = global[index];
    }
    for (std::size_t k = 0; k < slabs_.size(); ++k)
      slabs_[k].nextSurfelStart = k + 1 < slabs_.size() ? slabs_[k + 1].surfelStart : std::vector<std::uint32_t>(n, 0);
    for (Slab<T>& s : slabs_) {
      std::vector<T>().swap(s.labels);
      std::vector<std::uint64_t>().swap(s.voxels);
      std::vector<std::uint64_t>().swap(s.surfels);
      std::vector<std::uint64_t>().swap(s.triangles);
    }
  }

  const VolumeRef<T>& image_;
  T background_;
  const Wanted& wanted_;
  std::array<scanlabels::Config, 256> table_;
  ScanOwnership own_;
  tbb::task_arena& arena_;
  std::vector<scanlabels::Slab<T>> slabs_;
  LabelCounts<T> counts_;
};

}  // namespace surftrack
