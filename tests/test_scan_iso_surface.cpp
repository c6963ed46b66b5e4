// The scanning method (method 1 of Figure 9): scanIsoSurface, its components, and method 2 = 1.
//  - the vertices of the scanned mesh are exactly the boundary surfels, each once; the mesh is a
//    closed oriented surface (every directed edge once, its reverse once);
//  - the fast dense path, the generic path and a naive per-cube reference give the same mesh;
//  - the components of the mesh are exactly the kappa-lambda-boundaries (scanBoundaries and
//    independent voxel components), on every 2x2x2 and 2x2x3 image and on random images;
//  - the mesh of each boundary, tracked (trackComponent) and converted (extractLoops), has
//    exactly the triangles of that boundary's component of the scanned mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "CaseSubset.h"
#include "DigitalCube.h"
#include "LoopExtraction.h"
#include "Phantoms.h"
#include "ScanBoundaries.h"
#include "ScanIsoSurface.h"
#include "TrackComponent.h"
#include "VoxelComponents.h"

using namespace surftrack;
using surftrack::testing::randomVolume;
using surftrack::testing::sortedKeys;

namespace {

using Keys = std::vector<std::uint64_t>;
/// A triangle as surfel keys, rotated so that the smallest key comes first (orientation kept).
using Triple = std::array<std::uint64_t, 3>;

Triple normalised(Triple t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

/// The triangles of a mesh as a sorted list of normalised oriented triples (repeats kept).
std::vector<Triple> triangleTriples(const TriangleMesh& mesh) {
  std::vector<Triple> out;
  out.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    out.push_back(normalised({mesh.surfels[t[0]].key(), mesh.surfels[t[1]].key(), mesh.surfels[t[2]].key()}));
  std::sort(out.begin(), out.end());
  return out;
}

/// Naive independent reference: every cube with min corner in [-1, n-1]^3, configurationAt,
/// the table's triangles, surfels by surfelOnEdge. Only the table is shared with the scanner.
template <class BinaryImage>
std::vector<Triple> referenceTriples(const BinaryImage& image, AdjacencyPair pair) {
  const Dims d = image.dims();
  std::vector<Triple> out;
  for (int z = -1; z < d.nz; ++z)
    for (int y = -1; y < d.ny; ++y)
      for (int x = -1; x < d.nx; ++x) {
        const Voxel m{x, y, z};
        const std::uint8_t config = cube::configurationAt(image, m);
        for (const auto& t : configurationTable(pair, config).allTriangles()) {
          Triple k;
          for (int i = 0; i < 3; ++i) k[i] = cube::surfelOnEdge(m, t[i], config).key();
          out.push_back(normalised(k));
        }
      }
  std::sort(out.begin(), out.end());
  return out;
}

/// 1,000+ random images: sides 3..16 (not necessarily cubic), density 0.1..0.9.
std::vector<BinaryVolume> randomImages(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<BinaryVolume> out;
  for (int i = 0; i < count; ++i) {
    const Dims d{3 + int(rng() % 14), 3 + int(rng() % 14), 3 + int(rng() % 14)};
    const double density = 0.1 + 0.8 * double(rng() >> 11) * 0x1p-53;
    const std::uint32_t seed = std::uint32_t(rng());
    if (surftrack::testing::caseChecked(std::uint64_t(i))) out.push_back(randomVolume(d, density, seed));
  }
  return out;
}

/// Every image of the given size (2x2x2: 256, 2x2x3: 4096).
std::vector<BinaryVolume> allImages(Dims dims) {
  const int n = int(dims.count());
  std::vector<BinaryVolume> out;
  for (int bits = 0; bits < (1 << n); ++bits)
    if (surftrack::testing::caseChecked(std::uint64_t(bits))) out.push_back(surftrack::testing::volumeFromBits(dims, bits));
  return out;
}

/// The vertex sets of the mesh's components, each a sorted key list, sorted.
std::vector<Keys> componentVertexSets(const TriangleMesh& mesh) {
  std::size_t count = 0;
  const std::vector<std::uint32_t> label = meshComponents(mesh, count);
  std::vector<Keys> out(count);
  for (std::size_t v = 0; v < mesh.surfels.size(); ++v) out[label[v]].push_back(mesh.surfels[v].key());
  for (Keys& k : out) std::sort(k.begin(), k.end());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Keys> boundaryVertexSets(const BoundaryPartition& partition) {
  std::vector<Keys> out;
  for (const auto& c : partition.components()) out.push_back(sortedKeys(c));
  std::sort(out.begin(), out.end());
  return out;
}

/// Structural checks of a scanned mesh; returns an empty string when all hold.
template <class BinaryImage>
std::string structureProblem(const BinaryImage& image, const TriangleMesh& mesh) {
  if (sortedKeys(mesh.surfels) != sortedKeys(allBoundarySurfels(image)))
    return "vertices are not the boundary surfels";
  const Keys keys = sortedKeys(mesh.surfels);
  if (std::adjacent_find(keys.begin(), keys.end()) != keys.end()) return "a surfel is two vertices";
  std::set<std::array<std::uint32_t, 3>> unoriented;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (std::uint32_t v : t)
      if (v >= mesh.surfels.size()) return "vertex index out of range";
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return "degenerate triangle";
    std::array<std::uint32_t, 3> s = t;
    std::sort(s.begin(), s.end());
    if (!unoriented.insert(s).second) return "repeated triangle";
    for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
  }
  for (const auto& [e, n] : directed) {
    if (n != 1) return "a directed edge is used twice";
    if (!directed.count({e.second, e.first})) return "an edge has no opposite (open or misoriented)";
  }
  std::vector<bool> used(mesh.surfels.size(), false);
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t) used[v] = true;
  if (std::find(used.begin(), used.end(), false) != used.end()) return "a vertex is in no triangle";
  return {};
}

/// Widths around the 64-voxel words of the row bit sets.
const std::vector<Dims> kWordBoundaryDims = {{1, 1, 1}, {62, 3, 2}, {63, 2, 3},  {64, 3, 3},
                                             {65, 2, 2}, {126, 2, 2}, {127, 3, 2}, {128, 2, 3},
                                             {129, 3, 3}, {200, 2, 2}};

}  // namespace

