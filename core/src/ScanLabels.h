// Every boundary of every label of a label image in one scan of its digital 3-cubes (internal
// to core/; docs/theory.md §11). For a label L the 1-voxels are f = L (paper §3.1), and the
// kappa-lambda-iso-surface of that binary image is the union of its boundaries (§5.1, the
// scanning method): the triangles of each cube's configuration-table entry. A cube whose 8
// corners hold labels L1, L2, ... has one configuration per label (bit i: corner i = Lk), so
// one visit of each cube triangulates all the labels it holds at once: the cost is one pass
// over the volume plus the output, whatever the number of labels, and the triangles are those
// the scanner (converter/ScanIsoSurface.h) gives each label alone.
//
// Vertices are numbered without a hash map of surfels: a plane of voxels is numbered once,
// each voxel of label L taking the next indices of L for its surfels (its faces towards a voxel
// that is not L, in direction order), and a cube finds the surfel of an edge from the numbers
// of its L-corner. Slabs of planes run in parallel, each numbering its own planes from 0 per
// label; a slab's last cubes reach the first plane of the next slab, whose numbers it computes
// the same way and marks (kNextSlab) so that the merge adds the next slab's offset. Each
// label's vertices come in the order of the scan (plane, row, voxel, direction) and its
// triangles in the order of the cubes: the same for any number of threads.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "AdjacencyPair.h"
#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "Image.h"
#include "Surfel.h"
#include "TriangleMesh.h"

namespace surftrack {

/// What one scan of a label image gives: the labels wanted that occur, their voxel counts and
/// every boundary of each as one mesh (vertices: its surfels).
template <class T>
struct LabelScan {
  std::vector<T> labels;  ///< increasing
  std::vector<std::uint64_t> voxels;
  std::vector<TriangleMesh> meshes;
};

namespace scanlabels {

inline constexpr std::uint32_t kNone = ~std::uint32_t(0);  ///< background, unwanted, outside
inline constexpr std::uint32_t kNextSlab = std::uint32_t(1) << 31;

/// A configuration's triangles, each vertex as the L-corner c of its cube edge (bits 0-2) and
/// the directions of that corner's surfels numbered before it (bits 3-8: those below the edge's
/// direction), so that a vertex is first + popcount(directions & mask) of its corner.
struct Config {
  int triangles = 0;
  std::array<std::array<std::uint16_t, 3>, CubeTriangulation::kMaxTriangles> corners{};
};

inline std::array<Config, 256> configTable(AdjacencyPair pair) {
  std::array<Config, 256> out;
  for (int config = 0; config < 256; ++config) {
    const CubeTriangulation& t = configurationTable(pair, std::uint8_t(config));
    out[config].triangles = t.triangleCount;
    for (int i = 0; i < t.triangleCount; ++i)
      for (int j = 0; j < 3; ++j) {
        const int edge = t.triangles[i][j];
        const int low = cube::edgeLowCorner(edge), high = cube::edgeHighCorner(edge);
        const bool lowIsL = config >> low & 1;
        const int n = directionOf(cube::edgeAxis(edge), lowIsL ? +1 : -1);
        out[config].corners[i][j] = std::uint16_t((lowIsL ? low : high) | ((1u << n) - 1) << 3);
      }
  }
  return out;
}

/// One slab of planes [z0, z1): its labels (local indices), their surfels on its own planes and
/// the triangles of its cubes (min corner z in [z0, z1), and -1 for the first slab).
template <class T>
struct Slab {
  std::vector<T> labels;
  std::vector<std::uint64_t> voxels;
  std::vector<std::vector<Surfel>> surfels;
  std::vector<std::vector<std::array<std::uint32_t, 3>>> triangles;
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

/// The per-voxel planes of a slab: labels of the planes around the one being numbered (a ring
/// of four), and for the two planes of the current cubes the first surfel number of each voxel
/// and its surfel directions (bit n: a surfel of normal n).
template <class T, class Wanted>
class SlabScanner {
 public:
  SlabScanner(const VolumeRef<T>& image, T background, const Wanted& wanted,
              const std::array<Config, 256>& table)
      : image_(image), background_(background), wanted_(wanted), table_(table),
        width_(image.dims.nx + 2), plane_(std::size_t(image.dims.nx + 2) * std::size_t(image.dims.ny + 2)) {
    for (auto& p : labelPlanes_) p.assign(plane_, kNone);
    for (int k = 0; k < 2; ++k) {
      first_[k].assign(plane_, 0);
      directions_[k].assign(plane_, 0);
    }
  }

