// The front door (core/, docs/api.md): extract() over views and sources, against the engine
// called directly and against counts computed here from the voxels; what it reads and allocates
// on a seeded path; its typed errors, progress and cancellation.
#include <gtest/gtest.h>

#include <surftrack/Extract.h>
#include <surftrack/Labels.h>
#include <surftrack/Refine.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <new>
#include <random>
#include <vector>

#include "Image.h"
#include "LoopExtraction.h"
#include "FindSeed.h"
#include "TrackComponent.h"

using namespace surftrack;

// Every allocation of this test program is counted, so that a test can measure the peak of the
// bytes allocated while extract() runs (an independent check that a seeded extraction over a
// view allocates nothing proportional to the volume).
namespace {
std::atomic<std::size_t> gLive{0}, gPeak{0};
}  // namespace
void* operator new(std::size_t n) {
  void* p = std::malloc(n + 16);
  if (!p) throw std::bad_alloc();
  *static_cast<std::size_t*>(p) = n;
  const std::size_t live = gLive += n;
  for (std::size_t peak = gPeak; live > peak && !gPeak.compare_exchange_weak(peak, live);) {}
  return static_cast<char*>(p) + 16;
}
void operator delete(void* p) noexcept {
  if (!p) return;
  char* base = static_cast<char*>(p) - 16;
  gLive -= *reinterpret_cast<std::size_t*>(base);
  std::free(base);
}
void operator delete(void* p, std::size_t) noexcept { operator delete(p); }
// The other forms, so that every block is made and freed by the pair above (the sanitizer
// runtime would otherwise serve, say, the nothrow form that std::stable_sort uses).
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return operator new(n);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete[](void* p) noexcept { operator delete(p); }
void operator delete[](void* p, std::size_t) noexcept { operator delete(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { operator delete(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { operator delete(p); }

namespace {

/// A gray ball f = 50 + 20 (r - |x - c|), with noise specks (one voxel in 50 flipped) unless
/// `seed` is 0, of type T.
template <class T>
std::vector<T> noisyBall(Dims d, double r, unsigned seed) {
  std::vector<T> v(d.count());
  std::mt19937 rng(seed);
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x) {
        const double dist = std::sqrt((x - d.nx / 2.0) * (x - d.nx / 2.0) + (y - d.ny / 2.0) * (y - d.ny / 2.0) +
                                      (z - d.nz / 2.0) * (z - d.nz / 2.0));
        double f = std::clamp(50 + 20 * (r - dist), 0.0, 120.0);
        if (seed && rng() % 50 == 0) f = 120 - f;
        v[(std::size_t(z) * d.ny + y) * d.nx + x] = T(f);
      }
  return v;
}

/// The number of 6-adjacent (selected, not selected) voxel pairs, the domain border included.
template <class T>
std::size_t boundaryPairs(const std::vector<T>& v, Dims d, double s) {
  auto on = [&](int x, int y, int z) { return d.contains(x, y, z) && double(v[(std::size_t(z) * d.ny + y) * d.nx + x]) > s; };
  std::size_t n = 0;
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x)
        if (on(x, y, z))
          for (Direction k = 0; k < 6; ++k) {
            const Voxel u = Voxel{x, y, z} + unitVector(k);
            n += !on(u.x, u.y, u.z);
          }
  return n;
}

/// A source that counts the voxels it is asked for.
class CountingSource final : public VoxelSource {
 public:
  explicit CountingSource(const VoxelSource& inner) : inner_(inner) {}
  Dims dims() const override { return inner_.dims(); }
  ImageGeometry geometry() const override { return inner_.geometry(); }
  ScalarType type() const override { return inner_.type(); }
  void binaryBlock(const Selection& s, Voxel o, int w, int ny, int nz, std::uint16_t* out) const override {
    read += std::size_t(w) * ny * nz;
    inner_.binaryBlock(s, o, w, ny, nz, out);
  }
  std::uint64_t binaryRow(const Selection& s, Voxel start, int count) const override {
    read += std::size_t(count);
    return inner_.binaryRow(s, start, count);
  }
  void values(const Voxel* v, std::size_t n, double* out) const override {
    read += n;
    inner_.values(v, n, out);
  }
  mutable std::size_t read = 0;

 private:
  const VoxelSource& inner_;
};

TEST(FrontDoor, EveryScalarTypeAndTheEngineGiveTheSameSurface) {
  const Dims d{23, 20, 17};
  const std::vector<std::uint8_t> ref = noisyBall<std::uint8_t>(d, 6, 1);
  ExtractOptions o;
  o.selection = Selection::threshold(60.5);
  o.seed = SeedRule::all();
  o.mapping = Mapping::Midpoint;
  const Surface base = extract(VolumeView::of(ref.data(), d), o);
  EXPECT_EQ(base.surfels.size(), boundaryPairs(ref, d, 60.5));
  EXPECT_GT(base.components.size(), 1u);  // the ball and the noise specks

  // The engine, called directly on the same image.
  const DenseImage<std::uint8_t> dense = [&] {
    DenseImage<std::uint8_t> im(d);
    std::copy(ref.begin(), ref.end(), im.data().begin());
    return im;
  }();
  const ThresholdImage<std::uint8_t> binary(dense, 60.5);
  o.seed = SeedRule::largest();
  const Surface largest = extract(VolumeView::of(ref.data(), d), o);
  const TriangleMesh direct = extractLoops(trackComponent(binary, *largest.seed.surfel, AdjacencyPair::k26_6));
  EXPECT_EQ(largest.surfels, direct.surfels);
  EXPECT_EQ(largest.triangles, direct.triangles);

  auto same = [&](auto zero) {
    using T = decltype(zero);
    std::vector<T> v(ref.begin(), ref.end());
    ExtractOptions all = o;
    all.seed = SeedRule::all();
    const Surface s = extract(VolumeView::of(v.data(), d), all);
    EXPECT_EQ(s.surfels, base.surfels) << toString(scalarTypeOf<T>());
    EXPECT_EQ(s.triangles, base.triangles) << toString(scalarTypeOf<T>());
  };
  same(std::int8_t{}), same(std::uint16_t{}), same(std::int16_t{}), same(std::uint32_t{});
  same(std::int32_t{}), same(std::uint64_t{}), same(std::int64_t{}), same(float{}), same(double{});

  // A function source of the same values gives the same surface.
  const auto f = makeFunctionSource(d, [&](int x, int y, int z) { return double(dense.at(x, y, z)); });
  o.seed = SeedRule::all();
  const Surface fs = extract(*f, o);
  EXPECT_EQ(fs.surfels, base.surfels);
  EXPECT_EQ(fs.triangles, base.triangles);
}

TEST(FrontDoor, StridedViewsReadTheSameVoxels) {
  const Dims d{19, 21, 18};
  const std::vector<float> ref = noisyBall<float>(d, 7, 2);
  // The same volume with x running backwards and y with a gap of 3 elements per row.
  const std::ptrdiff_t sy = d.nx + 3, sz = sy * d.ny;
  std::vector<float> padded(std::size_t(sz) * d.nz, -1.0f);
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x) padded[z * sz + y * sy + (d.nx - 1 - x)] = ref[(std::size_t(z) * d.ny + y) * d.nx + x];
  ExtractOptions o;
  o.selection = Selection::threshold(60);
  o.seed = SeedRule::all();
  const Surface a = extract(VolumeView::of(ref.data(), d), o);
  const Surface b = extract(VolumeView::strided(padded.data() + d.nx - 1, d, {-1, sy, sz}), o);
  EXPECT_EQ(a.surfels, b.surfels);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.vertices, b.vertices);
}

TEST(FrontDoor, ASeededExtractionReadsAndAllocatesOnlyNearTheSurface) {
  // 256 MiB of voxels, one ball of radius 20 in it.
  const Dims d{1024, 512, 512};
  std::vector<std::uint8_t> volume(d.count(), 0);
  const int c = 256, r = 20;
  for (int z = c - r; z <= c + r; ++z)
    for (int y = c - r; y <= c + r; ++y)
      for (int x = c - r; x <= c + r; ++x)
        if ((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c) <= r * r)
          volume[(std::size_t(z) * d.ny + y) * d.nx + x] = 200;
  const auto view = makeViewSource(VolumeView::of(volume.data(), d));
  const CountingSource counting(*view);
  ExtractOptions o;
  o.selection = Selection::threshold(100);
  o.seed = SeedRule::fromVoxel({c, c, c});
  const std::size_t before = gLive;
  gPeak = before;
  const Surface s = extract(counting, o);
  const std::size_t peak = gPeak - before;
  EXPECT_EQ(s.euler, 2);
  // Reads: the bricks around the surface (1000 voxels each), the walk to it, the gray values.
  EXPECT_LT(counting.read, 100 * s.surfels.size()) << counting.read << " voxels read";
  // Memory: a few hundred bytes per surfel, nothing near the 256 MiB of the volume.
  EXPECT_LT(peak, 1000 * s.surfels.size()) << peak << " bytes for " << s.surfels.size() << " surfels";
  EXPECT_LT(peak, d.count() / 100);
}

TEST(FrontDoor, FiguresMirrorsAndSeeds) {
  const Dims d{30, 30, 30};
  const std::vector<std::uint8_t> v = noisyBall<std::uint8_t>(d, 9, 0);
  ExtractOptions o;
  o.selection = Selection::threshold(60.5);
  o.seed = SeedRule::fromVoxel({15, 15, 15});
  ImageGeometry g;
  g.spacing = {0.5, 1, 2};
  const Surface s = extract(VolumeView::of(v.data(), d, g), o);
  ASSERT_EQ(s.components.size(), 1u);
  const ComponentFigures& f = s.components[0];
  EXPECT_EQ(f.surfels, s.surfels.size());
  EXPECT_EQ(f.triangles, s.triangles.size());
  EXPECT_EQ(2 * f.edges, 3 * f.triangles);
  EXPECT_EQ(f.euler, (long long)f.surfels - (long long)f.edges + (long long)f.triangles);
  EXPECT_GT(f.volume, 0);
  // A mirrored frame gives the mirrored vertices and the same outward volume.
  ImageGeometry m = g;
  m.direction = {{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  const Surface sm = extract(VolumeView::of(v.data(), d, m), o);
  ASSERT_EQ(sm.vertices.size(), s.vertices.size());
  for (std::size_t i = 0; i < s.vertices.size(); ++i) EXPECT_DOUBLE_EQ(sm.vertices[i][0], -s.vertices[i][0]);
  EXPECT_NEAR(sm.components[0].volume, f.volume, 1e-9 * f.volume);
  // The seed point at the same place as the voxel, in physical coordinates.
  o.seed = SeedRule::point(g.toPhysical({15, 15, 15}));
  EXPECT_EQ(extract(VolumeView::of(v.data(), d, g), o).surfels, s.surfels);
}

// A seeded (or the largest) boundary is one component by construction, and extract() runs no
// union-find for its figures: checked here against the components found by a breadth-first
// search over the triangles' vertices, and against componentFigures (which runs one), on random
// images for every adjacency pair.
TEST(FrontDoor, ATrackedBoundaryIsOneComponentWithTheFiguresOfAUnionFind) {
  std::mt19937 rng(20261202);
  std::size_t surfaces = 0;
  for (int image = 0; image < 300; ++image) {
    const Dims d{int(4 + rng() % 10), int(4 + rng() % 10), int(4 + rng() % 10)};
    const unsigned density = 20 + rng() % 60;  // percent of 1-voxels
    std::vector<std::uint8_t> v(d.count());
    for (auto& x : v) x = std::uint8_t(rng() % 100 < density);
    for (AdjacencyPair pair : {AdjacencyPair::k26_6, AdjacencyPair::k18_6, AdjacencyPair::k6_18, AdjacencyPair::k6_26}) {
      ExtractOptions o;
      o.selection = Selection::threshold(0.5);
      o.pair = pair;
      o.seed = image % 3 == 0 ? SeedRule::largest()
                              : SeedRule::fromVoxel({int(rng() % d.nx), int(rng() % d.ny), int(rng() % d.nz)});
      Surface s;
      try {
        s = extract(VolumeView::of(v.data(), d), o);
      } catch (const InvalidInput&) {
        continue;  // no 1-voxel, or every voxel one
      }
      SCOPED_TRACE("image " + std::to_string(image) + ", pair " + std::to_string(int(pair)));
      // The vertices reached from vertex 0 through the triangles' edges.
      std::vector<std::vector<std::uint32_t>> neighbours(s.vertices.size());
      for (const auto& t : s.triangles)
        for (int j = 0; j < 3; ++j) neighbours[t[j]].push_back(t[(j + 1) % 3]), neighbours[t[(j + 1) % 3]].push_back(t[j]);
      std::vector<char> reached(s.vertices.size(), 0);
      std::vector<std::uint32_t> queue = {0};
      reached[0] = 1;
      for (std::size_t i = 0; i < queue.size(); ++i)
        for (std::uint32_t w : neighbours[queue[i]])
          if (!reached[w]) reached[w] = 1, queue.push_back(w);
      EXPECT_EQ(queue.size(), s.vertices.size());
      const std::vector<ComponentFigures> found = componentFigures(s.vertices, s.triangles);
      ASSERT_EQ(s.components.size(), 1u);
      ASSERT_EQ(found.size(), 1u);
      const ComponentFigures &a = s.components[0], &b = found[0];
      EXPECT_EQ(a.surfels, b.surfels);
      EXPECT_EQ(a.triangles, b.triangles);
      EXPECT_EQ(a.edges, b.edges);
      EXPECT_EQ(a.euler, b.euler);
      EXPECT_EQ(a.area, b.area);
      EXPECT_EQ(a.volume, b.volume);
      EXPECT_EQ(s.euler, a.euler);
      ++surfaces;
    }
  }
  EXPECT_GT(surfaces, 1000u);
}

TEST(FrontDoor, ProgressAndCancellation) {
  const Dims d{40, 40, 40};
  const std::vector<std::uint8_t> v = noisyBall<std::uint8_t>(d, 12, 4);
  ExtractOptions o;
  o.selection = Selection::threshold(60.5);
  o.seed = SeedRule::fromVoxel({20, 20, 20});
  std::vector<std::string> stages;
  o.progress = [&](const ProgressEvent& e) {
    if (!e.surfels) stages.push_back(e.stage);
  };
  const Surface s = extract(VolumeView::of(v.data(), d), o);
  EXPECT_EQ(stages, (std::vector<std::string>{"seed", "track", "convert", "place", "figures"}));
  ASSERT_EQ(s.timings.size(), stages.size());
  std::atomic<bool> cancel{true};
  o.cancel = &cancel;
  EXPECT_THROW(extract(VolumeView::of(v.data(), d), o), Cancelled);
}

TEST(FrontDoor, BadInputIsInvalidInputNamingTheValue) {
  const Dims d{10, 10, 10};
  std::vector<std::uint8_t> v(d.count(), 0);
  v[555] = 9;
  auto message = [&](ExtractOptions o, const VolumeView& view) -> std::string {
    try {
      extract(view, o);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "no InvalidInput";
  };
  const VolumeView view = VolumeView::of(v.data(), d);
  ExtractOptions o;
  o.selection = Selection::label(300);
  o.seed = SeedRule::all();
  EXPECT_NE(message(o, view).find("label 300 is not a value of uint8"), std::string::npos);
  o.selection = Selection::threshold(100);
  EXPECT_NE(message(o, view).find("empty selection"), std::string::npos);
  o.seed = SeedRule::fromVoxel({20, 1, 1});
  EXPECT_NE(message(o, view).find("seed voxel (20,1,1) lies outside the image domain [0,10)x[0,10)x[0,10)"),
            std::string::npos);
  o.seed = SeedRule::fromVoxel({1, 1, 1});
  EXPECT_NE(message(o, view).find("seed voxel (1,1,1) has no boundary surfel near it"), std::string::npos);
  o.seed = SeedRule::ray({1, 1, 1});
  EXPECT_NE(message(o, view).find("not on any boundary"), std::string::npos);
  o.seed = SeedRule::fromSurfel(Surfel{{1, 1, 1}, 0});
  o.selection = Selection::threshold(5);
  EXPECT_NE(message(o, view).find("is not a boundary surfel"), std::string::npos);
  o.selection = Selection::label(9);
  o.mapping = Mapping::Linear;
  EXPECT_NE(message(o, view).find("midpoint"), std::string::npos);
  EXPECT_THROW(makeViewSource(VolumeView{}), InvalidInput);
  EXPECT_THROW(parseMapping("cubic"), InvalidInput);
}

}  // namespace

namespace {

// nearestBoundarySurfel against every boundary surfel of the image, measured one by one.
TEST(FrontDoor, NearestSurfelSeedIsTheBruteForceNearest) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    const Dims d{int(3 + rng() % 20), int(3 + rng() % 20), int(3 + rng() % 20)};
    DenseImage<std::uint8_t> image(d, 0);
    const int blobs = 1 + int(rng() % 3);
    for (int b = 0; b < blobs; ++b) {
      const Voxel c{int(rng() % d.nx), int(rng() % d.ny), int(rng() % d.nz)};
      const int r = int(rng() % 4);
      for (int z = 0; z < d.nz; ++z)
        for (int y = 0; y < d.ny; ++y)
          for (int x = 0; x < d.nx; ++x)
            if ((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) + (z - c.z) * (z - c.z) <= r * r) image.at(x, y, z) = 1;
    }
    ImageGeometry g;
    g.spacing = {0.5 + (rng() % 4) * 0.5, 1.0, 0.75};
    const std::array<double, 3> p{double(rng() % 400) / 10 - 10, double(rng() % 400) / 10 - 10,
                                  double(rng() % 400) / 10 - 10};
    const ThresholdImage<std::uint8_t> binary(image, 0.5);
    // Brute force: every (1-voxel, 0-neighbour) pair.
    std::optional<Surfel> best;
    double bestDistance = 0;
    const std::array<double, 3> target = g.toPhysical(p);
    for (int z = 0; z < d.nz; ++z)
      for (int y = 0; y < d.ny; ++y)
        for (int x = 0; x < d.nx; ++x)
          for (Direction n = 0; n < 6; ++n) {
            const Surfel s{{x, y, z}, n};
            if (!binary(s.inside()) || binary(s.outside())) continue;
            const Voxel c = s.inside(), o = s.outside();
            const auto m = g.toPhysical({(c.x + o.x) / 2.0, (c.y + o.y) / 2.0, (c.z + o.z) / 2.0});
            const double dist = std::hypot(m[0] - target[0], m[1] - target[1], m[2] - target[2]);
            if (!best || dist < bestDistance || (dist == bestDistance && s.key() < best->key())) {
              best = s;
              bestDistance = dist;
            }
          }
    const std::optional<NearestSurfel> found = nearestBoundarySurfel(binary, p, g);
    ASSERT_EQ(found.has_value(), best.has_value()) << "trial " << trial;
    // Bounded (the seed rules' maxSeedDistance): the nearest if it lies within the bound (at
    // it included), nothing otherwise — whatever bricks the bound lets the search skip.
    const double limit = double(rng() % 300) / 10;
    const std::optional<NearestSurfel> bounded = nearestBoundarySurfel(binary, p, g, limit);
    ASSERT_EQ(bounded.has_value(), best && bestDistance <= limit) << "trial " << trial << ", limit " << limit;
    if (best && found) {
      const std::optional<NearestSurfel> atBest = nearestBoundarySurfel(binary, p, g, found->distance);
      ASSERT_TRUE(atBest) << "trial " << trial;
      EXPECT_EQ(atBest->surfel, *best) << "trial " << trial;
    }
    if (!best) continue;
    EXPECT_EQ(found->surfel, *best) << "trial " << trial;
    EXPECT_DOUBLE_EQ(found->distance, bestDistance) << "trial " << trial;
    if (bounded) {
      EXPECT_EQ(bounded->surfel, *best) << "trial " << trial;
    }
  }
}

// A seed far from every object: the nearest-surfel search stops at maxSeedDistance with an
// error that names it, having read only the bricks within that distance; at the distance of the
// nearest surfel (found with no bound) it gives that surfel and the same surface.
TEST(FrontDoor, TheNearestSurfelSearchStopsAtTheMaxSeedDistance) {
  const Dims d{4096, 64, 64};
  std::vector<std::uint8_t> v(d.count(), 0);
  for (int z = 16; z < 48; ++z)
    for (int y = 16; y < 48; ++y)
      for (int x = 0; x < 8; ++x) v[(std::size_t(z) * d.ny + y) * d.nx + x] = 200;
  ImageGeometry g;
  g.spacing = {0.5, 1, 2};  // the distance is in voxels of the smallest spacing, 0.5
  const auto view = makeViewSource(VolumeView::of(v.data(), d, g));
  ExtractOptions o;
  o.selection = Selection::threshold(100);
  for (const SeedRule& rule : {SeedRule::fromVoxel({4000, 32, 32}), SeedRule::point(g.toPhysical({4000, 32, 32}))}) {
    o.seed = rule;
    o.maxSeedDistance = 256;  // the default
    const CountingSource counting(*view);
    try {
      extract(counting, o);
      ADD_FAILURE() << "no error for a seed 3992 voxels from the object";
    } catch (const SeedTooFar& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("has no boundary surfel within 256 voxels"), std::string::npos) << message;
      EXPECT_NE(message.find("maxSeedDistance"), std::string::npos) << message;
      EXPECT_NE(message.find("--max-seed-distance"), std::string::npos) << message;
    }
    // The bricks within 256 voxels of x = 4000 (and their aprons), not the 16.8 M voxels.
    EXPECT_LT(counting.read, d.count() / 4) << counting.read << " voxels read";

    o.maxSeedDistance = std::numeric_limits<double>::infinity();
    const Surface unbounded = extract(*view, o);
    ASSERT_TRUE(unbounded.seed.distance);
    EXPECT_NEAR(*unbounded.seed.distance, (4000 - 7.5) * 0.5, 1e-9);  // to the face at x = 7.5
    o.maxSeedDistance = *unbounded.seed.distance / 0.5;
    const Surface within = extract(*view, o);
    EXPECT_EQ(within.seed.surfel, unbounded.seed.surfel);
    EXPECT_EQ(within.surfels, unbounded.surfels);
    EXPECT_EQ(within.triangles, unbounded.triangles);
    o.maxSeedDistance = std::nextafter(*unbounded.seed.distance / 0.5, 0.0);
    EXPECT_THROW(extract(*view, o), SeedTooFar);
  }
  // Not a positive number of voxels.
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    o.maxSeedDistance = bad;
    EXPECT_THROW(extract(*view, o), InvalidInput) << bad;
  }
}

