// simplifyJunctionLines (JunctionLines.h; docs/theory.md §12, "Decimating the complex").
#include "JunctionLines.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>
#include <span>
#include <tuple>

#include "Cancellation.h"
#include "ProvenDistanceGuard.h"
#include "TriangleCover.h"
#include "TriangleGrid.h"

namespace surftrack::refine {
namespace {

using Tri = DecimatedComplex::Tri;

bool has(const Tri& t, std::uint32_t v) { return t[0] == v || t[1] == v || t[2] == v; }

/// The distance from p to the segment [a, b].
double distanceToSegment(const Point3& p, const Point3& a, const Point3& b) {
  const Point3 ab = sub(b, a), ap = sub(p, a);
  const double l2 = dot(ab, ab);
  const double s = l2 > 0 ? std::clamp(dot(ap, ab) / l2, 0.0, 1.0) : 0.0;
  return norm(sub(ap, {s * ab[0], s * ab[1], s * ab[2]}));
}

class JunctionLines {
 public:
  JunctionLines(DecimatedComplex& c, const DecimationParameters& p) : c_(c), p_(p), at_(c.points.size()) {
    Box3 bounds{{0, 0, 0}, {0, 0, 0}};
    for (std::size_t v = 0; v < c.points.size(); ++v)
      for (int k = 0; k < 3; ++k) {
        bounds.lo[k] = v ? std::min(bounds.lo[k], c.points[v][k]) : c.points[v][k];
        bounds.hi[k] = v ? std::max(bounds.hi[k], c.points[v][k]) : c.points[v][k];
      }
    double edges = 0;
    std::size_t live = 0;
    for (std::uint32_t t = 0; t < c.triangles.size(); ++t) {
      if (c.removed[t]) continue;
      for (std::uint32_t v : c.triangles[t]) at_[v].push_back(t);
      edges += norm(sub(c.points[c.triangles[t][0]], c.points[c.triangles[t][1]]));
      ++live;
    }
    const double edgeLength = live ? edges / double(live) : 1.0;
    grid_.reset(bounds, 2 * edgeLength);
    tolerance_ = 1e-9 * grid_.cell();  // as EmbeddingGuard.h's
    version_.assign(c.triangles.size(), 0);
    mark_.assign(c.triangles.size(), 0);
    for (std::uint32_t t = 0; t < c.triangles.size(); ++t)
      if (!c.removed[t]) grid_.insert(t, 0, boxOf(c.triangleAt(t)));
    if (p.maxError) {
      // The original triangles may reach beyond today's points: the grid covers both.
      for (const Triangle3& t : c.original) {
        const Box3 b = boxOf(t);
        for (int k = 0; k < 3; ++k) {
          bounds.lo[k] = std::min(bounds.lo[k], b.lo[k]);
          bounds.hi[k] = std::max(bounds.hi[k], b.hi[k]);
        }
      }
      originalGrid_.reset(bounds, 2 * std::max(*p.maxError, edgeLength));
      for (std::uint32_t t = 0; t < c.original.size(); ++t) originalGrid_.insert(t, 0, boxOf(c.original[t]));
    }
    stamp_.assign(c.points.size(), 0);
  }

  std::size_t run() {
    for (std::uint32_t v = 0; v < c_.points.size(); ++v) consider(v);
    std::size_t collapses = 0, pops = 0;
    while (!queue_.empty()) {
      const auto [cost, v, stamp] = queue_.top();
      queue_.pop();
      if (stamp != stamp_[v]) continue;
      if (++pops % 1024 == 0) throwIfCancelled(p_.cancel, "decimation");
      std::uint32_t line[2];
      if (!lineNeighbours(v, line) || singularVertex(v, at_[v], c_.triangles, c_.sides)) continue;
      // Condition 5 (JunctionLines.h), for every region at v: each loses two triangles.
      const std::vector<std::uint32_t> regions = regionsOf(at_[v], c_.sides);
      // When balancing, some region at v must be above its target, and every region may lose its
      // two triangles without going below its floor.
      const std::size_t loses = c_.balancing ? 2 : 1;
      if (std::any_of(regions.begin(), regions.end(), [&](std::uint32_t r) { return c_.mayLose(r) < loses; }) ||
          (c_.balancing && std::none_of(regions.begin(), regions.end(), [&](std::uint32_t r) { return c_.aboveTarget(r); })))
        continue;
      // The shorter edge first: its triangles are the smaller ones to lose.
      const Point3& x = c_.points[v];
      if (norm(sub(c_.points[line[1]], x)) < norm(sub(c_.points[line[0]], x))) std::swap(line[0], line[1]);
      for (std::uint32_t u : line)
        if (collapse(v, u)) {
          ++collapses;
          break;
        }
    }
    return collapses;
  }