TEST(ScanIsoSurface, VerticesAreTheBoundarySurfelsAndTheMeshIsClosedAndOriented) {
  int images = 0;
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    for (const BinaryVolume& v : randomImages(150, 11)) {
      const auto image = binaryView(v);
      ASSERT_EQ(structureProblem(image, scanIsoSurface(image, pair)), "") << toString(pair);
      ++images;
    }
    for (Dims d : kWordBoundaryDims)
      for (double density : {0.05, 0.5, 0.95}) {
        const BinaryVolume v = randomVolume(d, density, 7 + d.nx);
        const auto image = binaryView(v);
        ASSERT_EQ(structureProblem(image, scanIsoSurface(image, pair)), "")
            << toString(pair) << " " << d.nx << "x" << d.ny << "x" << d.nz;
      }
  }
  EXPECT_GE(images, 4 * int(surftrack::testing::subsetMinimum(150)));  // the random images were made
}

// Count, prefix sum, fill in runs of slabs: the mesh does not depend on the number of threads,
// down to the vertex numbering.
TEST(ScanIsoSurface, EveryThreadCountGivesTheSameMesh) {
  auto check = [](const auto& image, AdjacencyPair pair, const char* what) {
    const TriangleMesh one = scanIsoSurface(image, pair, 1);
    for (int threads : {2, 7, 0}) {
      const TriangleMesh many = scanIsoSurface(image, pair, threads);
      ASSERT_EQ(many.surfels, one.surfels) << what << " " << toString(pair) << " threads " << threads;
      ASSERT_EQ(many.triangles, one.triangles) << what << " " << toString(pair) << " threads " << threads;
    }
  };
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    for (const BinaryVolume& v : randomImages(40, 31)) check(binaryView(v), pair, "random");
    for (Dims d : kWordBoundaryDims) check(binaryView(randomVolume(d, 0.5, 5 + d.nx)), pair, "word boundaries");
    const NoisyPhantom sphere = makeNoisySphere(48, 0.05, 9);
    check(sphere.binary(), pair, "sphere");
  }
}

