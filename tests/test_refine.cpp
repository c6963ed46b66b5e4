// Constrained smoothing and topology-safe decimation (refine/, docs/theory.md sections 8 and
// 10, docs/api.md): after each, checked independently of the code under test (CgalMeshChecks.h:
// combinatorics by hand, geometry with CGAL): a closed oriented manifold with the Euler
// characteristic and components of the input, no self-intersection; smoothing keeps every vertex
// on its segment and every voxel centre on its side (CGAL point-in-mesh against the image itself);
// decimation stays within its error (sampled, both ways) and meets its triangle target.
#include <gtest/gtest.h>
#include <surftrack/Extract.h>
#include <surftrack/Refine.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "CaseSubset.h"
#include "CgalMeshChecks.h"
#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "FoldCertificate.h"
#include "Image.h"
#include "PairTestName.h"
#include "Phantoms.h"
#include "TrianglesByCube.h"

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
  out.selfIntersections = ck::selfIntersections(s.vertices, s.triangles);
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
  const ck::SideOfMesh side(s.vertices, s.triangles);
  std::size_t wrong = 0;
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        const auto p = s.geometry.toPhysical({double(x), double(y), double(z)});
        const ck::Side where = side({p[0], p[1], p[2]});
        const bool inside = where == ck::Side::Inside;
        if (where == ck::Side::Boundary || inside != bool(image(x, y, z)))
          if (++wrong <= 3) ADD_FAILURE() << what << ": voxel (" << x << "," << y << "," << z << ") is on the wrong side";
      }
}

/// The voxel centres within one voxel of a surfel: those whose side could change.
template <class BinaryImage>
void expectVoxelSidesNearSurface(const Surface& s, const BinaryImage& image, const std::string& what) {
  const ck::SideOfMesh side(s.vertices, s.triangles);
  std::size_t wrong = 0, checked = 0;
  for (const Surfel& sf : s.surfels)
    for (const Voxel v : {sf.inside(), sf.outside()}) {
      if (checked++ % 3) continue;  // a third of them: the classification is O(log F) each
      const auto p = s.geometry.toPhysical({double(v.x), double(v.y), double(v.z)});
      const ck::Side where = side({p[0], p[1], p[2]});
      const bool inside = where == ck::Side::Inside;
      if (where == ck::Side::Boundary || inside != bool(image(v.x, v.y, v.z)))
        if (++wrong <= 3) ADD_FAILURE() << what << ": voxel " << v << " is on the wrong side";
    }
}

