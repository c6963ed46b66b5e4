// Definition 38 as a look-up table over a surfel's 3x3x3 neighbourhood, for the tracker's inner
// loop. The table is filled by running the reference betaNeighbours (lib/BetaAdjacency.h) on
// synthetic neighbourhoods, so there is one statement of the rule; tests check that both agree
// on every neighbourhood pattern.
#pragma once

#include <array>
#include <cstdint>

#include "AdjacencyPair.h"
#include "BetaAdjacency.h"
#include "BinaryBricks.h"

namespace surftrack {

class BetaNeighbourTable {
 public:
  explicit BetaNeighbourTable(AdjacencyPair pair)
      : kappa26_(kappa(pair) == 26), lambda26_(lambda(pair) == 26) {
    const Voxel u{0, 0, 0};
    const int uBit = Neighbourhood::bitOf(u);
    for (Direction n = 0; n < 6; ++n) {
      const Surfel t{u, n};
      const Voxel un = unitVector(n);
      Surfel out[kMaxBetaNeighbours];
      int k = 0;
      for (Direction ed = 0; ed < 6; ++ed) {
        if (axisOf(ed) == axisOf(n)) continue;
        EdgeRule& rule = edges_[n][k];
        rule.aBit = std::uint8_t(Neighbourhood::bitOf(unitVector(ed)));
        rule.bBit = std::uint8_t(Neighbourhood::bitOf(un + unitVector(ed)));
        for (int ab = 0; ab < 4; ++ab) {
          std::uint32_t bits = 1u << uBit;
          if (ab & 1) bits |= 1u << rule.aBit;
          if (ab & 2) bits |= 1u << rule.bBit;
          betaNeighbours(Neighbourhood{u, bits}, t, pair, out);
          rule.result[ab] = out[k];
        }
        ++k;
      }
      // The 4 cubes around t's edge, in the order betaNeighbours visits them.
      const int axis1 = axisOf(n) == 0 ? 1 : 0, axis2 = axisOf(n) == 2 ? 1 : 2;
      for (int q = 0; q < 4; ++q) {
        const Voxel e1 = unitVector(directionOf(axis1, (q & 1) ? -1 : 1));
        const Voxel e2 = unitVector(directionOf(axis2, (q & 2) ? -1 : 1));
        CubeRule& rule = cubes_[n][q];
        const Voxel others[6] = {e1, e2, un + e1, un + e2, e1 + e2, un + e1 + e2};
        for (Voxel v : others) rule.mask |= 1u << Neighbourhood::bitOf(v);
        rule.strictOnes = 1u << Neighbourhood::bitOf(un + e1 + e2);
        rule.strictZeros = rule.mask & ~(1u << Neighbourhood::bitOf(e1 + e2));
        if (kappa26_) {
          betaNeighbours(Neighbourhood{u, (1u << uBit) | rule.strictOnes}, t, pair, out);
          rule.links[0] = {out[4], out[5]};
        }
        if (lambda26_) {
          const std::uint32_t all = (1u << 27) - 1;
          const std::uint32_t zeros = (1u << Neighbourhood::bitOf(un)) |
                                      (1u << Neighbourhood::bitOf(e1 + e2));
          betaNeighbours(Neighbourhood{u, all & ~zeros}, t, pair, out);
          rule.links[1] = {out[4], out[5]};
        }
      }
    }
  }

  /// The beta-neighbours of boundary surfel t, given the neighbourhood bits of t's 1-voxel;
  /// the same neighbours, in the same order, as betaNeighbours(image, t, pair, out).
  int neighbours(std::uint32_t bits, const Surfel& t, Surfel* out) const {
    const auto& edges = edges_[t.n];
    for (int k = 0; k < 4; ++k) {
      const EdgeRule& r = edges[k];
      const Surfel& s = r.result[((bits >> r.aBit) & 1u) | (((bits >> r.bBit) & 1u) << 1)];
      out[k] = Surfel{t.c + s.c, s.n};
    }
    int count = 4;
    if (!kappa26_ && !lambda26_) return count;
    for (const CubeRule& r : cubes_[t.n]) {
      const std::uint32_t m = bits & r.mask;
      const int which = (kappa26_ && m == r.strictOnes) ? 0 : (lambda26_ && m == r.strictZeros) ? 1 : -1;
      if (which < 0) continue;
      for (const Surfel& s : r.links[which]) out[count++] = Surfel{t.c + s.c, s.n};
    }
    return count;
  }

  /// The rule across one edge of a surfel with normal n (the table of docs/theory.md, 'The
  /// beta-adjacency').
  struct EdgeRule {
    std::uint8_t aBit = 0, bBit = 0;  // neighbourhood bits of u+e and u+n+e
    std::array<Surfel, 4> result{};   // neighbour relative to u, by a | b << 1
  };
  /// Rule (iv) in one of the 4 cubes around a surfel's edge: its two strict-26 links.
  struct CubeRule {
    std::uint32_t mask = 0;         // the 6 corners other than u and u+n
    std::uint32_t strictOnes = 0;   // strict 26-configuration of 1-voxels
    std::uint32_t strictZeros = 0;  // strict 26-configuration of 0-voxels
    std::array<std::array<Surfel, 2>, 2> links{};  // [0]: of 1-voxels, [1]: of 0-voxels
  };

  /// Edge rule k (by increasing Direction code of e) of a surfel with normal n.
  const EdgeRule& edgeRule(Direction n, int k) const { return edges_[n][k]; }
  /// Cube rule q (the order of betaNeighbours) of a surfel with normal n.
  const CubeRule& cubeRule(Direction n, int q) const { return cubes_[n][q]; }

 private:
  bool kappa26_, lambda26_;
  std::array<std::array<EdgeRule, 4>, 6> edges_{};
  std::array<std::array<CubeRule, 4>, 6> cubes_{};
};

}  // namespace surftrack
