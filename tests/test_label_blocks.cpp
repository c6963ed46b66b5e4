// scanLabelBlock + mergeLabelFragments (docs/api.md, "Label maps by blocks") against the single
// pass extractLabels over the whole volume: for every label, the merged Surface equals the single
// pass's array by array (vertices bit-equal, triangles in the same order, surfels, figures), on
// random label images of every adjacency pair cut into random non-uniform blocks (1-voxel-thick
// blocks and a single block included), with labels at 2^53, 2^53 + 1 and 2^64 - 1 kept apart.
// Each fragment is also checked on its own against the ownership rule (docs/theory.md, "Label
// maps by blocks"): its triangles lie in cubes its block owns, every key is used, keys increase,
// and the voxels of the core are counted directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <random>

#include "CaseSubset.h"
#include "Labels.h"
#include "PairTestName.h"

using namespace surftrack;
namespace ref = surftrack::testing;

namespace {

using Label = std::uint64_t;

/// Label values: small ones, the doubles' integer limit and its neighbours, the top of uint64.
constexpr Label kTwo53 = Label(1) << 53;
const Label kPool[] = {1, 2, 3, 7, 255, 256, 65535, kTwo53 - 1, kTwo53, kTwo53 + 1, kTwo53 + 2,
                       std::numeric_limits<Label>::max(), std::numeric_limits<Label>::max() - 1,
                       Label(1) << 63, (Label(1) << 63) + 1};

struct Image {
  Dims dims;
  std::vector<Label> labels;
  Label& at(int x, int y, int z) { return labels[(std::size_t(z) * dims.ny + y) * dims.nx + x]; }
};

/// A random label image: background, blobs (boxes and balls, anywhere, often cut by the faces),
/// single voxels in the corners, noise; now and then one label filling everything.
Image randomImage(std::mt19937_64& rng, Label background) {
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  Image im;
  im.dims = {uniform(7, 13), uniform(5, 11), uniform(6, 9)};
  std::vector<Label> used;
  const int count = uniform(2, 40);
  for (int i = 0; i < count; ++i)
    used.push_back(uniform(0, 2) == 0 ? kPool[std::size_t(uniform(0, int(std::size(kPool)) - 1))]
                                      : Label(uniform(1, 60)) + (uniform(0, 3) == 0 ? kTwo53 - 30 : 0));
  auto pick = [&] { return used[std::size_t(uniform(0, int(used.size()) - 1))]; };
  const bool filled = uniform(0, 15) == 0;
  im.labels.assign(im.dims.count(), filled ? pick() : background);
  const int blobs = filled ? uniform(0, 2) : uniform(1, 12);
  for (int b = 0; b < blobs; ++b) {
    const Label L = pick();
    const int cx = uniform(-1, im.dims.nx), cy = uniform(-1, im.dims.ny), cz = uniform(-1, im.dims.nz);
    const int r = uniform(0, 4);
    const bool ball = uniform(0, 1);
    for (int z = 0; z < im.dims.nz; ++z)
      for (int y = 0; y < im.dims.ny; ++y)
        for (int x = 0; x < im.dims.nx; ++x) {
          const int dx = x - cx, dy = y - cy, dz = z - cz;
          if (ball ? dx * dx + dy * dy + dz * dz <= r * r : std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) <= r)
            im.at(x, y, z) = L;
        }
  }
  for (int c = 0; c < 8; ++c)
    if (uniform(0, 2) == 0)
      im.at(c & 1 ? im.dims.nx - 1 : 0, c & 2 ? im.dims.ny - 1 : 0, c & 4 ? im.dims.nz - 1 : 0) = pick();
  const int noise = uniform(0, 3) == 0 ? int(im.labels.size()) / uniform(3, 20) : 0;
  for (int i = 0; i < noise; ++i) im.labels[std::size_t(uniform(0, int(im.labels.size()) - 1))] = pick();
  return im;
}

