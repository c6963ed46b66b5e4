// Definition 38: degrees and symmetry of the beta-adjacency, and the strict 26-configurations
// (rule (iv)) of 1-voxels and of 0-voxels.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>

#include "CaseSubset.h"
#include "DigitalCube.h"
#include "PairTestName.h"
#include "ScanBoundaries.h"
#include "TrackComponent.h"
#include "VoxelComponents.h"

using namespace surftrack;
using namespace surftrack::testing;

namespace {

// Counted from the cube configuration alone, independently of betaNeighbours.
template <class Image>
int strict26Cubes(const Image& image, const Surfel& s, AdjacencyPair pair) {
  int count = 0;
  for (Voxel m : cube::cubesOf(s)) {
    const std::uint8_t config = cube::configurationAt(image, m);
    const std::uint8_t ones = kappa(pair) == 26 ? config : std::uint8_t(~config);
    if (kappa(pair) != 26 && lambda(pair) != 26) continue;
    if (std::popcount(ones) != 2) continue;
    int i = std::countr_zero(ones), j = 7 - std::countl_zero(ones);
    if ((i ^ j) == 7) ++count;
  }
  return count;
}

class BetaAdjacency : public ::testing::TestWithParam<AdjacencyPair> {};

TEST_P(BetaAdjacency, DegreesAndSymmetryOnRandomImages) {
  const AdjacencyPair pair = GetParam();
  std::mt19937 rng(7);
  for (int i = 0; i < 300; ++i) {
    const BinaryVolume volume =
        randomVolume({8, 7, 6}, std::uniform_real_distribution<double>(0.1, 0.9)(rng), rng());
    const auto image = binaryView(volume);
    for (const Surfel& s : allBoundarySurfels(image)) {
      Surfel nb[kMaxBetaNeighbours];
      const int k = betaNeighbours(image, s, pair, nb);
      ASSERT_EQ(k, 4 + 2 * strict26Cubes(image, s, pair)) << s;
      for (int j = 0; j < k; ++j) {
        ASSERT_TRUE(isBoundarySurfel(image, nb[j])) << s << " -> " << nb[j];
        ASSERT_EQ(std::count(nb, nb + k, nb[j]), 1) << "repeated neighbour of " << s;
        Surfel back[kMaxBetaNeighbours];
        const int kb = betaNeighbours(image, nb[j], pair, back);
        ASSERT_EQ(std::count(back, back + kb, s), 1) << "asymmetric arc " << s << " " << nb[j];
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllPairs, BetaAdjacency, ::testing::ValuesIn(kAllAdjacencyPairs),
                         surftrack::testing::pairTestName);

std::size_t componentCount(const BinaryVolume& volume, AdjacencyPair pair) {
  return scanBoundaries(binaryView(volume), pair).componentCount;
}

TEST(Strict26, TwoDiagonalOneVoxelsAreOneBoundaryOnlyFor26) {
  BinaryVolume volume({2, 2, 2});
  volume.at(0, 0, 0) = volume.at(1, 1, 1) = 1;
  const auto image = binaryView(volume);
  const SurfaceGraph g = trackComponent(image, Surfel{{0, 0, 0}, 0}, AdjacencyPair::k26_6);
  EXPECT_EQ(g.surfelCount(), 12u);
  // The three surfels of each voxel inside the cube gain two vertex links each.
  EXPECT_EQ(g.arcCount(), (12 * 4 + 6 * 2) / 2);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k26_6), 1u);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k18_6), 2u);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k6_18), 2u);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k6_26), 2u);
}

TEST(Strict26, TwoDiagonalZeroVoxelsAreOneBoundaryOnlyFor26) {
  BinaryVolume volume({4, 4, 4}, 1);
  volume.at(1, 1, 1) = volume.at(2, 2, 2) = 0;
  const auto image = binaryView(volume);
  const SurfaceGraph g = trackComponent(image, Surfel{{0, 1, 1}, 0}, AdjacencyPair::k6_26);
  EXPECT_EQ(g.surfelCount(), 12u);
  EXPECT_EQ(g.arcCount(), (12 * 4 + 6 * 2) / 2);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k6_26), 2u);  // the two holes + the outside
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k6_18), 3u);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k26_6), 3u);
  EXPECT_EQ(componentCount(volume, AdjacencyPair::k18_6), 3u);
}

