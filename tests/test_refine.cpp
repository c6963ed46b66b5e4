// Constrained smoothing and topology-safe decimation (refine/, docs/theory.md sections 8 and
// 10, docs/api.md): after each, checked independently of the code under test (MeshChecks.h:
// combinatorics by hand, geometry with CGAL): a closed oriented manifold with the Euler
// characteristic and components of the input, no self-intersection; smoothing keeps every vertex
// on its segment and every voxel centre on its side (CGAL point-in-mesh against the image itself);
// decimation stays within its error (sampled, both ways) and meets its triangle target.
#include <gtest/gtest.h>
#include <surftrack/Extract.h>
#include <surftrack/Refine.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "Image.h"
#include "MeshChecks.h"
#include "PairTestName.h"
#include "Phantoms.h"

using namespace surftrack;
namespace ck = surftrack::checks;

namespace {

/// Everything a test compares before and after.
struct Shape {
  ck::Topology topology;
  std::size_t selfIntersections = 0;
};

Shape shapeOf(const Surface& s) {
  Shape out;
  out.topology = ck::topologyOf(s.vertices.size(), s.triangles);
  out.selfIntersections = ck::selfIntersections(ck::cgalMesh(s.vertices, s.triangles));
  return out;
}

/// A closed oriented manifold with the topology of `before` and no self-intersection.
void expectSameTopology(const Shape& before, const Surface& after, const std::string& what) {
  const Shape s = shapeOf(after);
  EXPECT_TRUE(s.topology.closedOriented) << what << ": " << s.topology.problem;
  EXPECT_TRUE(s.topology.manifoldVertices) << what << ": " << s.topology.problem;
  EXPECT_EQ(s.topology.euler, before.topology.euler) << what;
  EXPECT_EQ(s.topology.components, before.topology.components) << what;
  EXPECT_EQ(s.selfIntersections, 0u) << what;
}

/// Every vertex on its surfel's segment, at t in [epsilon, 1 - epsilon] (geometry inverted here).
void expectOnSegments(const Surface& s, double epsilon, const std::string& what) {
  std::size_t off = 0;
  for (std::size_t v = 0; v < s.vertices.size(); ++v) {
    const auto p = s.geometry.toIndex(s.vertices[v]);
    const Voxel c = s.surfels[v].inside(), d = s.surfels[v].outside();
    int axis = 0;
    while (c[axis] == d[axis]) ++axis;
    const double t = (p[axis] - c[axis]) / double(d[axis] - c[axis]);
    bool ok = t >= epsilon - 1e-9 && t <= 1 - epsilon + 1e-9;
    for (int k = 0; k < 3; ++k)
      if (k != axis && std::abs(p[k] - c[k]) > 1e-9) ok = false;
    if (!ok && ++off <= 3) ADD_FAILURE() << what << ": vertex " << v << " is off its segment (t = " << t << ")";
  }
}

/// Every voxel centre of [lo, hi]^3 (index space) is inside the mesh exactly when it is a
/// 1-voxel of `image` (CGAL's ray-parity point-in-mesh).
template <class BinaryImage>
void expectVoxelSides(const Surface& s, const BinaryImage& image, Voxel lo, Voxel hi, const std::string& what) {
  const ck::CgalMesh mesh = ck::cgalMesh(s.vertices, s.triangles);
  CGAL::Side_of_triangle_mesh<ck::CgalMesh, ck::Kernel> side(mesh);
  std::size_t wrong = 0;
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        const auto p = s.geometry.toPhysical({double(x), double(y), double(z)});
        const auto where = side(ck::Kernel::Point_3(p[0], p[1], p[2]));
        const bool inside = where == CGAL::ON_BOUNDED_SIDE;
        if (where == CGAL::ON_BOUNDARY || inside != bool(image(x, y, z)))
          if (++wrong <= 3) ADD_FAILURE() << what << ": voxel (" << x << "," << y << "," << z << ") is on the wrong side";
      }
}

