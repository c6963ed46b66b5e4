// A uniform grid of triangles' bounding boxes, for the decimation guards (docs/theory.md,
// section 10): every triangle id is listed in each cell its box meets, so the triangles whose
// boxes may meet a query box are found in the cells of that box. Entries are never removed:
// callers tag them and skip the stale ones (LiveTriangleGrid in MeshTriangles.h, which also
// rebuilds the grid when they pile up).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "TriangleIntersection.h"

namespace surftrack::refine {

/// An axis-aligned box [lo, hi].
struct Box3 {
  Point3 lo, hi;
  bool meets(const Box3& o) const {
    return lo[0] <= o.hi[0] && o.lo[0] <= hi[0] && lo[1] <= o.hi[1] && o.lo[1] <= hi[1] && lo[2] <= o.hi[2] &&
           o.lo[2] <= hi[2];
  }
};

/// The bounding box of t, enlarged by `margin` on every side.
inline Box3 boxOf(const Triangle3& t, double margin = 0) {
  Box3 b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = std::min({t[0][k], t[1][k], t[2][k]}) - margin;
    b.hi[k] = std::max({t[0][k], t[1][k], t[2][k]}) + margin;
  }
  return b;
}

/// The grid covers a fixed bounding box (queries beyond it are clipped to it: every triangle
/// entered must lie inside it) with at most about 2^24 cells; each cell holds the head of a
/// list of entries in one pool, so an insertion is a push and a query walks a few short lists.
class TriangleGrid {
 public:
  /// An empty grid of cells of about `cell` over `bounds`.
  void reset(const Box3& bounds, double cell) {
    origin_ = bounds.lo;
    double extent = 0;
    for (int k = 0; k < 3; ++k) extent = std::max(extent, bounds.hi[k] - bounds.lo[k]);
    cell_ = std::max({cell, extent / 255.0, 1e-300});
    for (int k = 0; k < 3; ++k) size_[k] = long(std::floor((bounds.hi[k] - bounds.lo[k]) / cell_)) + 1;
    head_.assign(std::size_t(size_[0] * size_[1] * size_[2]), kEnd);
    entries_.clear();
  }
  double cell() const { return cell_; }
  /// Entries listed, over all cells (with the stale ones).
  std::size_t entries() const { return entries_.size(); }

  /// Lists `id`, with `tag`, in every cell that `box` meets.
  void insert(std::uint32_t id, std::uint32_t tag, const Box3& box) {
    std::array<long, 3> lo, hi;
    range(box, lo, hi);
    for (long z = lo[2]; z <= hi[2]; ++z)
      for (long y = lo[1]; y <= hi[1]; ++y)
        for (long x = lo[0]; x <= hi[0]; ++x) {
          std::uint32_t& h = head_[index(x, y, z)];
          entries_.push_back({id, tag, h});
          h = std::uint32_t(entries_.size() - 1);
        }
  }

  /// Calls visit(id, tag) for every entry of a cell that `box` meets (an id may come several
  /// times).
  template <class Visit>
  void near(const Box3& box, Visit&& visit) const {
    std::array<long, 3> lo, hi;
    range(box, lo, hi);
    for (long z = lo[2]; z <= hi[2]; ++z)
      for (long y = lo[1]; y <= hi[1]; ++y)
        for (long x = lo[0]; x <= hi[0]; ++x)
          for (std::uint32_t e = head_[index(x, y, z)]; e != kEnd; e = entries_[e].next)
            visit(entries_[e].id, entries_[e].tag);
  }

  /// The same, but the entries for which stale(id, tag) holds are unlinked from their cells
  /// instead of visited.
  template <class Stale, class Visit>
  void sweep(const Box3& box, Stale&& stale, Visit&& visit) {
    std::array<long, 3> lo, hi;
    range(box, lo, hi);
    for (long z = lo[2]; z <= hi[2]; ++z)
      for (long y = lo[1]; y <= hi[1]; ++y)
        for (long x = lo[0]; x <= hi[0]; ++x)
          for (std::uint32_t* link = &head_[index(x, y, z)]; *link != kEnd;) {
            Entry& e = entries_[*link];
            if (stale(e.id, e.tag)) {
              *link = e.next;
            } else {
              visit(e.id, e.tag);
              link = &e.next;
            }
          }
  }

 private:
  struct Entry {
    std::uint32_t id, tag, next;
  };
  static constexpr std::uint32_t kEnd = 0xFFFFFFFFu;

  void range(const Box3& b, std::array<long, 3>& lo, std::array<long, 3>& hi) const {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::clamp(long(std::floor((b.lo[k] - origin_[k]) / cell_)), 0L, size_[k] - 1);
      hi[k] = std::clamp(long(std::floor((b.hi[k] - origin_[k]) / cell_)), 0L, size_[k] - 1);
    }
  }
  std::size_t index(long x, long y, long z) const { return std::size_t((z * size_[1] + y) * size_[0] + x); }

  Point3 origin_{0, 0, 0};
  double cell_ = 1;
  std::array<long, 3> size_{1, 1, 1};
  std::vector<std::uint32_t> head_;
  std::vector<Entry> entries_;
};

}  // namespace surftrack::refine