  Slab<T> run(int z0, int z1, bool firstSlab) {
    z0_ = z0;
    z1_ = z1;
    const int c0 = firstSlab ? -1 : z0;
    fillLabels(c0 - 1);
    fillLabels(c0);
    fillLabels(c0 + 1);
    numberPlane(c0, 0);
    for (int c = c0; c < z1; ++c) {
      fillLabels(c + 2);
      numberPlane(c + 1, 1);
      marchPlane(c);
      std::swap(first_[0], first_[1]);
      std::swap(directions_[0], directions_[1]);
    }
    return std::move(out_);
  }

 private:
  std::vector<std::uint32_t>& labels(int z) { return labelPlanes_[std::size_t(z + 4) & 3]; }

  std::uint32_t localLabel(T value) {
    if (value == background_) return kNone;
    if (hasLast_ && value == lastValue_) return lastIndex_;
    auto [it, added] = indexOf_.try_emplace(value, kNone);
    if (added && wanted_(value)) {
      it->second = std::uint32_t(out_.labels.size());
      out_.labels.push_back(value);
      out_.voxels.push_back(0);
      out_.surfels.emplace_back();
      out_.triangles.emplace_back();
      counters_.push_back(0);
      nextCounters_.push_back(0);
    }
    hasLast_ = true;
    lastValue_ = value;
    lastIndex_ = it->second;
    return it->second;
  }

  /// The local labels of plane z (kNone outside the domain), by runs of equal values.
  void fillLabels(int z) {
    std::vector<std::uint32_t>& plane = labels(z);
    const Dims& dims = image_.dims;
    if (z < 0 || z >= dims.nz) {
      std::fill(plane.begin(), plane.end(), kNone);
      return;
    }
    const bool owned = z >= z0_ && z < z1_;
    for (int y = 0; y < dims.ny; ++y) {
      const T* row = &image_.at(0, y, z);
      const std::ptrdiff_t sx = image_.sx;
      std::uint32_t* out = plane.data() + std::size_t(y + 1) * width_ + 1;
      int x = 0;
      while (x < dims.nx) {
        const T value = row[x * sx];
        const int start = x;
        while (++x < dims.nx && row[x * sx] == value) {
        }
        const std::uint32_t L = localLabel(value);
        std::fill(out + start, out + x, L);
        if (owned && L != kNone) out_.voxels[L] += std::uint64_t(x - start);
      }
    }
  }

  /// Numbers the surfels of plane z into first_[k], directions_[k]: its own plane (surfels
  /// written) or the next slab's first plane (numbers marked kNextSlab, nothing written).
  void numberPlane(int z, int k) {
    std::uint32_t* first = first_[k].data();
    std::uint8_t* dirs = directions_[k].data();
    const Dims& dims = image_.dims;
    if (z < 0 || z >= dims.nz) return;  // no voxel of any label: never read
    const bool owned = z < z1_;
    std::vector<std::uint32_t>& counters = owned ? counters_ : nextCounters_;
    if (!owned) std::fill(nextCounters_.begin(), nextCounters_.end(), 0);
    const std::uint32_t* below = labels(z - 1).data();
    const std::uint32_t* here = labels(z).data();
    const std::uint32_t* above = labels(z + 1).data();
    const std::size_t w = width_;
    for (int y = 0; y < dims.ny; ++y) {
      const std::size_t rowStart = std::size_t(y + 1) * w + 1;
      // The directions of every voxel of the row first, without a branch (the compiler
      // vectorises it); direction n = 2 axis + (sign < 0): +x, -x, +y, -y, +z, -z.
      for (int x = 0; x < dims.nx; ++x) {
        const std::size_t i = rowStart + std::size_t(x);
        const std::uint32_t L = here[i];
        const unsigned mask = unsigned(here[i + 1] != L) | unsigned(here[i - 1] != L) << 1 |
                              unsigned(here[i + w] != L) << 2 | unsigned(here[i - w] != L) << 3 |
                              unsigned(above[i] != L) << 4 | unsigned(below[i] != L) << 5;
        dirs[i] = std::uint8_t(L == kNone ? 0u : mask);
      }
      forEachNonZero(dirs + rowStart, dims.nx, [&](int x) {
        const std::size_t i = rowStart + std::size_t(x);
        const std::uint32_t L = here[i];
        const unsigned mask = dirs[i];
        const std::uint32_t n = counters[L];
        first[i] = owned ? n : n | kNextSlab;
        counters[L] = n + std::uint32_t(std::popcount(mask));
        if (counters[L] >= kNextSlab) throw std::length_error("a label has 2^31 or more surfels in one slab");
        if (owned) {
          std::vector<Surfel>& surfels = out_.surfels[L];
          for (unsigned m = mask; m; m &= m - 1)
            surfels.push_back(Surfel{Voxel{x, y, z}, Direction(std::countr_zero(m))});
        }
      });
    }
  }

