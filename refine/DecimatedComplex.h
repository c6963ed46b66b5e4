// A conforming complex under decimation (docs/theory.md §12, "Decimating the complex"), as the
// two kinds of collapse read and change it: inside one wall (ComplexDecimation.cpp) and along a
// junction line (JunctionLines.h). Triangle t lies on the wall between regions sides[t][0] and
// sides[t][1]; a collapse removes triangles (removed[t]) and renames a vertex in others
// (triangles[t]), never moving a point. With a distance bound, every triangle keeps the
// coordinates it had at the start (`original`, the surface each wall is measured against) and
// the pieces of the original wall it answers for (`pieces`, ProvenDistanceGuard.h's, handed on from
// collapse to collapse and from one kind of collapse to the other), so that the bound holds for
// the whole decimation and not for each pass alone.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "TriangleIntersection.h"

namespace surftrack::refine {

struct DecimatedComplex {
  using Tri = std::array<std::uint32_t, 3>;
  const std::vector<Point3>& points;
  std::vector<Tri>& triangles;
  const std::vector<std::array<std::uint32_t, 2>>& sides;
  std::vector<char>& removed;
  std::vector<std::uint32_t> wallOf{};               ///< triangle -> its wall
  std::vector<std::vector<std::uint32_t>> walls{};   ///< wall -> its triangles, removed ones included
  std::vector<std::size_t> live{}, target{};           ///< by wall: triangles left, and the goal
  std::vector<std::size_t> regionLive{}, regionTarget{};  ///< by region: its walls' live and target summed
  std::vector<Triangle3> original{};                 ///< by triangle (with a distance bound)
  std::vector<std::vector<Triangle3>> pieces{};      ///< by live triangle (with a distance bound)

  /// Once the regions' targets are met as far as they go, a region at its target may still give
  /// up to 1/kSlack of it (4 %) to a neighbour above its own, so that both end within 5 % of
  /// theirs (docs/theory.md §12, "Decimating the complex"): then `balancing` is set.
  static constexpr std::size_t kSlack = 25;
  bool balancing = false;

  /// Region r is above a target of its own (the background, with none, never is).
  bool aboveTarget(std::uint32_t r) const { return regionTarget[r] > 0 && regionLive[r] > regionTarget[r]; }

  /// How many more triangles region r may lose: down to its target, or, when balancing and it
  /// is not above its target, down to its floor (the background, with no target, all).
  std::size_t mayLose(std::uint32_t r) const {
    const std::size_t floor =
        balancing && !aboveTarget(r) ? regionTarget[r] - regionTarget[r] / kSlack : regionTarget[r];
    return regionLive[r] > floor ? regionLive[r] - floor : 0;
  }

  Triangle3 triangleAt(std::uint32_t t) const {
    return {points[triangles[t][0]], points[triangles[t][1]], points[triangles[t][2]]};
  }
};

/// The triangles `ts` at vertex v form one closed disc around it: each of their edges at v is
/// in exactly two of them, once each way, and they are joined through those edges.
inline bool closedDisc(std::uint32_t v, const std::vector<std::uint32_t>& ts,
                       const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  if (ts.size() < 3) return false;
  // Each triangle's edge out of v (to `next`) and into v (from `prev`), in its orientation.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> around;  // (prev, next)
  around.reserve(ts.size());
  for (std::uint32_t t : ts) {
    const auto& x = triangles[t];
    const int k = int(std::find(x.begin(), x.end(), v) - x.begin());
    around.push_back({x[std::size_t((k + 2) % 3)], x[std::size_t((k + 1) % 3)]});
  }
  // One disc: following next -> the triangle whose prev it is walks all of them in one cycle.
  std::size_t at = 0, steps = 0;
  std::vector<char> seen(ts.size(), 0);
  do {
    if (seen[at]) return false;
    seen[at] = 1;
    ++steps;
    std::size_t found = ts.size();
    for (std::size_t j = 0; j < ts.size(); ++j)
      if (around[j].first == around[at].second) {
        if (found != ts.size()) return false;  // an edge of more than two
        found = j;
      }
    if (found == ts.size()) return false;  // a border
    at = found;
  } while (at != 0);
  if (steps != ts.size()) return false;
  // No edge in two triangles the same way (then the walk above could still close).
  for (std::size_t i = 0; i < ts.size(); ++i)
    for (std::size_t j = i + 1; j < ts.size(); ++j)
      if (around[i].second == around[j].second || around[i].first == around[j].first) return false;
  return true;
}

/// The regions of the triangles `star` (those at one vertex), sorted, each once.
inline std::vector<std::uint32_t> regionsOf(const std::vector<std::uint32_t>& star,
                                            const std::vector<std::array<std::uint32_t, 2>>& sides) {
  std::vector<std::uint32_t> regions;
  for (std::uint32_t t : star) {
    regions.push_back(sides[t][0]);
    regions.push_back(sides[t][1]);
  }
  std::sort(regions.begin(), regions.end());
  regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
  return regions;
}

/// Some region's triangles among `star` (those at v) are not one closed disc around v: v is a
/// pinch of that region. A triangle is stored as its wall's first region sees it, so the
/// second region's are reversed before they are chained.
inline bool singularVertex(std::uint32_t v, const std::vector<std::uint32_t>& star,
                           const std::vector<std::array<std::uint32_t, 3>>& triangles,
                           const std::vector<std::array<std::uint32_t, 2>>& sides) {
  std::vector<std::array<std::uint32_t, 3>> oriented;
  std::vector<std::uint32_t> ts;
  for (std::uint32_t r : regionsOf(star, sides)) {
    oriented.clear();
    ts.clear();
    for (std::uint32_t t : star)
      if (sides[t][0] == r || sides[t][1] == r) {
        const auto& x = triangles[t];
        ts.push_back(std::uint32_t(oriented.size()));
        oriented.push_back(sides[t][0] == r ? x : std::array<std::uint32_t, 3>{x[0], x[2], x[1]});
      }
    if (!closedDisc(v, ts, oriented)) return true;
  }
  return false;
}

}  // namespace surftrack::refine