/// Decimation's bounds: sampled distance both ways within maxError (plus rounding).
void expectWithin(const Surface& original, const Surface& decimated, double maxError, const std::string& what) {
  const Surface &a = original, &b = decimated;
  EXPECT_LE(ck::sampledDistance(a.vertices, a.triangles, b.vertices, b.triangles), maxError * (1 + 1e-6)) << what;
  EXPECT_LE(ck::sampledDistance(b.vertices, b.triangles, a.vertices, a.triangles), maxError * (1 + 1e-6)) << what;
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
    if (!surftrack::testing::caseChecked(std::uint64_t(trial))) continue;
    const std::string what = "trial " + std::to_string(trial);
    Surface s = extractAll(image, pair);
    const Shape before = shapeOf(s);
    ASSERT_EQ(before.selfIntersections, 0u) << what << ": the midpoint mesh itself";
    const auto binary = [&](int x, int y, int z) { return dims.contains(x, y, z) && image.at(x, y, z) == 1; };

    SmoothOptions so;
    so.iterations = 10;
    const Surface unsmoothed = s;
    const SmoothReport sr = smooth(s, so);
    EXPECT_EQ(sr.unguardedCubes, 0u) << what;
    // Smoothing moves points only: the triangles and the surfels of the vertices are the same.
    EXPECT_EQ(s.triangles, unsmoothed.triangles) << what;
    EXPECT_EQ(s.surfels, unsmoothed.surfels) << what;
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

namespace {

/// Smooths, then decimates, `s` (extracted from `binary`) and checks both results; returns the
/// decimated surface's figures for further checks.
template <class BinaryImage>
void checkSmoothThenDecimate(Surface s, const BinaryImage& binary, double maxError, std::optional<double> reduction,
                             const std::string& what) {
  const Shape before = shapeOf(s);
  ASSERT_TRUE(before.topology.closedOriented) << what << ": " << before.topology.problem;
  const std::size_t intersectionsBefore = before.selfIntersections;
  SmoothOptions so;
  const SmoothReport sr = smooth(s, so);
  Shape expected = before;
  expected.selfIntersections = 0;
  const Shape after = shapeOf(s);
  EXPECT_TRUE(after.topology.closedOriented) << what << ": " << after.topology.problem;
  EXPECT_TRUE(after.topology.manifoldVertices) << what << ": " << after.topology.problem;
  EXPECT_EQ(after.topology.euler, before.topology.euler) << what;
  EXPECT_EQ(after.topology.components, before.topology.components) << what;
  // Cubes not embedded in the input are not guarded; none may be added.
  if (sr.unguardedCubes == 0) EXPECT_EQ(after.selfIntersections, 0u) << what << " smoothed";
  else EXPECT_LE(after.selfIntersections, intersectionsBefore) << what << " smoothed";
  expectOnSegments(s, so.epsilon, what + " smoothed");
  expectVoxelSidesNearSurface(s, binary, what + " smoothed");
  EXPECT_GT(sr.maxDisplacement, 0) << what;

  const Surface smoothed = s;
  DecimateOptions dop;
  dop.maxError = maxError;
  dop.reduction = reduction;
  const DecimateReport dr = decimate(s, dop);
  EXPECT_LT(dr.trianglesAfter, dr.trianglesBefore) << what;
  const Shape decimated = shapeOf(s);
  EXPECT_TRUE(decimated.topology.closedOriented) << what << ": " << decimated.topology.problem;
  EXPECT_TRUE(decimated.topology.manifoldVertices) << what << ": " << decimated.topology.problem;
  EXPECT_EQ(decimated.topology.euler, before.topology.euler) << what;
  EXPECT_EQ(decimated.topology.components, before.topology.components) << what;
  EXPECT_EQ(decimated.selfIntersections, 0u) << what << " decimated";
  expectWithin(smoothed, s, maxError, what + " decimated");
  // Survivors are still surfels, on their segments.
  expectOnSegments(s, so.epsilon, what + " decimated");
}

template <class T>
Surface extractFrom(const DenseImage<T>& image, Selection selection, SeedRule seed, Mapping mapping = Mapping::Default) {
  ExtractOptions o;
  o.selection = selection;
  o.seed = seed;
  o.mapping = mapping;
  o.threads = 1;
  return extract(VolumeView::of(image.data().data(), image.dims(), image.geometry()), o);
}

}  // namespace

// The noisy sphere of Figure 9 (q = 64, 1 % noise): every boundary, midpoint and linear mappings.
TEST(RefineVolumes, Figure9NoisySphere) {
  const NoisyPhantom p = makeNoisySphere(surftrack::testing::inputSize(64, 32), 0.01);
  const auto binary = p.binary();
  checkSmoothThenDecimate(extractFrom(p.image, Selection::threshold(p.iso), SeedRule::all(), Mapping::Midpoint),
                          binary, 0.5, 0.8, "sphere, midpoint");
  checkSmoothThenDecimate(extractFrom(p.image, Selection::threshold(p.iso), SeedRule::all(), Mapping::Linear),
                          binary, 0.5, std::nullopt, "sphere, linear");
}

// The demo's phantom (sphere minus three cylinders, genus 5), anisotropic and mirrored geometry.
TEST(RefineVolumes, DemoPhantomInAMirroredAnisotropicFrame) {
  SphereMinusCylinders p = makeSphereMinusCylinders(48, 0.01);
  ImageGeometry g;
  g.spacing = {0.8, 1.0, 1.3};
  g.origin = {10, -5, 3};
  g.direction = {{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  p.image.geometry() = g;
  const auto binary = p.binary();
  Surface s = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::fromSurfel(p.seed), Mapping::Midpoint);
  EXPECT_EQ(componentFigures(s.vertices, s.triangles).front().genus(), 5.0);
  checkSmoothThenDecimate(s, binary, 0.6, 0.9, "phantom");
}

// The decimation's triangle target, with no error bound: met within 5 %.
TEST(RefineVolumes, DecimationMeetsItsTarget) {
  const NoisyPhantom p = makeNoisySphere(48, 0.0);
  for (double reduction : {0.5, 0.75, 0.9}) {
    Surface s = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
    smooth(s, {});
    DecimateOptions d;
    d.reduction = reduction;
    const DecimateReport r = decimate(s, d);
    const double target = (1 - reduction) * double(r.trianglesBefore);
    EXPECT_NEAR(double(s.triangles.size()), target, 0.05 * target) << "reduction " << reduction;
    const Shape shape = shapeOf(s);
    EXPECT_EQ(shape.topology.euler, 2);
    EXPECT_EQ(shape.selfIntersections, 0u);
  }
}

// Smoothing's passes are Jacobi updates (docs/theory.md, section 8), run in parallel: the
// result is the same, bit for bit, on any number of threads. The noisy sphere of Figure 9 with
// the linear mapping, on 1, 2 and 3 threads (more than the cores, on small machines) and all
// cores.
TEST(RefineVolumes, SmoothingIsTheSameOnAnyNumberOfThreads) {
  const NoisyPhantom p = makeNoisySphere(64, 0.01);
  const Surface input = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Linear);
  ASSERT_GE(input.vertices.size(), 4096u);  // enough vertices for the passes to run in parallel
  SmoothOptions so;
  so.threads = 1;
  Surface one = input;
  const SmoothReport r1 = smooth(one, so);
  for (int threads : {2, 3, 0}) {
    so.threads = threads;
    Surface s = input;
    const SmoothReport r = smooth(s, so);
    EXPECT_TRUE(s.vertices == one.vertices) << threads << " threads";
    EXPECT_EQ(r.stepsBack, r1.stepsBack) << threads << " threads";
    EXPECT_EQ(r.maxDisplacement, r1.maxDisplacement) << threads << " threads";
  }
  so.threads = -1;
  Surface s = input;
  EXPECT_THROW(smooth(s, so), InvalidInput);
}

TEST(RefineErrors, BadOptionsAndInputsThrowInvalidInput) {
  const NoisyPhantom p = makeNoisySphere(16, 0.0);
  Surface s = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
  SmoothOptions bad;
  bad.lambda = 0;
  EXPECT_THROW(smooth(s, bad), InvalidInput);
  bad = {};
  bad.mu = -0.4;  // not below -lambda
  EXPECT_THROW(smooth(s, bad), InvalidInput);
  bad = {};
  bad.epsilon = 0.5;
  EXPECT_THROW(smooth(s, bad), InvalidInput);
  EXPECT_THROW(decimate(s, {}), InvalidInput);  // neither bound nor target
  DecimateOptions d;
  d.reduction = 1.0;
  EXPECT_THROW(decimate(s, d), InvalidInput);
  d.reduction = std::nullopt;
  d.maxError = -1;
  EXPECT_THROW(decimate(s, d), InvalidInput);
  // A decimated surface is no longer a continuous analog: its triangles leave their cubes.
  d.maxError = 1.0;
  decimate(s, d);
  EXPECT_THROW(smooth(s, {}), InvalidInput);
  // A vertex moved off its segment.
  Surface t = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
  t.vertices[0][0] += 0.25;
  t.vertices[0][1] += 0.25;
  t.vertices[0][2] += 0.25;
  EXPECT_THROW(smooth(t, {}), InvalidInput);
  // A surfel with no direction of Z^3 (Surfel::fromKey decodes 6 and 7 from a bad key).
  Surface u = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
  u.surfels[3].n = 6;
  EXPECT_THROW(smooth(u, {}), InvalidInput);
}

namespace {

/// Runs `f` while another thread raises `flag` after `delay`; the seconds `f` took, or
/// nothing if it threw no Cancelled (a failure is then reported).
template <class F>
std::optional<double> secondsToCancel(std::atomic<bool>& flag, std::chrono::milliseconds delay, F&& f) {
  flag = false;
  std::thread raiser([&] {
    std::this_thread::sleep_for(delay);
    flag = true;
  });
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::optional<double> seconds;
  try {
    f();
    ADD_FAILURE() << "no Cancelled: ran to its end in " << elapsed() << " s";
  } catch (const Cancelled&) {
    seconds = elapsed();
  }
  raiser.join();
  return seconds;
}

}  // namespace

// Cancellation (lib/Cancellation.h, docs/api.md "Errors"): a flag raised from another thread
// while smooth() or decimate() runs stops it with Cancelled at its next check (every pass,
// every few thousand collapse candidates), the surface left as it was. Uninterrupted, the
// smoothing (20000 iterations of a 7,000-vertex sphere) runs for about seven seconds and the
// decimation (a 100,000-triangle sphere to 0.1 %) for about five on this project's machines;
// raised after a fifth of a second, the flag must stop them with Cancelled before their end
// (how soon is a speed, measured by no test: secondsToCancel reports it on failure only).
TEST(RefineCancel, ARaisedFlagStopsSmoothingAndDecimation) {
  std::atomic<bool> cancel{false};
  {
    const NoisyPhantom p = makeNoisySphere(48, 0.0);
    const Surface input = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
    SmoothOptions so;
    so.iterations = 20000;
    so.threads = 1;
    so.cancel = &cancel;
    Surface s = input;
    const auto seconds = secondsToCancel(cancel, std::chrono::milliseconds(200), [&] { smooth(s, so); });
    ASSERT_TRUE(seconds);
    EXPECT_TRUE(s.vertices == input.vertices);
    // Raised before: nothing runs.
    EXPECT_THROW(smooth(s, so), Cancelled);
    RefineOptions ro;
    ro.smooth = so;
    EXPECT_THROW(refineSurface(s, ro), Cancelled);
    EXPECT_TRUE(s.vertices == input.vertices);
    // The count itself is bounded, as the CLI's --smooth and Python's smooth= are.
    so.cancel = nullptr;
    so.iterations = kMaxSmoothIterations + 1;
    EXPECT_THROW(smooth(s, so), InvalidInput);
  }
  {
    const NoisyPhantom p = makeNoisySphere(128, 0.0);
    const Surface input = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
    ASSERT_GT(input.triangles.size(), 90000u);
    DecimateOptions d;
    d.reduction = 0.999;
    d.cancel = &cancel;
    Surface s = input;
    const auto seconds = secondsToCancel(cancel, std::chrono::milliseconds(200), [&] { decimate(s, d); });
    ASSERT_TRUE(seconds);
    EXPECT_TRUE(s.vertices == input.vertices && s.triangles == input.triangles);
    EXPECT_THROW(decimate(s, d), Cancelled);
    RefineOptions ro;
    ro.decimate = d;
    EXPECT_THROW(refineSurface(s, ro), Cancelled);
    EXPECT_TRUE(s.triangles == input.triangles);
  }
}

#ifdef SURFTRACK_TEST_MRICRON
#include <filesystem>

#include "ReadVolume.h"

namespace {

/// The block [lo, lo + size) of `image`, with the geometry that keeps its voxels in place.
template <class T>
DenseImage<T> crop(const DenseImage<T>& image, Voxel lo, int size) {
  DenseImage<T> out(Dims{size, size, size});
  for (int z = 0; z < size; ++z)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) out.at(x, y, z) = image.at(lo.x + x, lo.y + y, lo.z + z);
  out.geometry() = image.geometry();
  out.geometry().origin = image.geometry().toPhysical({double(lo.x), double(lo.y), double(lo.z)});
  return out;
}

}  // namespace