/// A random partition of [0, n) into intervals: one, a few of random lengths, or all of length 1,
/// often with a 1-voxel-thick one.
std::vector<int> randomCuts(std::mt19937_64& rng, int n) {
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::vector<int> cuts{0, n};
  const int kind = uniform(0, 9);
  if (kind == 0) {
    // one block on this axis
  } else if (kind == 1) {
    for (int i = 1; i < n; ++i) cuts.push_back(i);
  } else {
    const int k = uniform(1, 3);
    for (int i = 0; i < k; ++i) cuts.push_back(uniform(1, n - 1));
    if (uniform(0, 1)) {  // a 1-voxel-thick block
      const int at = uniform(1, n - 2);
      cuts.push_back(at);
      cuts.push_back(at + 1);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  return cuts;
}

void expectSameFigures(const std::vector<ComponentFigures>& a, const std::vector<ComponentFigures>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].surfels, b[i].surfels);
    EXPECT_EQ(a[i].triangles, b[i].triangles);
    EXPECT_EQ(a[i].edges, b[i].edges);
    EXPECT_EQ(a[i].euler, b[i].euler);
    EXPECT_EQ(std::memcmp(&a[i].area, &b[i].area, sizeof(double)), 0) << a[i].area << " " << b[i].area;
    EXPECT_EQ(std::memcmp(&a[i].volume, &b[i].volume, sizeof(double)), 0) << a[i].volume << " " << b[i].volume;
  }
}

/// The merged surface is the single pass's, field for field.
void expectSameSurface(const LabelSurface& merged, const LabelSurface& single) {
  EXPECT_EQ(merged.label, single.label);
  EXPECT_EQ(merged.voxels, single.voxels);
  const Surface& a = merged.surface;
  const Surface& b = single.surface;
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  EXPECT_EQ(std::memcmp(a.vertices.data(), b.vertices.data(), a.vertices.size() * sizeof(a.vertices[0])), 0);
  EXPECT_EQ(a.surfels, b.surfels);
  EXPECT_EQ(a.triangles, b.triangles);
  expectSameFigures(a.components, b.components);
  EXPECT_EQ(a.euler, b.euler);
  EXPECT_EQ(a.boundariesInImage, b.boundariesInImage);
  EXPECT_EQ(a.pair, b.pair);
  EXPECT_EQ(a.mapping, b.mapping);
  EXPECT_TRUE(a.selection.kind == b.selection.kind && a.selection.labelValue == b.selection.labelValue);
  EXPECT_EQ(std::memcmp(&a.geometry, &b.geometry, sizeof(ImageGeometry)), 0);
  EXPECT_EQ(a.warnings, b.warnings);
  EXPECT_EQ(a.voxelsRead, b.voxelsRead);
}

/// A fragment by itself: keys increasing and all used; each triangle in a cube its block owns
/// (the componentwise minimum of its six voxels in the core, or -1 on an axis where lo = 0).
void checkFragment(const LabelFragment& f, Voxel lo, Voxel hi) {
  ASSERT_TRUE(std::is_sorted(f.keys.begin(), f.keys.end()));
  ASSERT_TRUE(std::adjacent_find(f.keys.begin(), f.keys.end()) == f.keys.end());
  std::vector<bool> used(f.keys.size(), false);
  for (const auto& t : f.triangles) {
    Voxel m{1 << 20, 1 << 20, 1 << 20};
    for (std::uint32_t v : t) {
      ASSERT_LT(v, f.keys.size());
      used[v] = true;
      const Surfel s = Surfel::fromKey(f.keys[v]);
      for (Voxel c : {s.inside(), s.outside()}) m = {std::min(m.x, c.x), std::min(m.y, c.y), std::min(m.z, c.z)};
    }
    for (int a = 0; a < 3; ++a) EXPECT_TRUE((m[a] >= lo[a] && m[a] < hi[a]) || (m[a] == -1 && lo[a] == 0)) << a;
  }
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; }));
}

class LabelBlocks : public ::testing::TestWithParam<AdjacencyPair> {};

