// The walls of one cube from the nested (26,6) analogs (NestedWalls.h).
#include "NestedWalls.h"

#include <algorithm>
#include <stdexcept>

#include "ConfigurationTable.h"

namespace surftrack {

CubeWalls cubeWalls(const std::array<std::uint8_t, 8>& rank, AdjacencyPair pair) {
  int levels = 0;  // k: the ranks present are 0..k-1
  for (std::uint8_t r : rank) levels = std::max(levels, int(r) + 1);
  // Each distinct triangle (as a set of edges) with the first and last level whose analog has
  // it; checked to be every level in between, with one orientation.
  struct Seen {
    std::array<std::uint8_t, 3> edges, sorted;
    int first, last;
  };
  std::array<Seen, CubeWalls::kMaxTriangles> seen{};
  int n = 0;
  for (int t = 1; t < levels; ++t) {
    std::uint8_t config = 0;  // B_t: the corners of priority >= t
    for (int i = 0; i < 8; ++i)
      if (rank[std::size_t(i)] >= t) config = std::uint8_t(config | 1u << i);
    for (const auto& tri : configurationTable(pair, config).allTriangles()) {
      std::array<std::uint8_t, 3> sorted = tri;
      std::sort(sorted.begin(), sorted.end());
      const auto s = std::find_if(seen.begin(), seen.begin() + n, [&](const Seen& x) { return x.sorted == sorted; });
      if (s == seen.begin() + n) {
        if (n == CubeWalls::kMaxTriangles) throw std::logic_error("cubeWalls: too many triangles");
        seen[std::size_t(n++)] = {tri, sorted, t, t};
        continue;
      }
      // The same orientation: a rotation of the first one met.
      const auto& e = s->edges;
      const bool same = (tri[0] == e[0] && tri[1] == e[1]) || (tri[0] == e[1] && tri[1] == e[2]) ||
                        (tri[0] == e[2] && tri[1] == e[0]);
      if (!same) throw std::logic_error("cubeWalls: a wall changes orientation between levels");
      if (s->last != t - 1) throw std::logic_error("cubeWalls: a wall's levels are not an interval");
      s->last = t;
    }
  }
  CubeWalls out;
  for (int i = 0; i < n; ++i)
    out.triangles[std::size_t(out.count++)] = {seen[std::size_t(i)].edges, std::uint8_t(seen[std::size_t(i)].last),
                                               std::uint8_t(seen[std::size_t(i)].first - 1)};
  return out;
}

}  // namespace surftrack