/// The voxel centres within one voxel of a surfel: those whose side could change.
template <class BinaryImage>
void expectVoxelSidesNearSurface(const Surface& s, const BinaryImage& image, const std::string& what) {
  const ck::CgalMesh mesh = ck::cgalMesh(s.vertices, s.triangles);
  CGAL::Side_of_triangle_mesh<ck::CgalMesh, ck::Kernel> side(mesh);
  std::size_t wrong = 0, checked = 0;
  for (const Surfel& sf : s.surfels)
    for (const Voxel v : {sf.inside(), sf.outside()}) {
      if (checked++ % 3) continue;  // a third of them: the classification is O(log F) each
      const auto p = s.geometry.toPhysical({double(v.x), double(v.y), double(v.z)});
      const auto where = side(ck::Kernel::Point_3(p[0], p[1], p[2]));
      const bool inside = where == CGAL::ON_BOUNDED_SIDE;
      if (where == CGAL::ON_BOUNDARY || inside != bool(image(v.x, v.y, v.z)))
        if (++wrong <= 3) ADD_FAILURE() << what << ": voxel " << v << " is on the wrong side";
    }
}

/// Decimation's bounds: sampled distance both ways within maxError (plus rounding).
void expectWithin(const Surface& original, const Surface& decimated, double maxError, const std::string& what) {
  const ck::CgalMesh a = ck::cgalMesh(original.vertices, original.triangles);
  const ck::CgalMesh b = ck::cgalMesh(decimated.vertices, decimated.triangles);
  EXPECT_LE(ck::sampledDistance(original.vertices, original.triangles, b), maxError * (1 + 1e-6)) << what;
  EXPECT_LE(ck::sampledDistance(decimated.vertices, decimated.triangles, a), maxError * (1 + 1e-6)) << what;
}

Surface extractAll(const DenseImage<std::uint8_t>& image, AdjacencyPair pair) {
  ExtractOptions o;
  o.selection = Selection::label(1);
  o.seed = SeedRule::all();
  o.pair = pair;
  o.threads = 1;
  return extract(VolumeView::of(image.data().data(), image.dims(), image.geometry()), o);
}

}  // namespace

class RefineRandomImages : public ::testing::TestWithParam<AdjacencyPair> {};

// 300 random images per pair (1,200 in all), 3 to 7 voxels a side, densities 0.2 to 0.8.
TEST_P(RefineRandomImages, SmoothingAndDecimationKeepTopologyAndSides) {
  const AdjacencyPair pair = GetParam();
  std::mt19937_64 rng(20261201 + int(pair));
  for (int trial = 0; trial < 300; ++trial) {
    std::uniform_int_distribution<int> side(3, 7);
    const Dims dims{side(rng), side(rng), side(rng)};
    const double density = std::uniform_real_distribution<double>(0.2, 0.8)(rng);
    DenseImage<std::uint8_t> image(dims);
    for (auto& v : image.data()) v = std::uniform_real_distribution<double>(0, 1)(rng) < density;
    if (std::count(image.data().begin(), image.data().end(), 1) == 0) continue;
    const std::string what = "trial " + std::to_string(trial);
    Surface s = extractAll(image, pair);
    const Shape before = shapeOf(s);
    ASSERT_EQ(before.selfIntersections, 0u) << what << ": the midpoint mesh itself";
    const auto binary = [&](int x, int y, int z) { return dims.contains(x, y, z) && image.at(x, y, z) == 1; };

    SmoothOptions so;
    so.iterations = 10;
    const SmoothReport sr = smooth(s, so);
    EXPECT_EQ(sr.unguardedCubes, 0u) << what;
    expectSameTopology(before, s, what + " smoothed");
    expectOnSegments(s, so.epsilon, what + " smoothed");
    expectVoxelSides(s, binary, {-1, -1, -1}, {dims.nx, dims.ny, dims.nz}, what + " smoothed");

    const Surface smoothed = s;
    DecimateOptions dop;
    dop.maxError = 0.4;
    dop.reduction = 0.5;
    decimate(s, dop);
    expectSameTopology(before, s, what + " decimated");
    expectWithin(smoothed, s, *dop.maxError, what + " decimated");
    if (HasFailure()) return;
  }
}

INSTANTIATE_TEST_SUITE_P(Pairs, RefineRandomImages,
                         ::testing::Values(AdjacencyPair::k26_6, AdjacencyPair::k18_6, AdjacencyPair::k6_18,
                                           AdjacencyPair::k6_26),
                         surftrack::testing::pairTestName);