TEST(Strict26, NonStrictDiagonalGetsNoVertexLinks) {
  // A third 1-voxel in the cube makes the diagonal 18-connected: no rule (iv) arcs.
  BinaryVolume volume({2, 2, 2});
  volume.at(0, 0, 0) = volume.at(1, 1, 1) = volume.at(1, 0, 0) = 1;
  const auto image = binaryView(volume);
  for (const Surfel& s : allBoundarySurfels(image)) {
    Surfel nb[kMaxBetaNeighbours];
    EXPECT_EQ(betaNeighbours(image, s, AdjacencyPair::k26_6, nb), 4) << s;
  }
}

TEST(EdgeRule, Kappa6TurnsInwardWhereKappa18TurnsOutward) {
  // Two 1-voxels sharing only an edge: a = I(u+e) = 0, b = I(u+n+e) = 1 for the surfel between
  // them (docs/theory.md, 'The beta-adjacency', the case a = 0, b = 1 of the edge rule).
  BinaryVolume volume({2, 2, 1});
  volume.at(0, 0, 0) = volume.at(1, 1, 0) = 1;
  const auto image = binaryView(volume);
  const Surfel t{{0, 0, 0}, 2};  // normal +y, towards (0,1,0)
  Surfel nb[kMaxBetaNeighbours];
  betaNeighbours(image, t, AdjacencyPair::k18_6, nb);
  EXPECT_EQ(nb[0], (Surfel{{1, 1, 0}, 1}));  // (ii): same 0-voxel (0,1,0), turns outward
  betaNeighbours(image, t, AdjacencyPair::k6_18, nb);
  EXPECT_EQ(nb[0], (Surfel{{0, 0, 0}, 0}));  // (i): same 1-voxel, turns inward
}

}  // namespace

#include "BetaNeighbourTable.h"

namespace {

/// Every neighbourhood (Neighbourhood::bits around u = (0,0,0)) of a surfel with normal n that
/// Definition 38 can tell apart: u = 1, u + n = 0, and all 2^16 patterns of the other voxels of
/// the 3x3x2 slab spanned by u and u + n.
std::vector<std::uint32_t> neighbourhoodsOfASurfel(Direction n) {
  const Voxel u{0, 0, 0}, un = unitVector(n);
  std::vector<int> relevant;
  for (int b = 0; b < 27; ++b) {
    const Voxel d{b % 3 - 1, (b / 3) % 3 - 1, b / 9 - 1};
    const bool inSlab = d[axisOf(n)] == 0 || d[axisOf(n)] == signOf(n);
    if (inSlab && d != u && d != un) relevant.push_back(Neighbourhood::bitOf(d));
  }
  EXPECT_EQ(relevant.size(), 16u);
  std::vector<std::uint32_t> out;
  for (std::uint32_t pattern = 0; pattern < (1u << relevant.size()); ++pattern) {
    std::uint32_t bits = 1u << Neighbourhood::bitOf(u);
    for (std::size_t i = 0; i < relevant.size(); ++i)
      if ((pattern >> i) & 1) bits |= 1u << relevant[i];
    out.push_back(bits);
  }
  return out;
}

TEST(BetaNeighbourTable, AgreesWithDefinition38OnEveryNeighbourhood) {
  // The tracker's table must give the reference neighbours, in the same order, for every
  // pattern of the 16 voxels Definition 38 looks at around a surfel (u = 1, u + n = 0).
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    const BetaNeighbourTable table(pair);
    for (Direction n = 0; n < 6; ++n) {
      const Surfel t{Voxel{5, -3, 7}, n};
      for (const std::uint32_t bits : neighbourhoodsOfASurfel(n)) {
        Surfel expected[kMaxBetaNeighbours], found[kMaxBetaNeighbours];
        const int k = betaNeighbours(Neighbourhood{t.c, bits}, t, pair, expected);
        ASSERT_EQ(table.neighbours(bits, t, found), k) << toString(pair) << " neighbourhood " << bits;
        for (int j = 0; j < k; ++j) ASSERT_EQ(found[j], expected[j]) << toString(pair);
      }
    }
  }
}

}  // namespace