TEST(ScanIsoSurface, EmptyFullAndSingleVoxelImages) {
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    const BinaryVolume empty({5, 4, 3}, 0), full({5, 4, 3}, 1), one({1, 1, 1}, 1);
    EXPECT_TRUE(scanIsoSurface(binaryView(empty), pair).surfels.empty());
    EXPECT_TRUE(scanIsoSurface(binaryView(empty), pair).triangles.empty());
    const TriangleMesh box = scanIsoSurface(binaryView(full), pair);
    EXPECT_EQ(box.surfels.size(), 2u * (5 * 4 + 4 * 3 + 5 * 3));
    EXPECT_EQ(structureProblem(binaryView(full), box), "");
    const TriangleMesh cube = scanIsoSurface(binaryView(one), pair);
    EXPECT_EQ(cube.surfels.size(), 6u);
    EXPECT_EQ(cube.triangles.size(), 8u);  // an octahedron
  }
}

TEST(ScanIsoSurface, FastPathGenericPathAndNaiveReferenceAgree) {
  auto check = [](const auto& image, AdjacencyPair pair, const char* what) {
    const TriangleMesh fast = scanIsoSurface(image, pair);
    const TriangleMesh generic = scanIsoSurfaceGeneric(image, pair);
    // Same engine behind both: even the vertex numbering must agree.
    ASSERT_EQ(fast.surfels, generic.surfels) << what << " " << toString(pair);
    ASSERT_EQ(fast.triangles, generic.triangles) << what << " " << toString(pair);
    ASSERT_EQ(triangleTriples(fast), referenceTriples(image, pair)) << what << " " << toString(pair);
  };
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    for (const BinaryVolume& v : randomImages(60, 23)) check(binaryView(v), pair, "random");
    for (Dims d : kWordBoundaryDims)
      for (double density : {0.1, 0.5, 0.9}) {
        const BinaryVolume v = randomVolume(d, density, 99 + d.nx * 3 + d.ny);
        check(binaryView(v), pair, "word boundaries");
        check(binaryView(v, /*outside=*/true), pair, "outside is 1");
      }
    for (double noise : {0.0, 0.05}) {
      const NoisyPhantom sphere = makeNoisySphere(40, noise, 5);
      check(sphere.binary(), pair, "sphere");
    }
  }
  // Other gray types and iso-values, including iso-values outside the range of the type.
  std::mt19937_64 rng(3);
  const Dims d{70, 5, 4};
  DenseImage<std::int16_t> i16(d);
  DenseImage<float> f32(d);
  DenseImage<std::uint8_t> u8(d);
  DenseImage<std::uint32_t> u32(d);
  for (std::size_t i = 0; i < d.count(); ++i) {
    i16.data()[i] = std::int16_t(int(rng() % 2001) - 1000);
    f32.data()[i] = float(int(rng() % 2001) - 1000) / 8.0f;
    u8.data()[i] = std::uint8_t(rng());
    u32.data()[i] = std::uint32_t(rng() % 5);
  }
  for (double s : {-1e9, -1000.5, -3.0, 0.0, 0.25, 17.0, 999.0, 1e9}) {
    check(ThresholdImage<std::int16_t>(i16, s), AdjacencyPair::k26_6, "int16");
    check(ThresholdImage<float>(f32, s / 8), AdjacencyPair::k6_26, "float");
  }
  for (double s : {-1.0, -0.5, 0.0, 127.0, 127.5, 128.0, 254.5, 255.0, 300.0})
    check(ThresholdImage<std::uint8_t>(u8, s), AdjacencyPair::k18_6, "uint8");
  for (double s : {-1.0, 0.0, 2.5, 4.0, 5e9}) check(ThresholdImage<std::uint32_t>(u32, s), AdjacencyPair::k6_18, "uint32");
  // Images that only have an operator(): label and implicit images, through the generic path.
  const BinaryVolume labels = randomVolume({20, 9, 7}, 0.5, 1);
  const LabelImage<std::uint8_t> label(labels, 0);
  EXPECT_EQ(triangleTriples(scanIsoSurface(label, AdjacencyPair::k26_6)), referenceTriples(label, AdjacencyPair::k26_6));
  const ImplicitImage ball({21, 21, 21}, Ball::ofRadius({10, 10, 10}, 8));
  EXPECT_EQ(triangleTriples(scanIsoSurface(ball, AdjacencyPair::k6_18)), referenceTriples(ball, AdjacencyPair::k6_18));
}

