// trackComponent on images that cannot be scanned, its errors, and the seed finder; the graph
// and its mesh (extractLoops) the same for any number of threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <boost/range/iterator_range.hpp>

#include "FindSeed.h"
#include "LoopExtraction.h"
#include "Phantoms.h"
#include "TrackComponent.h"
#include "VoxelComponents.h"

using namespace surftrack;
using namespace surftrack::testing;

namespace {

// Number of grid lines parallel to `axis` that meet the digital ball |v - c|^2 <= r2 (c integer):
// a line at squared distance d2 from c meets it iff d2 <= r2. O(q^2), independent of surfels.
std::int64_t linesMeetingBall(std::int64_t r2, int radius) {
  std::int64_t lines = 0;
  for (int a = -radius; a <= radius; ++a)
    for (int b = -radius; b <= radius; ++b) lines += std::int64_t(a) * a + std::int64_t(b) * b <= r2;
  return lines;
}

TEST(Tracking, ImplicitBallOfRadius900InA4096CubedDomain) {
  // 68 G voxels: this image can be neither stored nor scanned; tracking touches its surface only.
  const int c = 2048, radius = 900;
  const std::int64_t r2 = std::int64_t(radius) * radius;
  const ImplicitImage ball({4096, 4096, 4096}, Ball{{c, c, c}, r2});
  const auto seed = seedAlongRay(ball, Voxel{c, c, c}, 0);
  ASSERT_TRUE(seed.has_value());
  EXPECT_EQ(*seed, (Surfel{{c + radius, c, c}, 0}));
  std::vector<std::size_t> reports;
  const SurfaceGraph g = trackComponent(ball, *seed, AdjacencyPair::k26_6,
                                        [&](std::size_t found) { reports.push_back(found); });
  // Each line meets the ball in one interval, hence carries exactly 2 surfels along it; by
  // symmetry L_x = L_y = L_z.
  EXPECT_EQ(std::int64_t(g.surfelCount()), 2 * 3 * linesMeetingBall(r2, radius));
  // Progress: about once per 2^20 surfels found, increasing, never past the total.
  EXPECT_GE(reports.size(), g.surfelCount() / (std::size_t(1) << 20) - 1);
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  ASSERT_FALSE(reports.empty());
  EXPECT_LE(reports.back(), g.surfelCount());
}

TEST(Tracking, BallFromAnySeedInEveryPair) {
  const ImplicitImage ball({40, 40, 40}, Ball{{20, 19, 21}, 150});
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    const SurfaceGraph g = trackComponent(ball, *seedAlongRay(ball, Voxel{20, 19, 21}, 3), pair);
    EXPECT_EQ(std::int64_t(g.surfelCount()), 2 * 3 * linesMeetingBall(150, 13));
    const SurfaceGraph h = trackComponent(ball, g.surfels.back(), pair);
    EXPECT_EQ(sortedKeys(h.surfels), sortedKeys(g.surfels));
  }
}

TEST(Tracking, SeedThatIsNotABoundarySurfelIsRejectedWithTheVoxelNamed) {
  BinaryVolume volume({4, 4, 4});
  volume.at(1, 1, 1) = 1;
  const auto image = binaryView(volume);
  try {
    trackComponent(image, Surfel{{2, 1, 1}, 0}, AdjacencyPair::k18_6);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("c=(2,1,1) is a 0-voxel"), std::string::npos) << e.what();
  }
  try {
    trackComponent(image, Surfel{{0, 1, 1}, 0}, AdjacencyPair::k18_6);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("d=(1,1,1) is a 1-voxel"), std::string::npos) << e.what();
  }
}

TEST(Tracking, SeedOutsideTheDomainIsRejected) {
  BinaryVolume volume({4, 4, 4}, 1);
  const auto image = binaryView(volume);
  EXPECT_THROW(trackComponent(image, Surfel{{9, 0, 0}, 0}, AdjacencyPair::k26_6),
               std::invalid_argument);
  // The outer surfels of the domain border are fine: the outside is background.
  EXPECT_EQ(trackComponent(image, Surfel{{3, 0, 0}, 0}, AdjacencyPair::k26_6).surfelCount(),
            6u * 16u);
}

TEST(Tracking, EmptyImageHasNoSeedAndNoBoundary) {
  BinaryVolume volume({5, 5, 5});
  const auto image = binaryView(volume);
  EXPECT_FALSE(seedAlongRay(image, Voxel{2, 2, 2}, 0).has_value());
  EXPECT_THROW(trackComponent(image, Surfel{{2, 2, 2}, 0}, AdjacencyPair::k26_6),
               std::invalid_argument);
  EXPECT_THROW(DenseImage<float>(Dims{0, 3, 3}), std::invalid_argument);
}