// A 56^3 block of the Colin27 MRI (ch2better.nii.gz, 0.5 mm, mirrored frame) through the
// cortex: every boundary at the demo's iso-value 100, linear mapping.
TEST(RefineVolumes, MriCortexBlock) {
  const std::string path = std::string(SURFTRACK_TEST_MRICRON) + "/ch2better.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not installed (mricron-data)";
  const auto volume = std::get<DenseImage<std::uint8_t>>(io::readVolume(path));
  const DenseImage<std::uint8_t> block = crop(volume, {118, 158, 208}, surftrack::testing::inputSize(56, 32));
  const ThresholdImage<std::uint8_t> binary(block, 100.0);
  checkSmoothThenDecimate(extractFrom(block, Selection::threshold(100), SeedRule::all()), binary, 0.25, 0.7,
                          "MRI block");
}

// An atlas label (aal.nii.gz, label 1: the left precentral gyrus), the whole region.
TEST(RefineVolumes, AtlasLabel) {
  const std::string path = std::string(SURFTRACK_TEST_MRICRON) + "/aal.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not installed (mricron-data)";
  const io::AnyVolume volume = io::readVolume(path);
  std::visit(
      [&](const auto& image) {
        using T = typename std::decay_t<decltype(image)>::value_type;
        const LabelImage<T> binary(image, T(1));
        checkSmoothThenDecimate(extractFrom(image, Selection::label(1), SeedRule::largest()), binary, 0.5, 0.8,
                                "AAL label 1");
      },
      volume);
}
#endif