TEST_P(LabelBlocks, MergedFragmentsAreTheSinglePass) {
  const AdjacencyPair pair = GetParam();
  std::mt19937_64 rng(0xB10C5 + std::uint64_t(pair));
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  int cases = 0, blocksSeen = 0, thinBlocks = 0, singleBlock = 0;
  int apronOnly = 0;  // fragments of a label with triangles in the block's cubes but no voxel in its core
  std::map<Label, int> bigLabels;  // labels above 2^53 checked
  for (int iteration = 0; iteration < 1000; ++iteration) {
    const Label background = uniform(0, 9) == 0 ? kPool[std::size_t(uniform(0, int(std::size(kPool)) - 1))] : 0;
    Image im = randomImage(rng, background);
    if (!ref::caseChecked(std::uint64_t(iteration))) continue;
    SCOPED_TRACE("case " + std::to_string(iteration) + " " + std::to_string(im.dims.nx) + "x" +
                 std::to_string(im.dims.ny) + "x" + std::to_string(im.dims.nz));
    ImageGeometry geometry;
    geometry.spacing = {0.5 + uniform(0, 8) * 0.25, 1.0 + uniform(0, 4) * 0.1, 0.3 + uniform(0, 6) * 0.7};
    geometry.origin = {uniform(-50, 50) * 0.37, uniform(-50, 50) * 1.3, uniform(-50, 50) * 0.11};
    if (uniform(0, 3) == 0) geometry.direction[0] = {-1, 0, 0};  // mirrored: the merge flips as the pass does
    LabelOptions o;
    o.pair = pair;
    o.background = LabelValue(background);
    o.threads = 1;
    o.figures = uniform(0, 4) != 0;
    const VolumeView whole = VolumeView::of(im.labels.data(), im.dims, geometry);
    std::vector<LabelSurface> single;
    try {
      single = extractLabels(whole, o);
    } catch (const InvalidInput&) {  // every voxel the background
      EXPECT_TRUE(std::all_of(im.labels.begin(), im.labels.end(), [&](Label L) { return L == background; }));
      continue;
    }
    if (uniform(0, 4) == 0 && single.size() > 1) {  // a selection: a list or a range of labels
      if (uniform(0, 1)) {
        o.labels = LabelSelection::list({single[1].label, single.back().label});
      } else {
        o.labels = LabelSelection::range(single[0].label, single[single.size() / 2].label);
      }
      single = extractLabels(whole, o);
    }
    // Several slabs of planes within a block too, now and then (an arena of threads per block
    // call costs more than these small blocks' scan).
    const int blockThreads = iteration % 25 == 0 ? 2 : 1;

    std::vector<int> cx = randomCuts(rng, im.dims.nx), cy = randomCuts(rng, im.dims.ny),
                     cz = randomCuts(rng, im.dims.nz);
    if (iteration % 20 == 1) cx = {0, im.dims.nx}, cy = {0, im.dims.ny}, cz = {0, im.dims.nz};  // one block
    if (cx.size() == 2 && cy.size() == 2 && cz.size() == 2) ++singleBlock;
    std::map<Label, std::vector<LabelFragment>> fragments;
    std::map<Label, std::uint64_t> voxels;  // counted directly per core
    for (std::size_t k = 0; k + 1 < cz.size(); ++k)
      for (std::size_t j = 0; j + 1 < cy.size(); ++j)
        for (std::size_t i = 0; i + 1 < cx.size(); ++i) {
          const Voxel lo{cx[i], cy[j], cz[k]}, hi{cx[i + 1], cy[j + 1], cz[k + 1]};
          // The box: the core and its high apron, sometimes more on either side.
          Voxel origin = lo, end{std::min(hi.x + 1, im.dims.nx), std::min(hi.y + 1, im.dims.ny),
                                  std::min(hi.z + 1, im.dims.nz)};
          if (uniform(0, 5) == 0)
            for (int a = 0; a < 3; ++a) {
              origin[a] = std::max(0, origin[a] - uniform(0, 2));
              end[a] = std::min(im.dims[a], end[a] + uniform(0, 2));
            }
          const Dims boxDims{end.x - origin.x, end.y - origin.y, end.z - origin.z};
          const VolumeView box = VolumeView::strided(
              &im.at(origin.x, origin.y, origin.z), boxDims,
              {1, std::ptrdiff_t(im.dims.nx), std::ptrdiff_t(im.dims.nx) * im.dims.ny});
          LabelOptions bo = o;
          bo.threads = blockThreads;
          const std::vector<LabelFragment> got = scanLabelBlock(box, origin, im.dims, lo, hi, bo);
          ++blocksSeen;
          if (hi.x - lo.x == 1 || hi.y - lo.y == 1 || hi.z - lo.z == 1) ++thinBlocks;
          for (std::size_t f = 0; f < got.size(); ++f) {
            if (f > 0) EXPECT_LT(got[f - 1].label, got[f].label);
            checkFragment(got[f], lo, hi);
            if (got[f].voxels == 0) ++apronOnly;
            fragments[got[f].label.as<Label>()].push_back(got[f]);
          }
          for (int z = lo.z; z < hi.z; ++z)
            for (int y = lo.y; y < hi.y; ++y)
              for (int x = lo.x; x < hi.x; ++x) ++voxels[im.at(x, y, z)];
        }
    // Each block's voxel counts are those of its core, counted directly.
    for (const auto& [L, list] : fragments) {
      std::uint64_t sum = 0;
      for (const LabelFragment& f : list) sum += f.voxels;
      EXPECT_EQ(sum, voxels[L]) << L;
    }
    ASSERT_EQ(fragments.size(), single.size());
    std::size_t at = 0;
    for (auto& [L, list] : fragments) {
      const LabelSurface& expected = single[at++];
      ASSERT_EQ(LabelValue(L), expected.label);
      if (L > kTwo53) ++bigLabels[L];
      std::shuffle(list.begin(), list.end(), rng);  // the merge takes the fragments in any order
      expectSameSurface(mergeLabelFragments(list, geometry, o), expected);
    }
    ++cases;
    if (HasFailure()) break;
  }
  EXPECT_GE(cases, int(ref::subsetMinimum(900)));
  EXPECT_GE(thinBlocks, int(ref::subsetMinimum(1000)));
  EXPECT_GE(singleBlock, int(ref::subsetMinimum(40)));
  EXPECT_GE(apronOnly, int(ref::subsetMinimum(1000)));
  EXPECT_TRUE(bigLabels.count(kTwo53 + 1) && bigLabels.count(std::numeric_limits<Label>::max()));
  std::printf("%d cases, %d blocks (%d thin, %d single-block cases), %d fragments without core voxels\n", cases,
              blocksSeen, thinBlocks, singleBlock, apronOnly);
}

