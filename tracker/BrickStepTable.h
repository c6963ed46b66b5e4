// Definition 38 recast as moves between the tracker's surfel slots (BrickSlot.h). A
// beta-neighbour of a surfel
// is then, most of the time, a fixed slot offset inside the same brick; it lies in another
// brick only when the surfel's voxel is on the brick's border on the side the neighbour moves
// to. Both facts are tabulated here from BetaNeighbourTable (itself filled by the reference
// betaNeighbours), so the rule of Definition 38 is still stated once.
#pragma once

#include <array>
#include <cstdint>

#include "AdjacencyPair.h"
#include "BetaNeighbourTable.h"
#include "BrickSlot.h"
#include "Voxel.h"

namespace surftrack {


/// One beta-neighbour as a move from the surfel's slot.
struct BrickStep {
  std::int16_t deltaSlot = 0;  // neighbour's slot minus the surfel's, when in the same brick
  std::uint8_t crossMask = 0;  // the border flags for which the neighbour lies in another brick
  Direction n = 0;             // the neighbour's normal
  std::int8_t dx = 0, dy = 0, dz = 0;  // the neighbour's 1-voxel minus the surfel's

  static BrickStep of(const Surfel& relative, Direction from) {
    BrickStep s;
    const Voxel d = relative.c;
    s.n = relative.n;
    s.dx = std::int8_t(d.x), s.dy = std::int8_t(d.y), s.dz = std::int8_t(d.z);
    s.deltaSlot = std::int16_t((int(relative.n) - int(from)) * brickslot::kVoxels +
                               brickslot::voxelOf(d.x, d.y, d.z));
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0) s.crossMask |= std::uint8_t(1u << (2 * a + (d[a] > 0 ? 1 : 0)));
    return s;
  }
};

class BrickStepTable {
 public:
  struct EdgeSteps {
    std::uint8_t aBit = 0, bBit = 0;  // neighbourhood bits of u+e and u+n+e
    std::array<BrickStep, 4> result{};  // by a | b << 1
  };
  struct CubeSteps {
    std::uint32_t mask = 0, strictOnes = 0, strictZeros = 0;
    std::array<std::array<BrickStep, 2>, 2> links{};  // [0]: of 1-voxels, [1]: of 0-voxels
  };

  explicit BrickStepTable(AdjacencyPair pair) {
    const BetaNeighbourTable beta(pair);
    for (Direction n = 0; n < 6; ++n) {
      for (int k = 0; k < 4; ++k) {
        const auto& rule = beta.edgeRule(n, k);
        EdgeSteps& e = edges_[n][k];
        e.aBit = rule.aBit, e.bBit = rule.bBit;
        for (int ab = 0; ab < 4; ++ab) e.result[ab] = BrickStep::of(rule.result[ab], n);
      }
      for (int q = 0; q < 4; ++q) {
        const auto& rule = beta.cubeRule(n, q);
        CubeSteps& c = cubes_[n][q];
        c.mask = rule.mask;
        c.strictOnes = kappa(pair) == 26 ? rule.strictOnes : kNever;
        c.strictZeros = lambda(pair) == 26 ? rule.strictZeros : kNever;
        for (int w = 0; w < 2; ++w)
          for (int j = 0; j < 2; ++j) c.links[w][j] = BrickStep::of(rule.links[w][j], n);
      }
      computeCandidates(n);
      computeSlicePatterns(n);
    }
  }

  /// Bit q is set when cube q of a surfel with normal n may be a strict 26-configuration of
  /// the pair, given the rule indices a | b << 1 of its 4 edges packed 2 bits each: the 4 of
  /// the cube's 6 other corners that are edge voxels already decide it in almost every case.
  std::uint8_t cubeCandidates(Direction n, int edgePattern) const { return candidates_[n][edgePattern]; }

  /// The rule indices a | b << 1 of the 4 edges of a surfel with normal n, packed 2 bits each,
  /// from its neighbourhood's three 9-bit z-slices: three table look-ups instead of eight bit
  /// extractions at positions that depend on n.
  int edgePattern(Direction n, const std::uint32_t (&slices)[3]) const {
    const auto& t = slicePatterns_[n];
    return t[0][slices[0]] | t[1][slices[1]] | t[2][slices[2]];
  }

  const std::array<EdgeSteps, 4>& edges(Direction n) const { return edges_[n]; }
  const std::array<CubeSteps, 4>& cubes(Direction n) const { return cubes_[n]; }

 private:
  // The strict pattern of a cube when the pair has no such link: no neighbourhood has it (bit
  // 27 lies outside the 27 bits), so the tracker's test never matches.
  static constexpr std::uint32_t kNever = 1u << 27;

  void computeSlicePatterns(Direction n) {
    for (int k = 0; k < 3; ++k)
      for (std::uint32_t v = 0; v < 512; ++v) {
        const std::uint32_t bits = v << (9 * k);
        int pattern = 0;
        for (int e = 0; e < 4; ++e)
          pattern |= int((bits >> edges_[n][e].aBit) & 1u) << (2 * e) |
                     int((bits >> edges_[n][e].bBit) & 1u) << (2 * e + 1);
        slicePatterns_[n][k][v] = std::uint8_t(pattern);
      }
  }

  void computeCandidates(Direction n) {
    std::uint32_t edgeBits = 0;
    for (const EdgeSteps& e : edges_[n]) edgeBits |= 1u << e.aBit | 1u << e.bBit;
    for (int pattern = 0; pattern < 256; ++pattern) {
      std::uint32_t bits = 0;
      for (int k = 0; k < 4; ++k) {
        bits |= std::uint32_t((pattern >> (2 * k)) & 1) << edges_[n][k].aBit;
        bits |= std::uint32_t((pattern >> (2 * k + 1)) & 1) << edges_[n][k].bBit;
      }
      for (int q = 0; q < 4; ++q) {
        const CubeSteps& c = cubes_[n][q];
        const std::uint32_t known = c.mask & edgeBits;
        for (std::uint32_t strict : {c.strictOnes, c.strictZeros})
          if (strict != kNever && (bits & known) == (strict & known))
            candidates_[n][pattern] |= std::uint8_t(1u << q);
      }
    }
  }

  std::array<std::array<std::uint8_t, 256>, 6> candidates_{};
  std::array<std::array<std::array<std::uint8_t, 512>, 3>, 6> slicePatterns_{};
  std::array<std::array<EdgeSteps, 4>, 6> edges_{};
  std::array<std::array<CubeSteps, 4>, 6> cubes_{};
};

}  // namespace surftrack