// A spacing or origin that puts vertices beyond the float range (mesh files store floats) —
// or the double range, where they would be inf — is InvalidInput before any voxel is read, for
// extract (every seed rule), extractLabels and smooth, not a mesh of infinite vertices.
TEST(FrontDoor, AGeometryBeyondTheFloatRangeIsInvalidInput) {
  const Dims d{20, 20, 20};
  const std::vector<std::uint8_t> v = noisyBall<std::uint8_t>(d, 6, 0);
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "no InvalidInput";
  };
  ImageGeometry huge, beyondFloat, farOrigin, justInside;
  huge.spacing = {1e300, 1e300, 1e300};                  // inf in double
  beyondFloat.spacing = {1, 1e38, 1};                    // 2e39: finite in double, not in float
  farOrigin.origin = {0, 0, -1e39};                      // finite in double, not in float
  justInside.spacing = {1e37, 1e37, 1e37};               // 20e37 < 3.4e38
  for (const ImageGeometry& g : {huge, beyondFloat, farOrigin}) {
    const VolumeView view = VolumeView::of(v.data(), d, g);
    ExtractOptions o;
    o.selection = Selection::threshold(60.5);
    for (const SeedRule& rule : {SeedRule::all(), SeedRule::largest(), SeedRule::fromVoxel({10, 10, 10}),
                                 SeedRule::ray({10, 10, 10})}) {
      o.seed = rule;
      const auto source = makeViewSource(view);
      const CountingSource counting(*source);
      const std::string m = message([&] { extract(counting, o); });
      EXPECT_NE(m.find("put vertices beyond the float range"), std::string::npos) << m;
      EXPECT_EQ(counting.read, 0u);
    }
    LabelOptions lo;
    const std::string m = message([&] { extractLabels(view, lo); });
    EXPECT_NE(m.find("put vertices beyond the float range"), std::string::npos) << m;
  }
  // At the edge of the range, the vertices are finite as floats.
  ExtractOptions o;
  o.selection = Selection::threshold(60.5);
  o.seed = SeedRule::fromVoxel({10, 10, 10});
  Surface s = extract(VolumeView::of(v.data(), d, justInside), o);
  ASSERT_FALSE(s.vertices.empty());
  for (const auto& p : s.vertices)
    for (double x : p) EXPECT_TRUE(std::isfinite(float(x))) << x;
  // smooth() on a surface whose geometry was changed: refused, the vertices untouched.
  s.geometry = huge;
  const std::vector<std::array<double, 3>> before = s.vertices;
  const std::string m = message([&] { smooth(s, SmoothOptions{}); });
  EXPECT_NE(m.find("put vertices beyond the float range"), std::string::npos) << m;
  EXPECT_EQ(s.vertices, before);
}