  /// The triangles of every cube with min corner z: planes z (first_[0]) and z + 1 (first_[1]).
  void marchPlane(int z) {
    const std::uint32_t* lo = labels(z).data();
    const std::uint32_t* hi = labels(z + 1).data();
    const std::size_t w = width_;
    // Corner i of the cube at index p (x + 1, y + 1): plane bit 2, row bit 1, column bit 0.
    const std::size_t offset[8] = {0, 1, w, w + 1, 0, 1, w, w + 1};
    const Dims& dims = image_.dims;
    mixed_.resize(width_ + 8);
    for (int y = -1; y < dims.ny; ++y) {
      const std::size_t rowStart = std::size_t(y + 1) * w;
      // Cube x + 1 of the row holds two labels (or a label and none) when its corner column x
      // or x + 1 does, or the two columns differ; without a branch first (vectorised).
      std::uint8_t* mixed = mixed_.data();
      for (std::size_t i = 0; i < w; ++i) {
        const std::uint32_t a = lo[rowStart + i];
        mixed[i] = std::uint8_t((a != lo[rowStart + i + w]) | (a != hi[rowStart + i]) | (a != hi[rowStart + i + w]));
      }
      for (std::size_t i = 0; i + 1 < w; ++i)
        mixed[i] = std::uint8_t(mixed[i] | mixed[i + 1] | (lo[rowStart + i] != lo[rowStart + i + 1]));
      forEachNonZero(mixed, int(w) - 1, [&](int column) {
        const std::size_t p = rowStart + std::size_t(column);
        std::uint32_t corner[8];
        for (int i = 0; i < 8; ++i) corner[i] = (i < 4 ? lo : hi)[p + offset[i]];
        unsigned done = 0;
        for (int i = 0; i < 8; ++i) {
          const std::uint32_t L = corner[i];
          if (L == kNone || (done >> i & 1)) continue;
          unsigned config = 0;
          for (int j = i; j < 8; ++j) config |= unsigned(corner[j] == L) << j;
          done |= config;
          const Config& entry = table_[config];
          auto vertex = [&](std::uint8_t corner) {
            const int c = corner & 7, k = c >> 2;
            const std::size_t at = p + offset[c];
            return first_[k][at] + std::uint32_t(std::popcount(unsigned(directions_[k][at] & (corner >> 3))));
          };
          auto& triangles = out_.triangles[L];
          for (int t = 0; t < entry.triangles; ++t)
            triangles.push_back({vertex(entry.corners[t][0]), vertex(entry.corners[t][1]), vertex(entry.corners[t][2])});
        }
      });
    }
  }

