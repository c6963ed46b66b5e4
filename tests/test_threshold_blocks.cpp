// scanThresholdBlock + mergeThresholdFragments (docs/api.md, "Thresholds by blocks") against the
// single pass extract() with SeedRule::all() over the whole volume: the merged Surface equals the
// single pass's field for field (vertices bit-equal and in the same order, triangles in the same
// order, surfels, figures, voxelsRead), for both mappings, on random float and uint8 volumes of
// every adjacency pair (NaN, infinities and values equal to the level among the floats) cut into
// random non-uniform blocks (1-voxel-thick blocks and a single block included). Each fragment is
// also checked on its own against the ownership rule (docs/theory.md, "Thresholds by blocks"):
// its triangles lie in cubes its block owns, every key is used, keys increase, and the gray
// values it carries are those of the volume, read directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>

#include "CaseSubset.h"
#include "PairTestName.h"
#include "ThresholdBlocks.h"

using namespace surftrack;
namespace ref = surftrack::testing;

namespace {

template <class T>
struct Volume {
  Dims dims;
  std::vector<T> f;
  T& at(int x, int y, int z) { return f[(std::size_t(z) * dims.ny + y) * dims.nx + x]; }
  double value(Voxel v) const { return double(f[(std::size_t(v.z) * dims.ny + v.y) * dims.nx + v.x]); }
};

/// A random volume: a smooth field (a sum of a few bumps, so that boundaries are surfaces with
/// interior and cavities) or noise, often cut by the faces; floats with now and then NaN,
/// infinities and values exactly at the level.
template <class T>
Volume<T> randomVolume(std::mt19937_64& rng, double level, bool wide) {
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::uniform_real_distribution<double> real(0.0, 1.0);
  Volume<T> v;
  v.dims = wide ? Dims{uniform(60, 140), uniform(2, 4), uniform(2, 4)} : Dims{uniform(3, 12), uniform(2, 10), uniform(3, 9)};
  v.f.resize(v.dims.count());
  const int bumps = uniform(0, 5);
  std::vector<std::array<double, 5>> b;
  b.resize(std::size_t(bumps));  // centre, radius, height
  for (auto& p : b)
    p = {real(rng) * (v.dims.nx + 2) - 1, real(rng) * (v.dims.ny + 2) - 1, real(rng) * (v.dims.nz + 2) - 1,
         1 + real(rng) * 4, (real(rng) < 0.2 ? -1 : 1) * (50 + real(rng) * 150)};
  const double noise = uniform(0, 3) == 0 ? 200 : uniform(0, 1) * 20;
  for (int z = 0; z < v.dims.nz; ++z)
    for (int y = 0; y < v.dims.ny; ++y)
      for (int x = 0; x < v.dims.nx; ++x) {
        double f = 60 + noise * (real(rng) - 0.5);
        for (const auto& p : b) {
          const double d2 = (x - p[0]) * (x - p[0]) + (y - p[1]) * (y - p[1]) + (z - p[2]) * (z - p[2]);
          f += p[4] * std::exp(-d2 / (p[3] * p[3]));
        }
        if constexpr (std::is_integral_v<T>)
          v.at(x, y, z) = T(std::clamp(std::lround(f), 0L, 255L));
        else
          v.at(x, y, z) = T(f);
      }
  if constexpr (!std::is_integral_v<T>) {
    const int specials = uniform(0, 2) == 0 ? uniform(1, 6) : 0;
    for (int i = 0; i < specials; ++i) {
      const T special[] = {std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::infinity(),
                           -std::numeric_limits<T>::infinity(), T(level)};
      v.f[std::size_t(uniform(0, int(v.f.size()) - 1))] = special[uniform(0, 3)];
    }
  } else {
    const int atLevel = uniform(0, 2) == 0 ? uniform(1, 6) : 0;  // f = s: a 0-voxel, t clamped
    for (int i = 0; i < atLevel; ++i) v.f[std::size_t(uniform(0, int(v.f.size()) - 1))] = T(level);
  }
  return v;
}

/// A random partition of [0, n) into intervals: one, a few of random lengths, or all of length 1,
/// often with a 1-voxel-thick one.
std::vector<int> randomCuts(std::mt19937_64& rng, int n) {
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::vector<int> cuts{0, n};
  const int kind = uniform(0, 9);
  if (kind == 1) {
    for (int i = 1; i < n; ++i) cuts.push_back(i);
  } else if (kind > 1) {
    const int k = uniform(1, 3);
    for (int i = 0; i < k; ++i) cuts.push_back(uniform(1, std::max(1, n - 1)));
    if (n >= 3 && uniform(0, 1)) {  // a 1-voxel-thick block
      const int at = uniform(1, n - 2);
      cuts.push_back(at);
      cuts.push_back(at + 1);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  return cuts;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

/// The merged surface is the single pass's, field for field (but the stage timings).
void expectSameSurface(const Surface& a, const Surface& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  EXPECT_EQ(std::memcmp(a.vertices.data(), b.vertices.data(), a.vertices.size() * sizeof(a.vertices[0])), 0);
  EXPECT_EQ(a.surfels, b.surfels);
  EXPECT_EQ(a.triangles, b.triangles);
  ASSERT_EQ(a.components.size(), b.components.size());
  for (std::size_t i = 0; i < a.components.size(); ++i) {
    const ComponentFigures &p = a.components[i], &q = b.components[i];
    EXPECT_TRUE(p.surfels == q.surfels && p.triangles == q.triangles && p.edges == q.edges && p.euler == q.euler);
    EXPECT_TRUE(sameBits(p.area, q.area) && sameBits(p.volume, q.volume));
  }
  EXPECT_EQ(a.euler, b.euler);
  EXPECT_EQ(a.boundariesInImage, b.boundariesInImage);
  EXPECT_EQ(a.pair, b.pair);
  EXPECT_EQ(a.mapping, b.mapping);
  EXPECT_TRUE(a.selection.kind == b.selection.kind && sameBits(a.selection.value, b.selection.value));
  EXPECT_EQ(std::memcmp(&a.geometry, &b.geometry, sizeof(ImageGeometry)), 0);
  EXPECT_EQ(a.warnings, b.warnings);
  EXPECT_EQ(a.voxelsRead, b.voxelsRead);
  EXPECT_FALSE(a.seed.surfel || b.seed.surfel);
}

/// A fragment by itself: keys increasing and all used; each triangle in a cube its block owns
/// (the componentwise minimum of its six voxels in the core, or -1 on an axis where lo = 0);
/// the gray values those of the volume (NaN for a voxel outside it), or none for the midpoint.
template <class T>
void checkFragment(const ThresholdFragment& f, const Volume<T>& v, Voxel lo, Voxel hi, Mapping mapping) {
  ASSERT_TRUE(std::is_sorted(f.keys.begin(), f.keys.end()));
  ASSERT_TRUE(std::adjacent_find(f.keys.begin(), f.keys.end()) == f.keys.end());
  EXPECT_EQ(f.volume, v.dims);
  EXPECT_EQ(f.voxels, std::uint64_t(hi.x - lo.x) * std::uint64_t(hi.y - lo.y) * std::uint64_t(hi.z - lo.z));
  std::vector<bool> used(f.keys.size(), false);
  for (const auto& t : f.triangles) {
    Voxel m{1 << 20, 1 << 20, 1 << 20};
    for (std::uint32_t k : t) {
      ASSERT_LT(k, f.keys.size());
      used[k] = true;
      const Surfel s = Surfel::fromKey(f.keys[k]);
      for (Voxel c : {s.inside(), s.outside()}) m = {std::min(m.x, c.x), std::min(m.y, c.y), std::min(m.z, c.z)};
    }
    for (int a = 0; a < 3; ++a) EXPECT_TRUE((m[a] >= lo[a] && m[a] < hi[a]) || (m[a] == -1 && lo[a] == 0)) << a;
  }
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; }));
  if (mapping == Mapping::Midpoint) {
    EXPECT_TRUE(f.values.empty());
    return;
  }
  ASSERT_EQ(f.values.size(), f.keys.size());
  for (std::size_t k = 0; k < f.keys.size(); ++k) {
    const Surfel s = Surfel::fromKey(f.keys[k]);
    if (v.dims.contains(s.inside()) && v.dims.contains(s.outside())) {
      const double fc = v.value(s.inside()), fd = v.value(s.outside());
      EXPECT_TRUE(sameBits(f.values[k][0], fc) && sameBits(f.values[k][1], fd));
    } else {
      EXPECT_TRUE(std::isnan(f.values[k][0]) && std::isnan(f.values[k][1]));
    }
  }
}

struct Tally {
  int cases = 0, empty = 0, blocks = 0, thin = 0, single = 0, nonFinite = 0;
};

/// `iterations` random volumes of voxel type T (`wide`: rows of 60 to 140 voxels, across the
/// 64-voxel words by which the single pass numbers a row's edges) through both mappings.
template <class T>
void checkVolumes(AdjacencyPair pair, std::uint64_t seed, int iterations, Tally& tally, bool wide = false) {
  std::mt19937_64 rng(seed);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (int iteration = 0; iteration < iterations; ++iteration) {
    const double level = std::is_integral_v<T> ? uniform(40, 120) + (uniform(0, 1) ? 0.5 : 0.0)
                                               : 60 + uniform(-400, 400) * 0.1;
    Volume<T> v = randomVolume<T>(rng, level, wide);
    ImageGeometry geometry;
    geometry.spacing = {0.5 + uniform(0, 8) * 0.25, 1.0 + uniform(0, 4) * 0.1, 0.3 + uniform(0, 6) * 0.7};
    geometry.origin = {uniform(-50, 50) * 0.37, uniform(-50, 50) * 1.3, uniform(-50, 50) * 0.11};
    if (uniform(0, 3) == 0) geometry.direction[2] = {0, 0, -1};  // mirrored: the merge flips as the pass does
    std::vector<int> cx = randomCuts(rng, v.dims.nx), cy = randomCuts(rng, v.dims.ny), cz = randomCuts(rng, v.dims.nz);
    if (uniform(0, 15) == 0) cx = {0, v.dims.nx}, cy = {0, v.dims.ny}, cz = {0, v.dims.nz};  // one block
    const bool figures = uniform(0, 4) != 0;
    const int blockThreads = iteration % 25 == 0 ? 2 : 1;
    const double epsilon = uniform(0, 3) == 0 ? 0.1 : 1e-3;
    if (!ref::caseChecked(std::uint64_t(iteration))) continue;
    SCOPED_TRACE("case " + std::to_string(iteration) + " " + std::to_string(v.dims.nx) + "x" +
                 std::to_string(v.dims.ny) + "x" + std::to_string(v.dims.nz) + " level " + std::to_string(level));
    for (Mapping mapping : {Mapping::Midpoint, Mapping::Default}) {
      ExtractOptions o;
      o.selection = Selection::threshold(level);
      o.seed = SeedRule::all();
      o.pair = pair;
      o.mapping = mapping;
      o.epsilon = epsilon;
      o.threads = iteration % 7 == 3 ? 2 : 1;  // the single pass is the same on any number of threads
      o.figures = figures;
      std::optional<Surface> single;
      try {
        single = extract(VolumeView::of(v.f.data(), v.dims, geometry), o);
      } catch (const InvalidInput&) {  // no boundary: every voxel on one side of the level
      }
      std::vector<ThresholdFragment> fragments;
      for (std::size_t k = 0; k + 1 < cz.size(); ++k)
        for (std::size_t j = 0; j + 1 < cy.size(); ++j)
          for (std::size_t i = 0; i + 1 < cx.size(); ++i) {
            const Voxel lo{cx[i], cy[j], cz[k]}, hi{cx[i + 1], cy[j + 1], cz[k + 1]};
            Voxel origin = lo, end{std::min(hi.x + 1, v.dims.nx), std::min(hi.y + 1, v.dims.ny),
                                    std::min(hi.z + 1, v.dims.nz)};
            if (uniform(0, 5) == 0)
              for (int a = 0; a < 3; ++a) {
                origin[a] = std::max(0, origin[a] - uniform(0, 2));
                end[a] = std::min(v.dims[a], end[a] + uniform(0, 2));
              }
            const VolumeView box = VolumeView::strided(
                &v.at(origin.x, origin.y, origin.z), Dims{end.x - origin.x, end.y - origin.y, end.z - origin.z},
                {1, std::ptrdiff_t(v.dims.nx), std::ptrdiff_t(v.dims.nx) * v.dims.ny});
            ExtractOptions bo = o;
            bo.threads = blockThreads;
            fragments.push_back(scanThresholdBlock(box, origin, v.dims, lo, hi, bo));
            checkFragment(fragments.back(), v, lo, hi, mapping == Mapping::Midpoint ? mapping : Mapping::Linear);
            if (mapping == Mapping::Midpoint) {
              ++tally.blocks;
              if (hi.x - lo.x == 1 || hi.y - lo.y == 1 || hi.z - lo.z == 1) ++tally.thin;
            }
          }
      std::shuffle(fragments.begin(), fragments.end(), rng);  // the merge takes the fragments in any order
      if (!single) {
        EXPECT_THROW(mergeThresholdFragments(fragments, geometry, o), InvalidInput);
        tally.empty += mapping == Mapping::Midpoint;
        continue;
      }
      expectSameSurface(mergeThresholdFragments(fragments, geometry, o), *single);
      if (mapping == Mapping::Midpoint) {
        ++tally.cases;
        if (cx.size() == 2 && cy.size() == 2 && cz.size() == 2) ++tally.single;
        if (!std::all_of(v.f.begin(), v.f.end(), [](T f) { return std::isfinite(double(f)); })) ++tally.nonFinite;
      }
    }
    if (::testing::Test::HasFailure()) return;
  }
}

class ThresholdBlocks : public ::testing::TestWithParam<AdjacencyPair> {};

TEST_P(ThresholdBlocks, MergedFragmentsAreTheSinglePass) {
  const AdjacencyPair pair = GetParam();
  Tally f32, u8;
  checkVolumes<float>(pair, 0x7B10C5 + std::uint64_t(pair), 300, f32);
  checkVolumes<std::uint8_t>(pair, 0x8B10C5 + std::uint64_t(pair), 300, u8);
  for (const Tally* t : {&f32, &u8}) {
    EXPECT_GE(t->cases, int(ref::subsetMinimum(250)));
    EXPECT_GE(t->thin, int(ref::subsetMinimum(300)));
    EXPECT_GE(t->single, int(ref::subsetMinimum(10)));
  }
  EXPECT_GE(f32.nonFinite, int(ref::subsetMinimum(20)));
  std::printf("float: %d cases (%d empty), %d blocks (%d thin), %d single-block, %d with NaN or infinity; "
              "uint8: %d cases (%d empty), %d blocks (%d thin), %d single-block\n",
              f32.cases, f32.empty, f32.blocks, f32.thin, f32.single, f32.nonFinite, u8.cases, u8.empty, u8.blocks,
              u8.thin, u8.single);
}

/// Rows wider than a word of the single pass's row bit sets, and other voxel types.
TEST_P(ThresholdBlocks, WideRowsAndOtherTypes) {
  const AdjacencyPair pair = GetParam();
  Tally f64, i16, u8;
  checkVolumes<double>(pair, 0x9B10C5 + std::uint64_t(pair), 20, f64, true);
  checkVolumes<std::int16_t>(pair, 0xAB10C5 + std::uint64_t(pair), 20, i16, true);
  checkVolumes<std::uint8_t>(pair, 0xBB10C5 + std::uint64_t(pair), 20, u8, true);
  for (const Tally* t : {&f64, &i16, &u8}) {
    EXPECT_GE(t->cases + t->empty, int(ref::subsetMinimum(20)));  // every case checked
    EXPECT_GE(t->cases, int(ref::subsetMinimum(15)));
  }
}

INSTANTIATE_TEST_SUITE_P(Pairs, ThresholdBlocks, ::testing::ValuesIn(kAllAdjacencyPairs), ref::pairTestName);

TEST(ThresholdBlocks, BadInputIsRefused) {
  const Dims dims{6, 5, 4};
  std::vector<float> gray(dims.count(), 0.f);
  gray[7] = 3;
  const VolumeView whole = VolumeView::of(gray.data(), dims);
  ExtractOptions o;
  o.selection = Selection::threshold(1);
  o.seed = SeedRule::all();
  // A box without its high apron, a core outside the volume, an empty core, a box beyond it.
  const VolumeView part = VolumeView::strided(gray.data(), Dims{3, 5, 4}, {1, 6, 30});
  EXPECT_THROW(scanThresholdBlock(part, {0, 0, 0}, dims, {0, 0, 0}, {3, 5, 4}, o), InvalidInput);
  EXPECT_NO_THROW(scanThresholdBlock(part, {0, 0, 0}, dims, {0, 0, 0}, {2, 5, 4}, o));
  EXPECT_THROW(scanThresholdBlock(whole, {0, 0, 0}, dims, {0, 0, 0}, {7, 5, 4}, o), InvalidInput);
  EXPECT_THROW(scanThresholdBlock(whole, {0, 0, 0}, dims, {2, 0, 0}, {2, 5, 4}, o), InvalidInput);
  EXPECT_THROW(scanThresholdBlock(whole, {1, 0, 0}, dims, {1, 0, 0}, {6, 5, 4}, o), InvalidInput);
  EXPECT_THROW(scanThresholdBlock(whole, {0, 0, 0}, Dims{6, 5, 0}, {0, 0, 0}, {6, 5, 4}, o), InvalidInput);
  // A label selection, a NaN level, a seed rule, an epsilon, negative threads.
  for (int bad = 0; bad < 5; ++bad) {
    ExtractOptions b = o;
    if (bad == 0) b.selection = Selection::label(LabelValue(3));
    if (bad == 1) b.selection = Selection::threshold(std::nan(""));
    if (bad == 2) b.seed = SeedRule::largest();
    if (bad == 3) b.epsilon = 0.5;
    if (bad == 4) b.threads = -1;
    EXPECT_THROW(scanThresholdBlock(whole, {}, dims, {}, {6, 5, 4}, b), InvalidInput) << bad;
  }

  // The merge: nothing, a triangle beyond the keys, keys not increasing, another volume, no
  // gray values for the linear mapping, no boundary at all.
  const ThresholdFragment f = scanThresholdBlock(whole, {}, dims, {}, {6, 5, 4}, o);
  ASSERT_FALSE(f.triangles.empty());
  EXPECT_NO_THROW(mergeThresholdFragments({f}, {}, o));
  EXPECT_THROW(mergeThresholdFragments({}, {}, o), InvalidInput);
  ThresholdFragment beyond = f;
  beyond.triangles[0][1] = std::uint32_t(beyond.keys.size());
  EXPECT_THROW(mergeThresholdFragments({beyond}, {}, o), InvalidInput);
  ThresholdFragment unsorted = f;
  std::swap(unsorted.keys[0], unsorted.keys[1]);
  EXPECT_THROW(mergeThresholdFragments({unsorted}, {}, o), InvalidInput);
  ThresholdFragment other = f;
  other.volume.nx = 7;
  EXPECT_THROW(mergeThresholdFragments({f, other}, {}, o), InvalidInput);
  ExtractOptions midpoint = o;
  midpoint.mapping = Mapping::Midpoint;
  const ThresholdFragment m = scanThresholdBlock(whole, {}, dims, {}, {6, 5, 4}, midpoint);
  EXPECT_NO_THROW(mergeThresholdFragments({m}, {}, midpoint));
  EXPECT_THROW(mergeThresholdFragments({m}, {}, o), InvalidInput);
  ExtractOptions high = o;
  high.selection = Selection::threshold(5);
  EXPECT_THROW(mergeThresholdFragments({scanThresholdBlock(whole, {}, dims, {}, {6, 5, 4}, high)}, {}, high),
               InvalidInput);
}

}  // namespace