TEST(FrontDoor, TheSpeckWarningFiresOnASpeckAndNotOnTheBall) {
  const Dims d{40, 40, 40};
  std::vector<std::uint8_t> v = noisyBall<std::uint8_t>(d, 12, 0);
  v[(std::size_t(2) * d.ny + 2) * d.nx + 2] = 120;  // a one-voxel speck in a corner
  ExtractOptions o;
  o.selection = Selection::threshold(60.5);
  o.seed = SeedRule::fromVoxel({1, 1, 1});
  const Surface speck = extract(VolumeView::of(v.data(), d), o);
  EXPECT_EQ(speck.surfels.size(), 6u);
  ASSERT_EQ(speck.warnings.size(), 1u);
  EXPECT_NE(speck.warnings[0].find("speck"), std::string::npos);
  ASSERT_TRUE(speck.seed.distance);
  EXPECT_NEAR(*speck.seed.distance, std::sqrt(0.25 + 1 + 1), 1e-12);  // to the face at x = 1.5
  o.seed = SeedRule::fromVoxel({20, 20, 20});
  EXPECT_TRUE(extract(VolumeView::of(v.data(), d), o).warnings.empty());
}

}  // namespace

// --threads: the scan of `largest`, the tracker's second pass, the loop extraction and the
// placement split their work; the surface is the same for 1, 2 and 7 threads, and `largest` is
// the boundary of most surfels (the first met among equals) of the full scan.
TEST(FrontDoor, EveryThreadCountGivesTheSameSurface) {
  for (unsigned noise : {3u, 4u}) {
    const Dims d{61, 57, 66};
    const std::vector<std::uint8_t> ref = noisyBall<std::uint8_t>(d, 22, noise);
    ExtractOptions o;
    o.selection = Selection::threshold(60.5);
    o.seed = SeedRule::all();
    o.threads = 1;
    const Surface all = extract(VolumeView::of(ref.data(), d), o);
    std::size_t most = 0;
    for (const ComponentFigures& c : all.components) most = std::max(most, c.surfels);
    ASSERT_GT(all.components.size(), 2u);
    for (Mapping mapping : {Mapping::Linear, Mapping::Midpoint}) {
      o.mapping = mapping;
      o.seed = SeedRule::largest();
      o.threads = 1;
      const Surface one = extract(VolumeView::of(ref.data(), d), o);
      EXPECT_EQ(one.surfels.size(), most);
      EXPECT_EQ(one.boundariesInImage, all.components.size());
      ExtractOptions seeded = o;
      seeded.seed = SeedRule::fromSurfel(*one.seed.surfel);
      for (int threads : {2, 7}) {
        o.threads = seeded.threads = threads;
        for (const ExtractOptions& options : {o, seeded}) {
          const Surface many = extract(VolumeView::of(ref.data(), d), options);
          EXPECT_EQ(many.seed.surfel, one.seed.surfel) << "threads " << threads;
          EXPECT_EQ(many.surfels, one.surfels) << "threads " << threads;
          EXPECT_EQ(many.triangles, one.triangles) << "threads " << threads;
          EXPECT_EQ(many.vertices, one.vertices) << "threads " << threads;
        }
      }
    }
  }
}