namespace {

/// Components of the scanned mesh = scanBoundaries (= independent voxel components, which are
/// slower to compute: checked when `withVoxelComponents`).
void expectComponentsAreBoundaries(const BinaryVolume& v, AdjacencyPair pair, bool withVoxelComponents = true) {
  const auto image = binaryView(v);
  const TriangleMesh mesh = scanIsoSurface(image, pair);
  const std::vector<Keys> components = componentVertexSets(mesh);
  ASSERT_EQ(components, boundaryVertexSets(scanBoundaries(image, pair))) << toString(pair);
  if (!withVoxelComponents) return;
  std::vector<Keys> reference;
  for (auto& [oq, keys] : surftrack::testing::VoxelComponents(image, pair).boundaries()) reference.push_back(keys);
  std::sort(reference.begin(), reference.end());
  ASSERT_EQ(components, reference) << toString(pair);
}

/// Method 2 = method 1: each boundary tracked and converted has the triangles of its component.
void expectTrackedEqualsScanned(const BinaryVolume& v, AdjacencyPair pair) {
  const auto image = binaryView(v);
  for (const TriangleMesh& component : scanComponents(image, pair)) {
    const Surfel seed = component.surfels.front();
    const TriangleMesh tracked = extractLoops(image, trackComponent(image, seed, pair));
    ASSERT_EQ(triangleTriples(tracked), triangleTriples(component)) << toString(pair) << " seed " << seed;
    ASSERT_EQ(sortedKeys(tracked.surfels), sortedKeys(component.surfels));
  }
}

}  // namespace

TEST(ScanIsoSurface, ComponentsAreTheBoundariesOnEvery2x2x2And2x2x3Image) {
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (Dims d : {Dims{2, 2, 2}, Dims{2, 2, 3}})
      for (const BinaryVolume& v : allImages(d)) ASSERT_NO_FATAL_FAILURE(expectComponentsAreBoundaries(v, pair));
}

TEST(ScanIsoSurface, ComponentsAreTheBoundariesOnRandomImages) {
  const std::vector<BinaryVolume> images = randomImages(1000, 2024);
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (std::size_t i = 0; i < images.size(); ++i)
      ASSERT_NO_FATAL_FAILURE(expectComponentsAreBoundaries(images[i], pair, i % 5 == 0));
}

TEST(ScanIsoSurface, TrackedAndConvertedEqualsScannedOnEvery2x2x2And2x2x3Image) {
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (Dims d : {Dims{2, 2, 2}, Dims{2, 2, 3}})
      for (const BinaryVolume& v : allImages(d)) ASSERT_NO_FATAL_FAILURE(expectTrackedEqualsScanned(v, pair));
}

TEST(ScanIsoSurface, TrackedAndConvertedEqualsScannedOnRandomImages) {
  const std::vector<BinaryVolume> images = randomImages(1000, 2024);
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (const BinaryVolume& v : images) ASSERT_NO_FATAL_FAILURE(expectTrackedEqualsScanned(v, pair));
}

TEST(ScanIsoSurface, ExtractComponentKeepsTheSeedsComponentRenumbered) {
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (const BinaryVolume& v : randomImages(40, 77)) {
      const auto image = binaryView(v);
      const TriangleMesh mesh = scanIsoSurface(image, pair);
      const std::vector<TriangleMesh> parts = splitComponents(mesh);
      std::size_t count = 0;
      meshComponents(mesh, count);
      ASSERT_EQ(parts.size(), count);
      std::size_t triangles = 0;
      for (const TriangleMesh& part : parts) {
        triangles += part.triangles.size();
        // From any of its surfels, extractComponent gives this part again, vertex for vertex.
        for (const Surfel& seed : {part.surfels.front(), part.surfels.back()}) {
          const TriangleMesh one = extractComponent(mesh, seed);
          ASSERT_EQ(one.surfels, part.surfels);
          ASSERT_EQ(one.triangles, part.triangles);
        }
        std::size_t c = 0;
        meshComponents(part, c);
        ASSERT_EQ(c, 1u);
        for (const auto& t : part.triangles)
          for (std::uint32_t i : t) ASSERT_LT(i, part.surfels.size());
      }
      ASSERT_EQ(triangles, mesh.triangles.size());
    }
  const BinaryVolume v = randomVolume({6, 6, 6}, 0.5, 4);
  EXPECT_THROW(extractComponent(scanIsoSurface(binaryView(v), AdjacencyPair::k26_6), Surfel{{40, 0, 0}, 0}),
               std::invalid_argument);
}

