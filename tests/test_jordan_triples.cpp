// Proposition 39 (Jordan triples): the beta-components of all boundary surfels are exactly the
// kappa-lambda-boundaries d(O, Q), with O and Q computed independently as voxel components.
// Also §2.1.5 (Jordan pairs): every boundary separates its immediate interior from its
// immediate exterior in the 6-grid. And tracking from any surfel returns its whole boundary.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "CaseSubset.h"
#include "PairTestName.h"
#include "ScanBoundaries.h"
#include "TrackComponent.h"
#include "VoxelComponents.h"

using namespace surftrack;
using namespace surftrack::testing;

namespace {

::testing::AssertionResult checkImage(const BinaryVolume& volume, AdjacencyPair pair,
                                      std::mt19937& rng, bool checkJordanPairs) {
  const auto image = binaryView(volume);
  const VoxelComponents voxels(image, pair);
  std::set<std::vector<std::uint64_t>> expected;
  for (const auto& [oq, keys] : voxels.boundaries()) expected.insert(keys);

  const BoundaryPartition partition = scanBoundaries(image, pair);
  std::set<std::vector<std::uint64_t>> found;
  for (const auto& component : partition.components()) found.insert(sortedKeys(component));
  if (found != expected)
    return ::testing::AssertionFailure()
           << toString(pair) << ": " << found.size() << " beta-components vs " << expected.size()
           << " kappa-lambda-boundaries";

  for (const auto& component : partition.components()) {
    std::uniform_int_distribution<std::size_t> pick(0, component.size() - 1);
    const Surfel seed = component[pick(rng)];
    const SurfaceGraph graph = trackComponent(image, seed, pair);
    if (sortedKeys(graph.surfels) != sortedKeys(component))
      return ::testing::AssertionFailure()
             << toString(pair) << ": tracking from " << seed << " found " << graph.surfelCount()
             << " surfels, its boundary has " << component.size();
    if (checkJordanPairs && !voxels.separates(component))
      return ::testing::AssertionFailure()
             << toString(pair) << ": boundary of " << component.size()
             << " surfels does not separate its interior from its exterior";
  }
  return ::testing::AssertionSuccess();
}

class JordanTriples : public ::testing::TestWithParam<AdjacencyPair> {};

TEST_P(JordanTriples, EveryConfigurationOf2x2x2Block) {
  std::mt19937 rng(1);
  for (std::uint64_t bits = 0; bits < 256; ++bits)
    ASSERT_TRUE(checkImage(volumeFromBits({2, 2, 2}, bits), GetParam(), rng, true))
        << "configuration " << bits;
}

TEST_P(JordanTriples, EveryConfigurationOf2x2x3Block) {
  std::mt19937 rng(2);
  for (std::uint64_t bits = 0; bits < 4096; ++bits)
    if (surftrack::testing::caseChecked(bits))
      ASSERT_TRUE(checkImage(volumeFromBits({2, 2, 3}, bits), GetParam(), rng, true))
        << "configuration " << bits;
}

TEST_P(JordanTriples, RandomImages) {
  // 2,000 images from 3^3 to 16^3, densities 0.1 to 0.9, fixed seeds; Jordan pairs are checked
  // on the smaller ones (the check costs a grid traversal per boundary).
  std::mt19937 rng(20261122u + unsigned(GetParam()));
  std::uniform_int_distribution<int> side(3, 16);
  std::uniform_real_distribution<double> density(0.1, 0.9);
  for (int i = 0; i < 2000; ++i) {
    const Dims dims{side(rng), side(rng), side(rng)};
    const double p = density(rng);
    const BinaryVolume volume = randomVolume(dims, p, rng());
    if (!surftrack::testing::caseChecked(std::uint64_t(i))) continue;
    ASSERT_TRUE(checkImage(volume, GetParam(), rng, dims.count() <= 600))
        << "image " << i << " " << dims.nx << "x" << dims.ny << "x" << dims.nz << " p=" << p;
  }
}

INSTANTIATE_TEST_SUITE_P(AllPairs, JordanTriples, ::testing::ValuesIn(kAllAdjacencyPairs),
                         surftrack::testing::pairTestName);

}  // namespace