namespace {

// A brick cache that answers one fixed neighbourhood and names each linked brick by its selector.
struct FixedNeighbourhood {
  NeighbourhoodSlices slices;
  NeighbourhoodSlices neighbourhoodSlices(std::uint32_t, int) const { return slices; }
  std::uint32_t linkedBrick(std::uint32_t, int selector) const { return std::uint32_t(selector); }
};

TEST(BrickStepTable, TrackerStepsAgreeWithDefinition38AtEveryPlaceOfABrick) {
  // The tracker's moves between brick slots (deltaSlot inside the brick, a linked brick across
  // its border, the strict-26 candidates filter) must give the reference neighbours, in order,
  // for every pattern of the 16 voxels around a surfel and for voxels on every kind of border.
  const Voxel places[] = {{0, 0, 0}, {7, 7, 7}, {3, 0, 7}, {7, 4, 0}, {2, 5, 3}, {0, 7, 4}};
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    const BrickStepTable steps(pair);
    for (Direction n = 0; n < 6; ++n) {
      const std::vector<std::uint32_t> neighbourhoods = neighbourhoodsOfASurfel(n);
      for (const Voxel& place : places) {
        const Surfel t{Voxel{40, -9, 13} + place, n};
        const int slot = brickslot::slotOf(brickslot::voxelOf(place.x, place.y, place.z), n);
        for (const std::uint32_t bits : neighbourhoods) {
          if (!surftrack::testing::caseChecked(bits)) continue;
          Surfel expected[kMaxBetaNeighbours];
          const int k = betaNeighbours(Neighbourhood{t.c, bits}, t, pair, expected);
          FixedNeighbourhood cache{{{bits & 511u, (bits >> 9) & 511u, bits >> 18}}};
          std::vector<Surfel> found;
          detail::forEachBetaNeighbour(
              cache, steps, 13, slot,
              [&](std::uint32_t brick, int to) {
                const int s = int(brick), v = to & 511;
                const Voxel local{v & 7, (v >> 3) & 7, v >> 6};
                const Voxel offset{8 * (s % 3 - 1), 8 * ((s / 3) % 3 - 1), 8 * (s / 9 - 1)};
                found.push_back(Surfel{t.c + offset + local - place, Direction(to >> 9)});
              });
          ASSERT_EQ(int(found.size()), k) << toString(pair) << " neighbourhood " << bits;
          for (int j = 0; j < k; ++j)
            ASSERT_EQ(found[j], expected[j]) << toString(pair) << " neighbourhood " << bits << " place " << place;
        }
      }
    }
  }
}

// The converter reads the 4 cubes around a surfel from its neighbourhood bits with shifts;
// the reference reads the 8 corners one by one.
TEST(Neighbourhood, CubeConfigurationsAgreeWithTheCornersOfEveryCube) {
  std::mt19937 rng(27);
  for (int trial = 0; trial < 20000; ++trial) {
    const Neighbourhood around{Voxel{-3, 5, 11}, std::uint32_t(rng()) & ((1u << 27) - 1)};
    for (int i = 0; i < cube::kCorners; ++i) {
      const Voxel offset = cube::cornerOffset(i) - Voxel{1, 1, 1};
      ASSERT_EQ(around.cubeConfiguration(offset), cube::configurationAt(around, around.center + offset))
          << "neighbourhood " << around.bits << " offset " << offset;
    }
  }
}

}  // namespace