TEST(ScanIsoSurface, NoisySphereOfTheProtocol) {
  for (double noise : {0.0, 0.01, 0.05}) {
    const NoisyPhantom sphere = makeNoisySphere(48, noise);
    const auto image = sphere.binary();
    const Surfel seed = protocolSeed(sphere);
    // The seed is a boundary surfel on the +x ray, untouched by noise, about R from the centre.
    EXPECT_TRUE(image(seed.inside()) && !image(seed.outside()));
    EXPECT_FALSE(sphere.changed(seed.inside()) || sphere.changed(seed.outside()));
    EXPECT_EQ(seed.c.y, 24);
    EXPECT_EQ(seed.c.z, 24);
    EXPECT_NEAR(0.5 * (seed.inside().x + seed.outside().x) - sphere.centre, sphere.radius, 1.0);
    for (AdjacencyPair pair : kAllAdjacencyPairs) {
      const TriangleMesh mesh = scanIsoSurface(image, pair);
      ASSERT_EQ(structureProblem(image, mesh), "");
      ASSERT_EQ(componentVertexSets(mesh), boundaryVertexSets(scanBoundaries(image, pair)));
      const TriangleMesh scanned = extractComponent(mesh, seed);
      const TriangleMesh tracked = extractLoops(image, trackComponent(image, seed, pair));
      EXPECT_EQ(triangleTriples(tracked), triangleTriples(scanned)) << noise << " " << toString(pair);
      // The seed lies on the sphere, the largest boundary, not on a speck of noise.
      std::size_t largest = 0;
      for (const TriangleMesh& part : splitComponents(mesh)) largest = std::max(largest, part.surfels.size());
      EXPECT_EQ(scanned.surfels.size(), largest);
    }
  }
  // When noise hit a voxel of the crossing on the +x ray, the seed comes from the next row.
  NoisyPhantom damaged = makeNoisySphere(48, 0.0);
  const Surfel onRay = protocolSeed(damaged);
  damaged.hit.assign(damaged.image.dims().count(), 0);
  damaged.hit[damaged.image.index(onRay.c.x, onRay.c.y, onRay.c.z)] = 1;
  const Surfel moved = protocolSeed(damaged);
  EXPECT_EQ(moved.c.y, onRay.c.y + 1);
  EXPECT_EQ(moved.c.z, onRay.c.z);
  EXPECT_FALSE(damaged.changed(moved.inside()) || damaged.changed(moved.outside()));
  // Noise changes about the requested fraction of voxels, half of them to 255.
  const NoisyPhantom noisy = makeNoisySphere(64, 0.05);
  std::size_t hits = 0, white = 0;
  for (std::size_t i = 0; i < noisy.hit.size(); ++i)
    if (noisy.hit[i]) {
      ++hits;
      white += noisy.image.data()[i] == 255;
    }
  EXPECT_NEAR(double(hits) / noisy.hit.size(), 0.05, 0.002);
  EXPECT_NEAR(double(white) / hits, 0.5, 0.02);
}

