// A uniform grid of triangles' bounding boxes, for the decimation guards (docs/theory.md,
// section 10): every triangle id is listed in each cell its box meets, so the triangles that
// may come within a distance of a box are found in the cells of the box so enlarged. Ids are
// never removed: callers skip the stale ones (deleted faces, or faces whose box has moved away,
// which costs a test but never misses a triangle that was entered at its current place).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "Hash.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

class TriangleGrid {
 public:
  explicit TriangleGrid(double cell = 1) : cell_(cell) {}

  void clear(double cell) {
    cell_ = cell;
    cells_.clear();
  }

  /// Lists `id` in every cell that t's bounding box meets.
  void insert(std::uint32_t id, const Triangle3& t) {
    forCells(t, 0, [&](std::vector<std::uint32_t>& cell) {
      if (std::find(cell.begin(), cell.end(), id) == cell.end()) cell.push_back(id);
    });
  }

  /// Calls visit(id) for every id listed in a cell that t's box, enlarged by `margin`, meets
  /// (an id may come several times).
  template <class Visit>
  void near(const Triangle3& t, double margin, Visit&& visit) const {
    std::array<long, 3> lo, hi;
    range(t, margin, lo, hi);
    for (long z = lo[2]; z <= hi[2]; ++z)
      for (long y = lo[1]; y <= hi[1]; ++y)
        for (long x = lo[0]; x <= hi[0]; ++x) {
          const auto it = cells_.find(key(x, y, z));
          if (it != cells_.end())
            for (std::uint32_t id : it->second) visit(id);
        }
  }

 private:
  void range(const Triangle3& t, double margin, std::array<long, 3>& lo, std::array<long, 3>& hi) const {
    for (int k = 0; k < 3; ++k) {
      lo[k] = long(std::floor((std::min({t[0][k], t[1][k], t[2][k]}) - margin) / cell_));
      hi[k] = long(std::floor((std::max({t[0][k], t[1][k], t[2][k]}) + margin) / cell_));
    }
  }
  template <class Fn>
  void forCells(const Triangle3& t, double margin, Fn&& fn) {
    std::array<long, 3> lo, hi;
    range(t, margin, lo, hi);
    for (long z = lo[2]; z <= hi[2]; ++z)
      for (long y = lo[1]; y <= hi[1]; ++y)
        for (long x = lo[0]; x <= hi[0]; ++x) fn(cells_[key(x, y, z)]);
  }
  static std::uint64_t key(long x, long y, long z) {
    return mix64((std::uint64_t(x) & 0x1FFFFF) | ((std::uint64_t(y) & 0x1FFFFF) << 21) |
                 ((std::uint64_t(z) & 0x1FFFFF) << 42));
  }

  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

}  // namespace surftrack::refine