INSTANTIATE_TEST_SUITE_P(Pairs, LabelBlocks, ::testing::ValuesIn(kAllAdjacencyPairs), ref::pairTestName);

/// Signed and narrow label types through the same merge: int16 labels with negative values,
/// uint8 labels.
template <class T>
void checkType(AdjacencyPair pair, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (int iteration = 0; iteration < 100; ++iteration) {
    if (!ref::caseChecked(std::uint64_t(iteration))) continue;
    const Dims dims{uniform(4, 9), uniform(4, 9), uniform(4, 9)};
    std::vector<T> labels(dims.count());
    for (T& v : labels) v = T(uniform(0, 3) == 0 ? 0 : uniform(0, 5) * (std::is_signed_v<T> ? -1 : 1) + uniform(0, 2));
    LabelOptions o;
    o.pair = pair;
    o.threads = 1;
    const ImageGeometry geometry;
    std::vector<LabelSurface> single;
    try {
      single = extractLabels(VolumeView::of(labels.data(), dims, geometry), o);
    } catch (const InvalidInput&) {
      continue;
    }
    std::map<std::int64_t, std::vector<LabelFragment>> fragments;
    const std::vector<int> cx = randomCuts(rng, dims.nx), cy = randomCuts(rng, dims.ny), cz = randomCuts(rng, dims.nz);
    for (std::size_t k = 0; k + 1 < cz.size(); ++k)
      for (std::size_t j = 0; j + 1 < cy.size(); ++j)
        for (std::size_t i = 0; i + 1 < cx.size(); ++i) {
          const Voxel lo{cx[i], cy[j], cz[k]}, hi{cx[i + 1], cy[j + 1], cz[k + 1]};
          const Voxel end{std::min(hi.x + 1, dims.nx), std::min(hi.y + 1, dims.ny), std::min(hi.z + 1, dims.nz)};
          const VolumeView box = VolumeView::strided(&labels[(std::size_t(lo.z) * dims.ny + lo.y) * dims.nx + lo.x],
                                                     Dims{end.x - lo.x, end.y - lo.y, end.z - lo.z},
                                                     {1, std::ptrdiff_t(dims.nx), std::ptrdiff_t(dims.nx) * dims.ny});
          for (LabelFragment& f : scanLabelBlock(box, lo, dims, lo, hi, o))
            fragments[f.label.as<std::int64_t>()].push_back(std::move(f));
        }
    ASSERT_EQ(fragments.size(), single.size());
    std::size_t at = 0;
    for (const auto& [L, list] : fragments) expectSameSurface(mergeLabelFragments(list, geometry, o), single[at++]);
  }
}