  const VolumeRef<T>& image_;
  T background_;
  const Wanted& wanted_;
  const std::array<Config, 256>& table_;
  std::size_t width_, plane_;
  int z0_ = 0, z1_ = 0;
  std::array<std::vector<std::uint32_t>, 4> labelPlanes_;
  std::array<std::vector<std::uint32_t>, 2> first_;
  std::array<std::vector<std::uint8_t>, 2> directions_;
  std::vector<std::uint32_t> counters_, nextCounters_;
  std::vector<std::uint8_t> mixed_;
  std::unordered_map<T, std::uint32_t> indexOf_;
  bool hasLast_ = false;
  T lastValue_{};
  std::uint32_t lastIndex_ = kNone;
  Slab<T> out_;
};

}  // namespace scanlabels

/// Every boundary of every label L != background of `image` with wanted(L), on the arena's
/// threads (`parts` slabs of planes). The result does not depend on `parts`.
template <class T, class Wanted>
LabelScan<T> scanLabelSurfaces(const VolumeRef<T>& image, T background, const Wanted& wanted,
                               AdjacencyPair pair, tbb::task_arena& arena, int parts) {
  using namespace scanlabels;
  const Dims& dims = image.dims;
  const std::array<Config, 256> table = configTable(pair);
  parts = std::clamp(parts, 1, std::max(1, dims.nz));
  const auto slabCount = std::size_t(parts);
  std::vector<Slab<T>> slabs(slabCount);
  auto bound = [&](int k) { return int(std::int64_t(dims.nz) * k / parts); };
  arena.execute([&] {
    tbb::parallel_for(0, parts, [&](int k) {
      SlabScanner<T, Wanted> scanner(image, background, wanted, table);
      slabs[std::size_t(k)] = scanner.run(bound(k), bound(k + 1), k == 0);
    });
  });

  // The labels of all slabs, and each slab's local index of each (kNone where it has none).
  LabelScan<T> out;
  for (const Slab<T>& s : slabs) out.labels.insert(out.labels.end(), s.labels.begin(), s.labels.end());
  std::sort(out.labels.begin(), out.labels.end());
  out.labels.erase(std::unique(out.labels.begin(), out.labels.end()), out.labels.end());
  const std::size_t n = out.labels.size();
  std::vector<std::vector<std::uint32_t>> local(slabs.size(), std::vector<std::uint32_t>(n, kNone));
  for (std::size_t k = 0; k < slabs.size(); ++k)
    for (std::size_t i = 0; i < slabs[k].labels.size(); ++i) {
      const auto g = std::size_t(std::lower_bound(out.labels.begin(), out.labels.end(), slabs[k].labels[i]) -
                                 out.labels.begin());
      local[k][g] = std::uint32_t(i);
    }
  out.voxels.assign(n, 0);
  out.meshes.resize(n);
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t g) {
      std::vector<std::size_t> start(slabs.size() + 1, 0);  // first vertex of each slab
      std::size_t triangles = 0;
      for (std::size_t k = 0; k < slabs.size(); ++k) {
        const std::uint32_t i = local[k][g];
        start[k + 1] = start[k] + (i == kNone ? 0 : slabs[k].surfels[i].size());
        if (i != kNone) triangles += slabs[k].triangles[i].size();
      }
      if (start.back() > std::numeric_limits<std::uint32_t>::max())
        throw std::length_error("a label has more than 2^32 - 1 surfels");
      TriangleMesh& mesh = out.meshes[g];
      const auto holders = std::count_if(local.begin(), local.end(), [&](const auto& l) { return l[g] != kNone; });
      if (holders == 1) {  // in one slab only: no number to shift, none in a next slab
        for (std::size_t k = 0; k < slabs.size(); ++k)
          if (const std::uint32_t i = local[k][g]; i != kNone) {
            out.voxels[g] = slabs[k].voxels[i];
            mesh.surfels = std::move(slabs[k].surfels[i]);
            mesh.triangles = std::move(slabs[k].triangles[i]);
          }
        return;
      }
      mesh.surfels.reserve(start.back());
      mesh.triangles.reserve(triangles);
      for (std::size_t k = 0; k < slabs.size(); ++k) {
        const std::uint32_t i = local[k][g];
        if (i == kNone) continue;
        out.voxels[g] += slabs[k].voxels[i];
        std::vector<Surfel>& surfels = slabs[k].surfels[i];
        mesh.surfels.insert(mesh.surfels.end(), surfels.begin(), surfels.end());
        std::vector<Surfel>().swap(surfels);
        const auto own = std::uint32_t(start[k]);
        const auto next = std::uint32_t(start[std::min(k + 1, slabs.size())]);
        std::vector<std::array<std::uint32_t, 3>>& ts = slabs[k].triangles[i];
        const std::uint32_t add[2] = {own, next - kNextSlab};  // modulo 2^32
        const std::size_t at = mesh.triangles.size();
        mesh.triangles.resize(at + ts.size());
        std::array<std::uint32_t, 3>* to = mesh.triangles.data() + at;
        for (std::size_t t = 0; t < ts.size(); ++t)
          for (int j = 0; j < 3; ++j) to[t][j] = ts[t][j] + add[ts[t][j] >> 31];
        std::vector<std::array<std::uint32_t, 3>>().swap(ts);
      }
    });
  });
  return out;
}

}  // namespace surftrack