 private:
  /// v's two neighbours on its junction line, if its edges in three triangles or more are two.
  bool lineNeighbours(std::uint32_t v, std::uint32_t line[2]) {
    neighbourCount_.clear();
    for (std::uint32_t t : at_[v])
      for (std::uint32_t x : c_.triangles[t])
        if (x != v) {
          auto it = std::find_if(neighbourCount_.begin(), neighbourCount_.end(), [&](auto& e) { return e.first == x; });
          if (it == neighbourCount_.end()) neighbourCount_.push_back({x, 1});
          else ++it->second;
        }
    int found = 0;
    for (const auto& [x, count] : neighbourCount_)
      if (count >= 3) {
        if (found == 2) return false;
        line[found++] = x;
      }
    return found == 2;
  }

  /// Queues v if it lies inside a junction line (again, with a new stamp, if it was queued).
  void consider(std::uint32_t v) {
    ++stamp_[v];
    std::uint32_t line[2];
    if (at_[v].empty() || !lineNeighbours(v, line)) return;
    const double cost = distanceToSegment(c_.points[v], c_.points[line[0]], c_.points[line[1]]);
    if (p_.maxError && cost > *p_.maxError) return;
    queue_.push({cost, v, stamp_[v]});
  }

  /// The neighbours of w in the triangles `star` (at w), those of region r alone if r is given.
  void neighbours(std::uint32_t w, const std::vector<std::uint32_t>& star, std::vector<std::uint32_t>& out,
                  const std::uint32_t* region = nullptr) const {
    out.clear();
    for (std::uint32_t t : star) {
      if (region && c_.sides[t][0] != *region && c_.sides[t][1] != *region) continue;
      for (std::uint32_t x : c_.triangles[t])
        if (x != w) out.push_back(x);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  /// Conditions 1 and 2 (JunctionLines.h) for v -> u; `onEdge`: v's triangles on uv.
  bool linkHolds(std::uint32_t v, std::uint32_t u, const std::vector<std::uint32_t>& onEdge) {
    if (singularVertex(u, at_[u], c_.triangles, c_.sides)) return false;
    std::vector<std::uint32_t> nv, nu, link;
    for (std::uint32_t t : onEdge)
      for (std::uint32_t x : c_.triangles[t])
        if (x != u && x != v) link.push_back(x);
    std::sort(link.begin(), link.end());
    link.erase(std::unique(link.begin(), link.end()), link.end());
    neighbours(v, at_[v], nv);
    neighbours(u, at_[u], nu);
    for (std::uint32_t x : nv)
      if (x != u && std::binary_search(nu.begin(), nu.end(), x) && !std::binary_search(link.begin(), link.end(), x))
        return false;
    // No triangle (v, x, y) with a twin (u, x, y): the contraction would fold them together.
    for (std::uint32_t t : at_[v]) {
      if (has(c_.triangles[t], u)) continue;
      for (std::uint32_t s : at_[u]) {
        int common = 0;
        for (std::uint32_t x : c_.triangles[t])
          if (x != v && has(c_.triangles[s], x)) ++common;
        if (common == 2) return false;
      }
    }
    // Every region with both u and v: its own link condition on its closed surface.
    std::vector<std::uint32_t> rv, ru, rl;
    for (std::uint32_t r : regionsOf(at_[v], c_.sides)) {
      neighbours(u, at_[u], ru, &r);
      if (ru.empty()) continue;  // u is not in r: r's disc at v is renamed, nothing joins
      neighbours(v, at_[v], rv, &r);
      rl.clear();
      for (std::uint32_t t : onEdge)
        if (c_.sides[t][0] == r || c_.sides[t][1] == r)
          for (std::uint32_t x : c_.triangles[t])
            if (x != u && x != v) rl.push_back(x);
      std::sort(rl.begin(), rl.end());
      if (rl.size() != 2 || rl[0] == rl[1]) return false;
      std::vector<std::uint32_t> common;
      std::set_intersection(rv.begin(), rv.end(), ru.begin(), ru.end(), std::back_inserter(common));
      if (common != rl) return false;
    }
    return true;
  }

  /// Two triangles (names and points) meet other than in the vertices they share.
  bool meet(const Tri& a, const Triangle3& pa, const Tri& b, const Triangle3& pb) const {
    int shared[3], count = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (a[std::size_t(i)] == b[std::size_t(j)]) shared[count++] = i * 3 + j;
    if (count == 3) return true;
    return trianglesMeetOutsideShared(pa, pb, std::span<const int>(shared, std::size_t(count)), tolerance_);
  }

  /// Offers the original triangles of wall w whose boxes meet `box` (the last one proven near
  /// first).
  template <class Visit>
  void nearOriginal(const Box3& box, std::uint32_t w, Visit&& visit) {
    if (lastHit_ < c_.original.size() && c_.wallOf[lastHit_] == w && visit(lastHit_, c_.original[lastHit_])) return;
    bool stop = false;
    originalGrid_.near(box, [&](std::uint32_t id, std::uint32_t) {
      if (!stop && c_.wallOf[id] == w && boxOf(c_.original[id]).meets(box) && visit(id, c_.original[id])) {
        stop = true;
        lastHit_ = id;
      }
    });
  }

  bool collapse(std::uint32_t v, std::uint32_t u) {
    std::vector<std::uint32_t> onEdge, moved;
    for (std::uint32_t t : at_[v]) (has(c_.triangles[t], u) ? onEdge : moved).push_back(t);
    if (onEdge.size() < 3 || !linkHolds(v, u, onEdge)) return false;
    // Condition 3: the changed triangles.
    std::vector<Tri> names;
    std::vector<Triangle3> created;
    const double cosLimit = std::cos(p_.maxNormalDeviation * std::numbers::pi / 180);
    for (std::uint32_t t : moved) {
      Tri x = c_.triangles[t];
      for (auto& y : x)
        if (y == v) y = u;
      const Triangle3 before = c_.triangleAt(t), after{c_.points[x[0]], c_.points[x[1]], c_.points[x[2]]};
      const Point3 n0 = triangleNormal(before), n1 = triangleNormal(after);
      double longest = 0;
      for (int k = 0; k < 3; ++k) longest = std::max(longest, dot(sub(after[k], after[(k + 1) % 3]), sub(after[k], after[(k + 1) % 3])));
      if (norm(n1) <= 1e-12 * longest) return false;
      if (dot(n0, n1) < cosLimit * norm(n0) * norm(n1)) return false;
      names.push_back(x);
      created.push_back(after);
    }
    for (std::size_t i = 0; i < created.size(); ++i) {
      for (std::size_t j = i + 1; j < created.size(); ++j)
        if (meet(names[i], created[i], names[j], created[j])) return false;
      const Box3 box = boxOf(created[i], tolerance_);
      ++stampOfQuery_;
      bool illegal = false;
      grid_.near(box, [&](std::uint32_t t, std::uint32_t tag) {
        if (illegal || tag != version_[t] || c_.removed[t] || mark_[t] == stampOfQuery_) return;
        mark_[t] = stampOfQuery_;
        if (has(c_.triangles[t], v)) return;  // removed or changed by this collapse
        const Triangle3 other = c_.triangleAt(t);
        if (boxOf(other).meets(box)) illegal = meet(names[i], created[i], c_.triangles[t], other);
      });
      if (illegal) return false;
    }
    // Condition 4: both ways, within each wall, for every point (TriangleCover.h).
    std::vector<std::pair<Triangle3, std::uint32_t>> handOver;  // each piece's triangle after the collapse
    if (p_.maxError) {
      const double e = *p_.maxError;
      for (std::size_t i = 0; i < created.size(); ++i) {
        const std::uint32_t w = c_.wallOf[moved[i]];
        if (!coverTriangle<std::uint32_t>(created[i], e, kDistanceCuts, [&](const Box3& box, auto&& visit) {
              nearOriginal(box, w, visit);
            }))
          return false;
      }
      for (std::uint32_t t : at_[v]) {
        const std::uint32_t w = c_.wallOf[t];
        const auto own = std::find(moved.begin(), moved.end(), t);
        for (const Triangle3& piece : c_.pieces[t])
          if (!coverTriangle<std::uint32_t>(
                  piece, e, kDistanceCuts,
                  [&](const Box3& box, auto&& visit) {
                    if (own != moved.end() && visit(t, created[std::size_t(own - moved.begin())])) return;
                    for (std::size_t i = 0; i < created.size(); ++i)
                      if (c_.wallOf[moved[i]] == w && moved[i] != t && visit(moved[i], created[i])) return;
                    bool stop = false;
                    ++stampOfQuery_;
                    grid_.near(box, [&](std::uint32_t s, std::uint32_t tag) {
                      if (stop || tag != version_[s] || c_.removed[s] || c_.wallOf[s] != w || mark_[s] == stampOfQuery_ ||
                          has(c_.triangles[s], v))
                        return;
                      mark_[s] = stampOfQuery_;
                      stop = visit(s, c_.triangleAt(s));
                    });
                  },
                  &handOver))
            return false;
      }
    }
    // The collapse.
    if (p_.maxError) {
      for (std::uint32_t t : at_[v]) c_.pieces[t].clear();
      for (const auto& [piece, t] : handOver) c_.pieces[t].push_back(piece);
    }
    const std::vector<std::uint32_t> star = at_[v];
    for (std::uint32_t t : onEdge) {
      c_.removed[t] = 1;
      --c_.live[c_.wallOf[t]];
      --c_.regionLive[c_.sides[t][0]];
      --c_.regionLive[c_.sides[t][1]];
      ++version_[t];
      for (std::uint32_t x : c_.triangles[t])
        if (x != v) at_[x].erase(std::find(at_[x].begin(), at_[x].end(), t));
    }
    for (std::size_t i = 0; i < moved.size(); ++i) {
      c_.triangles[moved[i]] = names[i];
      at_[u].push_back(moved[i]);
      grid_.insert(moved[i], ++version_[moved[i]], boxOf(created[i]));
    }
    at_[v].clear();
    consider(v);
    std::vector<std::uint32_t> around;
    for (std::uint32_t t : star)
      for (std::uint32_t x : c_.triangles[t])
        if (x != v) around.push_back(x);
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (std::uint32_t x : around) consider(x);
    return true;
  }

  DecimatedComplex& c_;
  const DecimationParameters& p_;
  std::vector<std::vector<std::uint32_t>> at_;  // each vertex's live triangles
  TriangleGrid grid_, originalGrid_;
  std::vector<std::uint32_t> version_;
  std::vector<std::uint64_t> mark_;
  std::uint64_t stampOfQuery_ = 0;
  double tolerance_ = 0;
  std::uint32_t lastHit_ = std::uint32_t(-1);
  std::vector<std::uint32_t> stamp_;
  std::vector<std::pair<std::uint32_t, int>> neighbourCount_;
  std::priority_queue<std::tuple<double, std::uint32_t, std::uint32_t>,
                      std::vector<std::tuple<double, std::uint32_t, std::uint32_t>>, std::greater<>>
      queue_;
};

}  // namespace

std::size_t simplifyJunctionLines(DecimatedComplex& complex, const DecimationParameters& parameters) {
  if (complex.triangles.empty()) return 0;
  return JunctionLines(complex, parameters).run();
}

}  // namespace surftrack::refine