namespace {

/// scanBoundaryCounts against the components of the scanned mesh: the same boundaries in the
/// same order, each with its surfel count, its first vertex and that vertex's surfel; on one
/// thread and, when `threaded`, on 2 and 7 (a run per slab or a few, so that boundaries cross
/// between runs). With `withVoxelComponents`, the counts are also those of the independent
/// voxel components.
template <class BinaryImage>
void expectCountsAreComponents(const BinaryImage& image, AdjacencyPair pair, bool withVoxelComponents,
                               const char* what, bool threaded = true) {
  const TriangleMesh mesh = scanIsoSurface(image, pair, 1);
  std::size_t count = 0;
  const std::vector<std::uint32_t> label = meshComponents(mesh, count);
  std::vector<BoundaryCount> expected(count);
  std::vector<bool> seen(count, false);
  for (std::size_t v = 0; v < label.size(); ++v) {
    BoundaryCount& b = expected[label[v]];
    ++b.surfels;
    if (!seen[label[v]]) {
      seen[label[v]] = true;
      b.firstVertex = v;
      b.seed = mesh.surfels[v];
    }
  }
  for (int threads : {1, 2, 7}) {
    if (threads > 1 && !threaded) break;
    const std::vector<BoundaryCount> counts = scanBoundaryCounts(image, pair, threads);
    ASSERT_EQ(counts.size(), expected.size()) << what << " " << toString(pair) << " threads " << threads;
    for (std::size_t i = 0; i < counts.size(); ++i) {
      ASSERT_EQ(counts[i].surfels, expected[i].surfels) << what << " " << toString(pair) << " threads " << threads;
      ASSERT_EQ(counts[i].firstVertex, expected[i].firstVertex) << what << " " << toString(pair) << " threads " << threads;
      ASSERT_EQ(counts[i].seed, expected[i].seed) << what << " " << toString(pair) << " threads " << threads;
    }
  }
  if (!withVoxelComponents) return;
  // Independently: each boundary of the voxel components holds exactly one seed, and has its size.
  std::map<std::uint64_t, std::size_t> sizeOfSeed;
  for (const BoundaryCount& b : expected) sizeOfSeed[b.seed.key()] = b.surfels;
  std::size_t boundaries = 0;
  for (auto& [oq, keys] : surftrack::testing::VoxelComponents(image, pair).boundaries()) {
    ++boundaries;
    std::size_t seeds = 0;
    for (std::uint64_t k : keys)
      if (auto it = sizeOfSeed.find(k); it != sizeOfSeed.end()) {
        ++seeds;
        EXPECT_EQ(it->second, keys.size()) << what << " " << toString(pair);
      }
    EXPECT_EQ(seeds, 1u) << what << " " << toString(pair);
  }
  EXPECT_EQ(boundaries, expected.size()) << what << " " << toString(pair);
}

}  // namespace

TEST(ScanBoundaryCounts, AreTheScannedComponentsOnEvery2x2x2And2x2x3Image) {
  for (AdjacencyPair pair : kAllAdjacencyPairs)
    for (Dims d : {Dims{2, 2, 2}, Dims{2, 2, 3}})
      for (const BinaryVolume& v : allImages(d))
        ASSERT_NO_FATAL_FAILURE(
            expectCountsAreComponents(binaryView(v), pair, d.nz == 2, "small", v.data()[0] + 2 * v.data()[5] == 3));
}

TEST(ScanBoundaryCounts, AreTheScannedComponentsOnRandomImagesForEveryThreadCount) {
  const std::vector<BinaryVolume> images = randomImages(1000, 4048);
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    for (std::size_t i = 0; i < images.size(); ++i)
      ASSERT_NO_FATAL_FAILURE(
          expectCountsAreComponents(binaryView(images[i]), pair, i % 10 == 0, "random", i % 4 == 0));
    for (Dims d : kWordBoundaryDims) {
      const BinaryVolume v = randomVolume(d, 0.5, 17 + d.nx);
      ASSERT_NO_FATAL_FAILURE(expectCountsAreComponents(binaryView(v), pair, true, "word boundaries"));
      ASSERT_NO_FATAL_FAILURE(expectCountsAreComponents(binaryView(v, /*outside=*/true), pair, false, "outside is 1"));
    }
    const NoisyPhantom sphere = makeNoisySphere(48, 0.05, 9);
    ASSERT_NO_FATAL_FAILURE(expectCountsAreComponents(sphere.binary(), pair, false, "sphere"));
  }
  // The generic path (operator() only) and an empty image.
  const BinaryVolume labels = randomVolume({20, 9, 7}, 0.5, 1);
  ASSERT_NO_FATAL_FAILURE(
      expectCountsAreComponents(LabelImage<std::uint8_t>(labels, 0), AdjacencyPair::k26_6, true, "label image"));
  EXPECT_TRUE(scanBoundaryCounts(binaryView(BinaryVolume({5, 4, 3}, 0)), AdjacencyPair::k6_26, 2).empty());
}