TEST(Tracking, UnsupportedPairIsRejected) {
  EXPECT_THROW(parseAdjacencyPair("18-18"), std::invalid_argument);
  EXPECT_THROW(parseAdjacencyPair("26-26"), std::invalid_argument);
  EXPECT_EQ(parseAdjacencyPair("6,26"), AdjacencyPair::k6_26);
}

TEST(SeedAlongRay, FromInsideAndFromOutside) {
  BinaryVolume volume({8, 3, 3});
  for (int x = 3; x <= 5; ++x) volume.at(x, 1, 1) = 1;
  const auto image = binaryView(volume);
  EXPECT_EQ(*seedAlongRay(image, Voxel{4, 1, 1}, 0), (Surfel{{5, 1, 1}, 0}));
  EXPECT_EQ(*seedAlongRay(image, Voxel{0, 1, 1}, 0), (Surfel{{3, 1, 1}, 1}));
  EXPECT_EQ(*seedAlongRay(image, Voxel{4, 1, 1}, 1), (Surfel{{3, 1, 1}, 1}));
}

TEST(SurfaceGraph, ArcsAreSymmetricAndMatchTheNeighbours) {
  const BinaryVolume volume = randomVolume({10, 10, 10}, 0.5, 99);
  const auto image = binaryView(volume);
  const auto seed = seedAlongRay(image, Voxel{0, 0, 0}, 0);
  ASSERT_TRUE(seed);
  const SurfaceGraph g = trackComponent(image, *seed, AdjacencyPair::k26_6);
  for (std::uint32_t v = 0; v < g.surfelCount(); ++v) {
    Surfel nb[kMaxBetaNeighbours];
    const int k = betaNeighbours(image, g.surfels[v], g.pair, nb);
    ASSERT_EQ(int(boost::out_degree(v, g.graph)), k);
    int j = 0;
    for (auto w : boost::make_iterator_range(boost::adjacent_vertices(v, g.graph)))
      ASSERT_EQ(g.surfels[w], nb[j++]);
  }
}


// The second pass of tracking and the loop extraction in runs of bricks / vertices: the graph
// (vertex order, arcs) and the mesh (triangle order included) do not depend on the number of
// threads, and the mesh is that of the one-thread walk over the image (extractLoops(image,
// graph), which reads the image again instead of the tracker's bricks).
TEST(Tracking, EveryThreadCountGivesTheSameGraphAndMesh) {
  auto check = [](const auto& image, const Surfel& seed, AdjacencyPair pair, const std::string& what) {
    const SurfaceGraph one = trackComponent(image, seed, pair, {}, 1);
    const TriangleMesh reference = extractLoops(image, one);
    ASSERT_EQ(extractLoops(one, 1).triangles, reference.triangles) << what;
    for (int threads : {2, 7, 0}) {
      const SurfaceGraph many = trackComponent(image, seed, pair, {}, threads);
      ASSERT_EQ(many.surfels, one.surfels) << what << " threads " << threads;
      ASSERT_EQ(many.graph.m_forward.m_rowstart, one.graph.m_forward.m_rowstart) << what << " threads " << threads;
      ASSERT_EQ(many.graph.m_forward.m_column, one.graph.m_forward.m_column) << what << " threads " << threads;
      const TriangleMesh mesh = extractLoops(many, threads);
      ASSERT_EQ(mesh.surfels, reference.surfels) << what << " threads " << threads;
      ASSERT_EQ(mesh.triangles, reference.triangles) << what << " threads " << threads;
    }
  };
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      // 5 % noise: 26-configurations and tubes on the sphere, noise specks touching it.
      const NoisyPhantom sphere = makeNoisySphere(40 + 8 * int(seed), 0.05, seed);
      check(sphere.binary(), protocolSeed(sphere), pair, "sphere " + std::to_string(seed) + " " + toString(pair));
    }
    for (std::uint32_t seed = 0; seed < 12; ++seed) {
      const BinaryVolume volume = randomVolume({24, 20, 22}, 0.3 + 0.03 * seed, 500 + seed);
      const auto image = binaryView(volume);
      const auto s = seedAlongRay(image, Voxel{0, 10, 11}, 0);
      if (s) check(image, *s, pair, "random " + std::to_string(seed) + " " + toString(pair));
    }
  }
  // A graph of more than 2^16 surfels, which all cores (0) also split.
  const NoisyPhantom big = makeNoisySphere(160, 0.01, 4);
  check(big.binary(), protocolSeed(big), AdjacencyPair::k26_6, "sphere 160");
}

}  // namespace