TEST(LabelBlocks, SignedAndNarrowLabelTypes) {
  for (AdjacencyPair pair : kAllAdjacencyPairs) {
    checkType<std::int16_t>(pair, 11 + std::uint64_t(pair));
    checkType<std::uint8_t>(pair, 23 + std::uint64_t(pair));
  }
}

TEST(LabelBlocks, BadInputIsRefused) {
  const Dims dims{6, 5, 4};
  std::vector<std::uint32_t> labels(dims.count(), 0);
  labels[7] = 3;
  const VolumeView whole = VolumeView::of(labels.data(), dims);
  const LabelOptions o;
  // A box without its high apron, a core outside the volume, an empty core, a box beyond it.
  const Dims small{3, 5, 4};
  const VolumeView part = VolumeView::strided(labels.data(), small, {1, 6, 30});
  EXPECT_THROW(scanLabelBlock(part, {0, 0, 0}, dims, {0, 0, 0}, {3, 5, 4}, o), InvalidInput);
  EXPECT_NO_THROW(scanLabelBlock(part, {0, 0, 0}, dims, {0, 0, 0}, {2, 5, 4}, o));
  EXPECT_THROW(scanLabelBlock(whole, {0, 0, 0}, dims, {0, 0, 0}, {7, 5, 4}, o), InvalidInput);
  EXPECT_THROW(scanLabelBlock(whole, {0, 0, 0}, dims, {2, 0, 0}, {2, 5, 4}, o), InvalidInput);
  EXPECT_THROW(scanLabelBlock(whole, {1, 0, 0}, dims, {1, 0, 0}, {6, 5, 4}, o), InvalidInput);
  EXPECT_THROW(scanLabelBlock(whole, {0, 0, 0}, Dims{6, 5, 0}, {0, 0, 0}, {6, 5, 4}, o), InvalidInput);
  // Float voxels, seeds, the largest boundary.
  std::vector<float> gray(dims.count(), 0.f);
  EXPECT_THROW(scanLabelBlock(VolumeView::of(gray.data(), dims), {}, dims, {}, {6, 5, 4}, o), InvalidInput);
  LabelOptions seeded = o;
  seeded.seeds = {Voxel{1, 1, 0}};
  EXPECT_THROW(scanLabelBlock(whole, {}, dims, {}, {6, 5, 4}, seeded), InvalidInput);
  LabelOptions largest = o;
  largest.boundaries = LabelBoundaries::Largest;
  EXPECT_THROW(scanLabelBlock(whole, {}, dims, {}, {6, 5, 4}, largest), InvalidInput);
  // A listed label need not occur in a block, but must be a value of the type.
  LabelOptions listed = o;
  listed.labels = LabelSelection::list({LabelValue(5)});
  EXPECT_TRUE(scanLabelBlock(whole, {}, dims, {}, {6, 5, 4}, listed).empty());
  listed.labels = LabelSelection::list({LabelValue(-1)});
  EXPECT_THROW(scanLabelBlock(whole, {}, dims, {}, {6, 5, 4}, listed), InvalidInput);

  // The merge: nothing, two labels, a triangle beyond the keys, keys not increasing.
  std::vector<LabelFragment> f = scanLabelBlock(whole, {}, dims, {}, {6, 5, 4}, o);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NO_THROW(mergeLabelFragments(f, {}, o));
  EXPECT_THROW(mergeLabelFragments({}, {}, o), InvalidInput);
  std::vector<LabelFragment> two = {f[0], f[0]};
  two[1].label = 4;
  EXPECT_THROW(mergeLabelFragments(two, {}, o), InvalidInput);
  std::vector<LabelFragment> beyond = f;
  beyond[0].triangles[0][1] = std::uint32_t(beyond[0].keys.size());
  EXPECT_THROW(mergeLabelFragments(beyond, {}, o), InvalidInput);
  std::vector<LabelFragment> unsorted = f;
  std::swap(unsorted[0].keys[0], unsorted[0].keys[1]);
  EXPECT_THROW(mergeLabelFragments(unsorted, {}, o), InvalidInput);
}

}  // namespace