// The fold certificates (refine/FoldCertificate.h, docs/theory.md section 8) against CGAL:
// every triangle and pair of triangles of a configuration-table entry (the four pairs, all 256
// configurations) that has a certificate is checked at every corner of its box of parameters
// and at random points of it (fixed seed): a certified triangle keeps the side of its
// reference normal (CGAL's exact orientation), a certified pair does not self-intersect as a
// two-triangle mesh (CGAL's self_intersections, which accepts what the two share).
TEST(FoldCertificates, HoldAtEveryPositionInTheirBoxes) {
  const double epsilon = SmoothOptions{}.epsilon;
  refine::FoldCertificates certificates(epsilon);
  using Edges = refine::CubeEdges;
  auto at = [](int k, double tau) {
    const Voxel low = cube::cornerOffset(cube::edgeLowCorner(k));
    std::array<double, 3> p{double(low.x), double(low.y), double(low.z)};
    p[cube::edgeAxis(k)] += tau;
    return p;
  };
  std::set<Edges> triangles;
  std::set<std::pair<Edges, Edges>> pairs;
  for (AdjacencyPair pair : {AdjacencyPair::k26_6, AdjacencyPair::k18_6, AdjacencyPair::k6_18, AdjacencyPair::k6_26})
    for (const CubeTriangulation& entry : configurationTables(pair)) {
      const auto all = entry.allTriangles();
      for (std::size_t i = 0; i < all.size(); ++i) {
        triangles.insert(all[i]);
        for (std::size_t j = i + 1; j < all.size(); ++j) pairs.insert({all[i], all[j]});
      }
    }
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> tau(epsilon, 1 - epsilon);
  auto position = [&](int sample, int slot) {  // the corners first, then random points
    return sample < 64 ? (sample >> slot & 1 ? 1 - epsilon : epsilon) : tau(rng);
  };
  std::size_t certain = 0, uncertain = 0;
  for (const Edges& t : triangles) {
    if (!certificates.triangleIsCertain(t)) {
      ++uncertain;
      continue;
    }
    ++certain;
    const auto m0 = at(t[0], 0.5), m1 = at(t[1], 0.5), m2 = at(t[2], 0.5);
    // The reference normal in doubles, as CGAL's inexact constructions compute it.
    const ck::Point u{m1[0] - m0[0], m1[1] - m0[1], m1[2] - m0[2]}, w{m2[0] - m0[0], m2[1] - m0[1], m2[2] - m0[2]};
    const ck::Point reference{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    for (int sample = 0; sample < 8 + 32; ++sample) {
      const int s = sample < 8 ? sample : 64 + sample;
      const auto a = at(t[0], position(s, 0)), b = at(t[1], position(s, 1)), c = at(t[2], position(s, 2));
      const ck::Point d{a[0] + reference[0], a[1] + reference[1], a[2] + reference[2]};
      ASSERT_EQ(ck::orientation(a, b, c, d), 1)
          << "triangle " << int(t[0]) << "," << int(t[1]) << "," << int(t[2]);
    }
  }
  EXPECT_GT(certain, 0u);
  for (const auto& [t, u] : pairs) {
    if (!certificates.pairIsCertain(t, u)) {
      ++uncertain;
      continue;
    }
    ++certain;
    // The distinct edges of the pair, each a vertex of the two-triangle mesh.
    std::vector<std::uint8_t> edges;
    for (const Edges* x : {&t, &u})
      for (std::uint8_t e : *x)
        if (std::find(edges.begin(), edges.end(), e) == edges.end()) edges.push_back(e);
    auto index = [&](std::uint8_t e) { return std::uint32_t(std::find(edges.begin(), edges.end(), e) - edges.begin()); };
    const ck::Triangles faces{{index(t[0]), index(t[1]), index(t[2])}, {index(u[0]), index(u[1]), index(u[2])}};
    for (int sample = 0; sample < 64 + 16; ++sample) {
      if (sample < 64 && sample >= (1 << edges.size())) continue;
      ck::Points points;
      for (std::size_t k = 0; k < edges.size(); ++k) {
        const auto p = at(edges[k], position(sample, int(k)));
        points.push_back(p);
      }
      ASSERT_EQ(ck::selfIntersections(points, faces), 0u)
          << "pair " << int(t[0]) << "," << int(t[1]) << "," << int(t[2]) << " / " << int(u[0]) << "," << int(u[1])
          << "," << int(u[2]) << " at sample " << sample;
    }
  }
  // Not everything is certain: some pairs of the tables can fold, and are left to the check.
  EXPECT_GT(uncertain, 0u);
}

// refineSurface: smooth() then decimate(), the progress before each, the reports of both.
TEST(RefineSurface, SmoothsThenDecimatesAsTheTwoCalls) {
  const NoisyPhantom p = makeNoisySphere(24, 0.0);
  const Surface extracted = extractFrom(p.image, Selection::threshold(p.iso), SeedRule::largest(), Mapping::Midpoint);
  Surface one = extracted, two = extracted;
  DecimateOptions d;
  d.maxError = 0.5;
  smooth(one, {});
  decimate(one, d);
  RefineOptions o;
  o.smooth = SmoothOptions{};
  o.decimate = d;
  std::vector<std::string> stages;
  o.progress = [&](const ProgressEvent& e) { stages.push_back(e.stage + std::to_string(e.index) + std::to_string(e.stages)); };
  const RefineReport r = refineSurface(two, o);
  EXPECT_EQ(stages, (std::vector<std::string>{"smooth02", "decimate12"}));
  EXPECT_EQ(two.triangles, one.triangles);
  EXPECT_EQ(two.vertices, one.vertices);
  ASSERT_TRUE(r.smooth && r.decimate);
  EXPECT_EQ(r.volumeBefore, r.smooth->volumeBefore);
  EXPECT_EQ(r.volumeAfter, r.decimate->volumeAfter);
  EXPECT_LT(r.decimate->trianglesAfter, r.decimate->trianglesBefore);
  // Nothing asked: nothing changes.
  Surface three = extracted;
  const RefineReport none = refineSurface(three, {});
  EXPECT_FALSE(none.smooth || none.decimate);
  EXPECT_EQ(three.vertices, extracted.vertices);
}

// groupTrianglesByCube (the fold check's grouping, refine/TrianglesByCube.h) against a std::map
// of the corners: the same groups, numbered in the order of their first triangles, each listing
// its triangles in increasing order; corners near together (one packed key and one or two radix
// passes, or three), negative ones, and ones too far apart for a 64-bit key (the comparison
// sort), among them x and y over all of int with z constant (widths 32, 32, 0).
TEST(TrianglesByCube, GroupsAsAMapOfTheCornersDoes) {
  std::mt19937 rng(20261202);
  constexpr int kSpread[] = {3, 100, 1000, 1 << 30};
  for (int trial = 0; trial < 400; ++trial) {
    const int spread = kSpread[trial % 5 == 4 ? 3 : trial % 4];
    const bool flatZ = trial % 5 == 4;  // x, y over all of int, z constant
    std::uniform_int_distribution<int> coordinate(flatZ ? std::numeric_limits<int>::min() : -spread,
                                                  flatZ ? std::numeric_limits<int>::max() : spread);
    const std::size_t n = std::size_t(rng() % 2000);
    std::vector<Voxel> corner(n);
    for (std::size_t f = 0; f < n; ++f) {
      // Repeat earlier corners often, so that groups have several triangles.
      if (f > 0 && rng() % 2)
        corner[f] = corner[rng() % f];
      else
        corner[f] = {coordinate(rng), coordinate(rng), flatZ ? 7 : coordinate(rng)};
    }
    std::map<std::tuple<int, int, int>, std::uint32_t> number;
    std::vector<std::vector<std::uint32_t>> members;
    for (std::size_t f = 0; f < n; ++f) {
      const auto [it, added] = number.try_emplace({corner[f].x, corner[f].y, corner[f].z}, std::uint32_t(members.size()));
      if (added) members.emplace_back();
      members[it->second].push_back(std::uint32_t(f));
    }
    const refine::Lists got = refine::groupTrianglesByCube(corner);
    ASSERT_EQ(got.size(), members.size()) << "trial " << trial;
    for (std::size_t c = 0; c < members.size(); ++c) {
      const auto list = got[c];
      ASSERT_EQ(std::vector<std::uint32_t>(list.begin(), list.end()), members[c]) << "trial " << trial << " cube " << c;
    }
  }
}
