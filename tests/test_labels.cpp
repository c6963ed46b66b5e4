// extractLabels (docs/api.md, "Label maps") against computations that do not use it: surfel and
// voxel counts from the 6-adjacent voxel pairs of the image, boundaries and Euler
// characteristics from voxel components (VoxelComponents.h, MeshChecks.h), the meshes of the
// binary path (extract with Selection::label), and the positions of the surfels shared by two
// labels. Random label images from fixed seeds, and every atlas of mricron-data present.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <map>
#include <random>
#include <set>
#include <unordered_map>

#include <unistd.h>

#include "CaseSubset.h"
#include "Extract.h"
#include "Labels.h"
#include "MeshChecks.h"
#include "PairTestName.h"
#include "ReadVolume.h"
#include "Refine.h"
#include "WallPoints.h"

using namespace surftrack;
namespace ref = surftrack::testing;

namespace {

/// A label image: labels as int64 (converted to the type under test), x fastest.
struct LabelVolume {
  Dims dims;
  std::vector<std::int64_t> labels;
  std::int64_t at(Voxel v) const { return labels[(std::size_t(v.z) * dims.ny + v.y) * dims.nx + v.x]; }
};

/// Voxel and surfel counts of each label, counted directly: the 6-adjacent pairs (c, d) with
/// f(c) = L and d outside the domain or f(d) != L; keys sorted.
struct DirectCounts {
  std::map<std::int64_t, std::uint64_t> voxels;
  std::map<std::int64_t, std::vector<std::uint64_t>> surfels;
  std::map<std::int64_t, std::pair<Voxel, Voxel>> boxes;  ///< bounding box [lo, hi] of each label
};

DirectCounts countDirectly(const LabelVolume& v, std::int64_t background) {
  DirectCounts out;
  for (int z = 0; z < v.dims.nz; ++z)
    for (int y = 0; y < v.dims.ny; ++y)
      for (int x = 0; x < v.dims.nx; ++x) {
        const Voxel c{x, y, z};
        const std::int64_t L = v.at(c);
        if (L == background) continue;
        ++out.voxels[L];
        auto [box, added] = out.boxes.try_emplace(L, c, c);
        if (!added) {
          box->second.first = {std::min(box->second.first.x, x), std::min(box->second.first.y, y),
                               std::min(box->second.first.z, z)};
          box->second.second = {std::max(box->second.second.x, x), std::max(box->second.second.y, y),
                                std::max(box->second.second.z, z)};
        }
        for (Direction n = 0; n < 6; ++n) {
          const Voxel d = c + unitVector(n);
          if (!v.dims.contains(d) || v.at(d) != L) out.surfels[L].push_back(Surfel{c, n}.key());
        }
      }
  for (auto& [L, keys] : out.surfels) std::sort(keys.begin(), keys.end());
  return out;
}

/// The binary image f = L of a label volume, on its own (ThresholdImage-like) interface.
struct LabelIs {
  const LabelVolume* volume;
  std::int64_t label;
  const Dims& dims() const { return volume->dims; }
  bool operator()(int x, int y, int z) const {
    return volume->dims.contains(x, y, z) && volume->at(Voxel{x, y, z}) == label;
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
};

TriangleMesh meshOf(const Surface& s) { return TriangleMesh{s.surfels, s.triangles}; }

/// The triangles as surfel-key triples, each rotated to start at its smallest key (orientation
/// kept), sorted: two meshes with the same surfels and triangles give the same list.
std::vector<std::array<std::uint64_t, 3>> keyTriangles(const Surface& s) {
  std::vector<std::array<std::uint64_t, 3>> out;
  for (const auto& t : s.triangles) {
    std::array<std::uint64_t, 3> k{s.surfels[t[0]].key(), s.surfels[t[1]].key(), s.surfels[t[2]].key()};
    std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());
    out.push_back(k);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::uint64_t> sortedSurfelKeys(const Surface& s) { return ref::sortedKeys(s.surfels); }

template <class T>
std::vector<T> typed(const LabelVolume& v) {
  return std::vector<T>(v.labels.begin(), v.labels.end());
}

struct CheckOptions {
  bool eulerFromVoxels = true;  ///< the voxel Euler identity (cost ~ 27 * volume per label)
  bool binaryPath = true;       ///< each label alone through extract()
  std::size_t binaryPathEvery = 1;  ///< only every k-th label through the binary path
};

/// Every check of the label surfaces `surfaces` of `volume` (a view `view` of it).
void checkLabelSurfaces(const LabelVolume& volume, const VolumeView& view, std::int64_t background,
                        AdjacencyPair pair, const std::vector<LabelSurface>& surfaces, CheckOptions checks) {
  const DirectCounts direct = countDirectly(volume, background);
  ASSERT_EQ(surfaces.size(), direct.voxels.size()) << "one surface per label but the background";
  std::map<std::int64_t, const LabelSurface*> byLabel;
  for (const LabelSurface& ls : surfaces) byLabel[ls.label.as<std::int64_t>()] = &ls;
  std::size_t k = 0;
  for (const auto& [L, voxels] : direct.voxels) {
    SCOPED_TRACE("label " + std::to_string(L));
    const std::size_t index = k++;
    ASSERT_TRUE(byLabel.count(L));
    const LabelSurface& ls = *byLabel[L];
    const Surface& s = ls.surface;
    EXPECT_EQ(ls.voxels, voxels);
    ASSERT_EQ(s.surfels.size(), direct.surfels.at(L).size()) << "surfels = (L, not L) voxel pairs";
    long euler = 0;
    const auto manifold = ref::isClosedManifoldOn(meshOf(s), direct.surfels.at(L), &euler);
    ASSERT_TRUE(manifold);
    EXPECT_EQ(euler, s.euler);

    // Boundaries and Euler characteristics from voxel components of f = L, on the bounding box
    // of L (outside it no voxel is L, as outside the domain).
    const bool deep = surftrack::testing::caseChecked(index);  // the costly checks: all labels but in the sanitized build
    if (checks.eulerFromVoxels && deep) {
      const auto [lo, hi] = direct.boxes.at(L);
      LabelVolume box;
      box.dims = {hi.x - lo.x + 1, hi.y - lo.y + 1, hi.z - lo.z + 1};
      for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
          for (int x = lo.x; x <= hi.x; ++x) box.labels.push_back(volume.at({x, y, z}));
      const LabelIs image{&box, L};
      const ref::VoxelComponents components(image, pair);
      const auto boundaries = components.boundaries();
      EXPECT_EQ(s.boundariesInImage, boundaries.size());
      EXPECT_EQ(s.components.size(), boundaries.size());
      std::multiset<std::size_t> expectedSizes, sizes;
      for (const auto& [key, b] : boundaries) expectedSizes.insert(b.size());
      for (const ComponentFigures& c : s.components) sizes.insert(c.surfels);
      EXPECT_EQ(sizes, expectedSizes);
      std::map<int, std::vector<Voxel>> members;
      for (int z = 0; z < box.dims.nz; ++z)
        for (int y = 0; y < box.dims.ny; ++y)
          for (int x = 0; x < box.dims.nx; ++x)
            if (image(x, y, z)) members[components.component({x, y, z})].push_back({x, y, z});
      long chi = 0;
      for (const auto& [O, voxelsOfO] : members) chi += ref::voxelEuler(voxelsOfO, components, O, pair);
      EXPECT_EQ(s.euler, 2 * chi) << "sum of the boundaries' chi = 2 chi(voxels of L)";
    }

    // The binary path: this label alone.
    if (checks.binaryPath && deep && index % checks.binaryPathEvery == 0) {
      ExtractOptions options;
      options.selection = Selection::label(L);
      options.seed = SeedRule::all();
      options.pair = pair;
      options.threads = 1;
      const Surface alone = extract(view, options);
      EXPECT_EQ(sortedSurfelKeys(alone), sortedSurfelKeys(s));
      EXPECT_EQ(keyTriangles(alone), keyTriangles(s)) << "the same triangles as the binary path";
    }
  }

  // Interfaces: the surfel (c, d) between an A-voxel and a B-voxel is a vertex of both, at the
  // same point.
  std::unordered_map<std::uint64_t, std::array<double, 3>> vertexOf;
  for (const LabelSurface& ls : surfaces)
    for (std::size_t v = 0; v < ls.surface.surfels.size(); ++v)
      vertexOf.emplace(ls.surface.surfels[v].key(), ls.surface.vertices[v]);
  for (const LabelSurface& ls : surfaces) {
    const Surface& a = ls.surface;
    for (std::size_t v = 0; v < a.surfels.size(); ++v) {
      const Surfel& t = a.surfels[v];
      if (!volume.dims.contains(t.outside()) || volume.at(t.outside()) == background) continue;
      const auto it = vertexOf.find(Surfel{t.outside(), opposite(t.n)}.key());
      ASSERT_NE(it, vertexOf.end()) << "label " << ls.label << ": the other side of " << t << " is no vertex";
      ASSERT_EQ(it->second, a.vertices[v]) << "label " << ls.label << ": interface vertex " << t;
    }
  }
}

/// A random label image of one of four shapes, from `seed`.
LabelVolume randomLabels(std::uint32_t seed, std::int64_t& background, std::string& shape) {
  std::mt19937 rng(seed);
  auto uniform = [&](int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); };
  LabelVolume v;
  const int kind = int(seed % 4);
  const int labels = uniform(2, 20);
  // Label values: small, or spread with gaps (and negative for the signed types below).
  std::vector<std::int64_t> values(labels);
  const bool spread = uniform(0, 1);
  for (int i = 0; i < labels; ++i) values[i] = spread ? std::int64_t(i) * 13 + 5 : i;
  background = values[uniform(0, labels - 1)];
  if (uniform(0, 3) == 0) background = 254;  // a background that does not occur (values <= 252)
  const int lo = kind == 0 ? 3 : 6, hi = kind == 0 ? 9 : 16;
  v.dims = {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
  v.labels.resize(v.dims.count());
  auto index = [&](int x, int y, int z) { return (std::size_t(z) * v.dims.ny + y) * v.dims.nx + x; };
  switch (kind) {
    case 0: {  // noise
      shape = "noise";
      for (auto& f : v.labels) f = values[uniform(0, labels - 1)];
      break;
    }
    case 1: {  // Voronoi cells
      shape = "voronoi";
      std::vector<std::array<int, 3>> centres(labels + uniform(0, 6));
      std::vector<std::int64_t> cellLabel(centres.size());
      for (std::size_t c = 0; c < centres.size(); ++c) {
        centres[c] = {uniform(0, v.dims.nx - 1), uniform(0, v.dims.ny - 1), uniform(0, v.dims.nz - 1)};
        cellLabel[c] = values[c % labels];
      }
      for (int z = 0; z < v.dims.nz; ++z)
        for (int y = 0; y < v.dims.ny; ++y)
          for (int x = 0; x < v.dims.nx; ++x) {
            std::size_t best = 0;
            int bestD = 1 << 30;
            for (std::size_t c = 0; c < centres.size(); ++c) {
              const int dx = x - centres[c][0], dy = y - centres[c][1], dz = z - centres[c][2];
              const int d = dx * dx + dy * dy + dz * dz;
              if (d < bestD) bestD = d, best = c;
            }
            v.labels[index(x, y, z)] = cellLabel[best];
          }
      break;
    }
    case 2: {  // balls painted over each other on the background
      shape = "balls";
      for (auto& f : v.labels) f = background;
      for (int b = 0; b < 2 * labels; ++b) {
        const int cx = uniform(0, v.dims.nx - 1), cy = uniform(0, v.dims.ny - 1), cz = uniform(0, v.dims.nz - 1);
        const int r2 = uniform(1, 20);
        const std::int64_t L = values[b % labels];
        for (int z = 0; z < v.dims.nz; ++z)
          for (int y = 0; y < v.dims.ny; ++y)
            for (int x = 0; x < v.dims.nx; ++x)
              if ((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz) <= r2) v.labels[index(x, y, z)] = L;
      }
      break;
    }
    default: {  // oblique layers, cut by a second family
      shape = "layers";
      const int a = uniform(1, 3), b = uniform(0, 3), c = uniform(0, 3), w = uniform(2, 5);
      for (int z = 0; z < v.dims.nz; ++z)
        for (int y = 0; y < v.dims.ny; ++y)
          for (int x = 0; x < v.dims.nx; ++x)
            v.labels[index(x, y, z)] = values[((a * x + b * y + c * z) / w + (x + 2 * z) / (w + 2)) % labels];
      break;
    }
  }
  return v;
}

constexpr AdjacencyPair kPairs[] = {AdjacencyPair::k26_6, AdjacencyPair::k18_6, AdjacencyPair::k6_18,
                                    AdjacencyPair::k6_26};

/// Runs the checks on one random image, its labels stored as T.
template <class T>
void checkRandomImage(std::uint32_t seed) {
  std::int64_t background = 0;
  std::string shape;
  const LabelVolume volume = randomLabels(seed, background, shape);
  const AdjacencyPair pair = kPairs[(seed / 4) % 4];
  SCOPED_TRACE("seed " + std::to_string(seed) + " " + shape + " pair " + toString(pair) + " type " +
               toString(scalarTypeOf<T>()));
  const std::vector<T> data = typed<T>(volume);
  const VolumeView view = VolumeView::of(data.data(), volume.dims);
  LabelOptions options;
  options.background = background;
  options.pair = pair;
  options.threads = 1 + int(seed % 2);
  std::vector<LabelSurface> surfaces;
  try {
    surfaces = extractLabels(view, options);
  } catch (const InvalidInput& e) {
    // Only an image of background alone has nothing to extract.
    const bool allBackground = std::all_of(volume.labels.begin(), volume.labels.end(),
                                           [&](std::int64_t f) { return f == background; });
    EXPECT_TRUE(allBackground) << e.what();
    return;
  }
  checkLabelSurfaces(volume, view, background, pair, surfaces, {});
}

TEST(Labels, FiveHundredRandomLabelImages) {
  for (std::uint32_t seed = 0; seed < 520; ++seed) {
    if (!surftrack::testing::caseChecked(seed)) continue;
    switch (seed % 5) {
      case 0: checkRandomImage<std::uint16_t>(seed); break;
      case 1: checkRandomImage<std::int32_t>(seed); break;
      case 2: checkRandomImage<std::uint8_t>(seed); break;
      case 3: checkRandomImage<std::uint64_t>(seed); break;
      default: checkRandomImage<std::int16_t>(seed); break;
    }
    if (HasFailure()) return;  // one image's failures are enough to read
  }
}

/// A labelled PLY as read back by a reader of its own (not the writer's code): the header's
/// element counts and properties, then float x y z + int label per vertex, uchar 3 + int
/// indices + int label per face, binary little-endian or text.
struct LabelledPly {
  std::vector<std::array<float, 3>> points;
  std::vector<std::int32_t> vertexLabels, faceLabels;
  std::vector<std::array<std::int32_t, 3>> faces;
};

LabelledPly readLabelledPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, format;
  std::vector<std::string> header;
  std::size_t vertices = 0, faces = 0;
  while (std::getline(in, line) && line != "end_header") {
    header.push_back(line);
    std::istringstream words(line);
    std::string word, kind;
    words >> word;
    if (word == "format") words >> format;
    if (word == "element") {
      words >> kind;
      (kind == "vertex" ? vertices : faces) = std::stoul(line.substr(line.rfind(' ') + 1));
    }
  }
  const std::vector<std::string> properties = {"property float x", "property float y", "property float z",
                                               "property int label", "property list uchar int vertex_indices",
                                               "property int label"};
  std::vector<std::string> found;
  for (const std::string& h : header)
    if (h.rfind("property", 0) == 0) found.push_back(h);
  EXPECT_EQ(found, properties);
  LabelledPly ply;
  ply.points.resize(vertices);
  ply.vertexLabels.resize(vertices);
  ply.faces.resize(faces);
  ply.faceLabels.resize(faces);
  const bool binary = format == "binary_little_endian";
  EXPECT_TRUE(binary || format == "ascii") << format;
  for (std::size_t v = 0; v < vertices; ++v) {
    if (binary) {
      in.read(reinterpret_cast<char*>(ply.points[v].data()), 12);
      in.read(reinterpret_cast<char*>(&ply.vertexLabels[v]), 4);
    } else {
      in >> ply.points[v][0] >> ply.points[v][1] >> ply.points[v][2] >> ply.vertexLabels[v];
    }
  }
  for (std::size_t f = 0; f < faces; ++f) {
    int count = 0;
    if (binary) {
      unsigned char n = 0;
      in.read(reinterpret_cast<char*>(&n), 1);
      count = n;
      in.read(reinterpret_cast<char*>(ply.faces[f].data()), 12);
      in.read(reinterpret_cast<char*>(&ply.faceLabels[f]), 4);
    } else {
      in >> count >> ply.faces[f][0] >> ply.faces[f][1] >> ply.faces[f][2] >> ply.faceLabels[f];
    }
    EXPECT_EQ(count, 3);
  }
  EXPECT_TRUE(bool(in)) << path << ": shorter than its header says";
  if (binary) {
    EXPECT_EQ(in.peek(), std::char_traits<char>::eof()) << path << ": longer than its header says";
  }
  return ply;
}

TEST(Labels, OnePlyOfEveryLabelReadsBackWithItsLabelsClosed) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("surftrack-test-labels-ply-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (std::uint32_t seed = 0; seed < 40; ++seed) {
    std::int64_t background = 0;
    std::string shape;
    const LabelVolume volume = randomLabels(seed, background, shape);
    const std::vector<std::int32_t> data = typed<std::int32_t>(volume);
    LabelOptions options;
    options.background = background;
    options.pair = kPairs[seed % 4];
    std::vector<LabelSurface> surfaces;
    try {
      surfaces = extractLabels(VolumeView::of(data.data(), volume.dims), options);
    } catch (const InvalidInput&) {
      continue;  // background alone
    }
    for (const bool binary : {true, false}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + (binary ? " binary" : " text"));
      const std::string path = (dir / "all.ply").string();
      writeLabelSurfaces(surfaces, path, binary);
      const LabelledPly ply = readLabelledPly(path);
      std::size_t vertex = 0, face = 0;
      for (const LabelSurface& ls : surfaces) {
        const Surface& s = ls.surface;
        ASSERT_LE(vertex + s.vertices.size(), ply.points.size());
        ASSERT_LE(face + s.triangles.size(), ply.faces.size());
        for (std::size_t v = 0; v < s.vertices.size(); ++v) {
          ASSERT_EQ(ply.vertexLabels[vertex + v], ls.label.as<std::int32_t>());
          for (int a = 0; a < 3; ++a) ASSERT_EQ(ply.points[vertex + v][a], float(s.vertices[v][a]));
        }
        // The label's faces: its label, indices among its own vertices, and every directed edge
        // once with its reverse once (closed and oriented).
        std::map<std::pair<std::int32_t, std::int32_t>, int> edges;
        for (std::size_t f = 0; f < s.triangles.size(); ++f) {
          ASSERT_EQ(ply.faceLabels[face + f], ls.label.as<std::int32_t>());
          const auto& t = ply.faces[face + f];
          for (int j = 0; j < 3; ++j) {
            ASSERT_GE(t[j], std::int32_t(vertex));
            ASSERT_LT(t[j], std::int32_t(vertex + s.vertices.size()));
            ASSERT_EQ(std::uint32_t(t[j] - std::int32_t(vertex)), s.triangles[f][j]);
            ++edges[{t[j], t[(j + 1) % 3]}];
          }
        }
        for (const auto& [e, count] : edges) {
          ASSERT_EQ(count, 1) << "edge used twice in one direction";
          ASSERT_EQ(edges.count({e.second, e.first}), 1u) << "a border edge";
        }
        vertex += s.vertices.size();
        face += s.triangles.size();
      }
      EXPECT_EQ(vertex, ply.points.size());
      EXPECT_EQ(face, ply.faces.size());
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(Labels, ListsRangesLargestAndSeedsAgreeWithTheBinaryPath) {
  for (std::uint32_t seed = 1000; seed < 1040; ++seed) {
    std::int64_t background = 0;
    std::string shape;
    const LabelVolume volume = randomLabels(seed, background, shape);
    SCOPED_TRACE("seed " + std::to_string(seed) + " " + shape);
    const std::vector<std::int32_t> data = typed<std::int32_t>(volume);
    const VolumeView view = VolumeView::of(data.data(), volume.dims);
    const DirectCounts direct = countDirectly(volume, background);
    if (direct.voxels.size() < 2) continue;
    std::vector<LabelValue> present;
    for (const auto& [L, n] : direct.voxels) present.push_back(L);

    LabelOptions options;
    options.background = background;
    options.labels = LabelSelection::list({present.back(), present.front(), present.back()});
    auto listed = extractLabels(view, options);
    ASSERT_EQ(listed.size(), 2u);
    EXPECT_EQ(listed[0].label, present.front());
    EXPECT_EQ(listed[1].label, present.back());

    options.labels = LabelSelection::range(present[0], present[1]);
    auto ranged = extractLabels(view, options);
    ASSERT_EQ(ranged.size(), 2u);
    EXPECT_EQ(ranged[1].surface.surfels.size(), direct.surfels.at(present[1].as<std::int64_t>()).size());

    options.labels = LabelSelection::all();
    options.boundaries = LabelBoundaries::Largest;
    for (const LabelSurface& ls : extractLabels(view, options)) {
      ExtractOptions alone;
      alone.selection = Selection::label(ls.label);
      alone.seed = SeedRule::largest();
      const Surface s = extract(view, alone);
      EXPECT_EQ(ls.surface.surfels.size(), s.surfels.size()) << "label " << ls.label;
      EXPECT_EQ(ls.surface.boundariesInImage, s.boundariesInImage);
      ASSERT_EQ(ls.surface.components.size(), 1u);
    }

    // Seeds: the voxel's boundary is that of SeedRule::ray(voxel) for its label.
    options.boundaries = LabelBoundaries::All;  // with seeds: the seeds' boundaries
    std::mt19937 rng(seed);
    for (int i = 0; i < 3; ++i) {
      Voxel v{};
      do {
        v = {int(rng() % volume.dims.nx), int(rng() % volume.dims.ny), int(rng() % volume.dims.nz)};
      } while (volume.at(v) == background);
      options.seeds.push_back(v);
    }
    for (const LabelSurface& ls : extractLabels(view, options)) {
      std::set<std::uint64_t> expected;
      for (const Voxel& v : options.seeds)
        if (LabelValue(volume.at(v)) == ls.label) {
          ExtractOptions alone;
          alone.selection = Selection::label(ls.label);
          alone.seed = SeedRule::ray(v);
          for (const Surfel& s : extract(view, alone).surfels) expected.insert(s.key());
        }
      const auto got = sortedSurfelKeys(ls.surface);
      EXPECT_EQ(got, std::vector<std::uint64_t>(expected.begin(), expected.end())) << "label " << ls.label;
    }
  }
}

// A label's Surface carries its image's geometry, as extract()'s does, so that smoothing keeps
// each vertex on its surfel's segment ]c, d[ in physical space (docs/theory.md §8);
// here 2 x 0.5 x 1.5 mm voxels in a mirrored frame, every segment computed again from c and d.
TEST(Labels, SmoothingKeepsEveryVertexOnItsSegmentInPhysicalSpace) {
  std::int64_t background = 0;
  std::string shape;
  const LabelVolume volume = randomLabels(11, background, shape);
  const std::vector<std::int32_t> data = typed<std::int32_t>(volume);
  ImageGeometry g;
  g.spacing = {2.0, 0.5, 1.5};
  g.origin = {-10, 4, 7};
  g.direction = {{{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}};
  LabelOptions options;
  options.background = background;
  std::vector<LabelSurface> surfaces = extractLabels(VolumeView::of(data.data(), volume.dims, g), options);
  ASSERT_FALSE(surfaces.empty()) << shape;
  std::size_t moved = 0, vertices = 0;
  for (LabelSurface& ls : surfaces) {
    Surface& s = ls.surface;
    const std::vector<std::array<double, 3>> before = s.vertices;
    smooth(s);
    for (std::size_t v = 0; v < s.vertices.size(); ++v) {
      const Voxel c = s.surfels[v].inside(), d = s.surfels[v].outside();
      const auto p = g.toPhysical({double(c.x), double(c.y), double(c.z)});
      const auto q = g.toPhysical({double(d.x), double(d.y), double(d.z)});
      const auto& x = s.vertices[v];
      double along = 0, length2 = 0;
      for (int i = 0; i < 3; ++i) along += (x[i] - p[i]) * (q[i] - p[i]), length2 += (q[i] - p[i]) * (q[i] - p[i]);
      const double t = along / length2;
      double off = 0;
      for (int i = 0; i < 3; ++i) off = std::max(off, std::abs(x[i] - p[i] - t * (q[i] - p[i])));
      EXPECT_GT(t, 0.0) << "label " << ls.label << " vertex " << v;
      EXPECT_LT(t, 1.0) << "label " << ls.label << " vertex " << v;
      EXPECT_LT(off, 1e-9) << "label " << ls.label << " vertex " << v << " is off its segment";
      moved += x != before[v];
      ++vertices;
      if (HasFailure()) return;
    }
  }
  EXPECT_GT(moved, vertices / 4) << "smoothing moved the vertices";
}

TEST(Labels, TheSurfacesAreTheSameForAnyNumberOfThreads) {
  std::int64_t background = 0;
  std::string shape;
  const LabelVolume volume = randomLabels(1201, background, shape);
  const std::vector<std::uint32_t> data = typed<std::uint32_t>(volume);
  const VolumeView view = VolumeView::of(data.data(), volume.dims);
  LabelOptions options;
  options.background = background;
  options.threads = 1;
  const auto one = extractLabels(view, options);
  options.threads = 2;
  const auto two = extractLabels(view, options);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].surface.surfels, two[i].surface.surfels);
    EXPECT_EQ(one[i].surface.triangles, two[i].surface.triangles);
  }
}

/// Labels of 64-bit images near the ends of the types and around 2^53, where doubles skip
/// integers (2^53 + 1 rounds to 2^53): every label of a random volume is its own, exactly. The
/// oracle counts voxels and boundary faces in T directly, never through a double.
template <class T>
void expectExactLabels(const std::vector<T>& ids, std::uint32_t seed) {
  const Dims dims{9, 8, 7};
  std::mt19937 rng(seed);
  std::vector<T> data(dims.count());
  for (T& v : data) v = ids[rng() % ids.size()];
  auto at = [&](Voxel c) { return data[std::size_t(c.x + dims.nx * (c.y + dims.ny * c.z))]; };
  std::map<T, std::uint64_t> voxels;
  std::map<T, std::vector<std::uint64_t>> surfels;
  const T background = ids[0];
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x) {
        const Voxel c{x, y, z};
        const T L = at(c);
        if (L == background) continue;
        ++voxels[L];
        for (Direction n = 0; n < 6; ++n)
          if (!dims.contains(c + unitVector(n)) || at(c + unitVector(n)) != L) surfels[L].push_back(Surfel{c, n}.key());
      }
  const VolumeView view = VolumeView::of(data.data(), dims);
  LabelOptions options;
  options.background = background;
  options.threads = 1;
  const std::vector<LabelSurface> surfaces = extractLabels(view, options);
  ASSERT_EQ(surfaces.size(), voxels.size());
  std::size_t k = 0;
  for (const auto& [L, count] : voxels) {
    const LabelSurface& ls = surfaces[k++];
    SCOPED_TRACE("label " + std::to_string(L));
    ASSERT_EQ(ls.label, LabelValue(L));
    ASSERT_EQ(ls.label.text(), std::to_string(L));
    EXPECT_EQ(ls.voxels, count);
    std::vector<std::uint64_t> keys;
    for (const Surfel& s : ls.surface.surfels) keys.push_back(s.key());
    std::sort(keys.begin(), keys.end());
    std::sort(surfels[L].begin(), surfels[L].end());
    EXPECT_EQ(keys, surfels[L]);
    // The single-label paths select the same voxels: a scan, and a seed on one of them.
    ExtractOptions alone;
    alone.selection = Selection::label(L);
    alone.seed = SeedRule::all();
    alone.threads = 1;
    EXPECT_EQ(extract(view, alone).surfels.size(), keys.size());
    alone.seed = SeedRule::fromSurfel(Surfel::fromKey(keys.front()));
    EXPECT_NO_THROW(extract(view, alone));
    // A list of this label alone, and a range of exactly it.
    LabelOptions one = options;
    one.labels = LabelSelection::list({L});
    ASSERT_EQ(extractLabels(view, one).at(0).label, LabelValue(L));
    one.labels = LabelSelection::range(L, L);
    ASSERT_EQ(extractLabels(view, one).size(), 1u);
  }
}

TEST(Labels, SixtyFourBitLabelsAreExact) {
  constexpr std::uint64_t two53 = std::uint64_t(1) << 53;
  const std::vector<std::uint64_t> unsignedIds = {0, two53, two53 + 1, two53 + 2, 864691135501989106ULL,
                                                  864691135501989107ULL, ~std::uint64_t(0), ~std::uint64_t(0) - 1};
  const std::vector<std::int64_t> signedIds = {0, std::numeric_limits<std::int64_t>::min(),
                                               std::numeric_limits<std::int64_t>::min() + 1,
                                               std::numeric_limits<std::int64_t>::max(),
                                               std::int64_t(two53) + 1, -std::int64_t(two53) - 1, -1};
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    expectExactLabels(unsignedIds, seed);
    expectExactLabels(signedIds, seed);
  }
}

TEST(Labels, LabelValueParsesComparesAndConvertsExactly) {
  EXPECT_EQ(LabelValue::parse("18446744073709551615")->magnitude(), ~std::uint64_t(0));
  EXPECT_FALSE(LabelValue::parse("18446744073709551616"));
  EXPECT_EQ(LabelValue::parse("-9223372036854775808")->as<std::int64_t>(), std::numeric_limits<std::int64_t>::min());
  EXPECT_FALSE(LabelValue::parse("-9223372036854775809"));
  EXPECT_FALSE(LabelValue::parse("1.5"));
  EXPECT_FALSE(LabelValue::parse(""));
  EXPECT_FALSE(LabelValue::parse("-"));
  EXPECT_EQ(*LabelValue::parse("-0"), LabelValue(0));
  EXPECT_FALSE(LabelValue::fromDouble(2.5));
  EXPECT_FALSE(LabelValue::fromDouble(0x1p64));
  EXPECT_FALSE(LabelValue::fromDouble(std::nan("")));
  // Order: every pair of a list sorted as integers compares as its integers do.
  const std::vector<LabelValue> sorted = {std::numeric_limits<std::int64_t>::min(), -2, -1, 0, 1,
                                          std::numeric_limits<std::int64_t>::max(),
                                          std::uint64_t(1) << 63, ~std::uint64_t(0)};
  for (std::size_t a = 0; a < sorted.size(); ++a)
    for (std::size_t b = 0; b < sorted.size(); ++b) EXPECT_EQ(sorted[a] < sorted[b], a < b) << a << " " << b;
  EXPECT_TRUE(LabelValue(255).fits<std::uint8_t>());
  EXPECT_FALSE(LabelValue(256).fits<std::uint8_t>());
  EXPECT_TRUE(LabelValue(-128).fits<std::int8_t>());
  EXPECT_FALSE(LabelValue(-129).fits<std::int8_t>());
  EXPECT_FALSE(LabelValue(-1).fits<std::uint64_t>());
  EXPECT_FALSE(LabelValue((std::uint64_t(1) << 53) + 1).fits<double>());
  EXPECT_TRUE(LabelValue(std::uint64_t(1) << 53).fits<double>());
}

TEST(Labels, BadInputIsOneLineInvalidInput) {
  const Dims dims{4, 4, 4};
  std::vector<std::uint16_t> labels(dims.count(), 0);
  labels[21] = 3;
  const VolumeView view = VolumeView::of(labels.data(), dims);
  auto message = [&](const LabelOptions& o, const VolumeView& v) -> std::string {
    try {
      extractLabels(v, o);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "no exception";
  };
  auto expectMessage = [&](const LabelOptions& o, const VolumeView& v, const std::string& part) {
    const std::string m = message(o, v);
    EXPECT_NE(m.find(part), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  };
  const std::vector<float> floats(dims.count(), 1.0f);
  expectMessage({}, VolumeView::of(floats.data(), dims), "integer voxels");
  LabelOptions o;
  o.labels = LabelSelection::list({42});
  expectMessage(o, view, "label 42 does not occur");
  o.labels = LabelSelection::list({});
  expectMessage(o, view, "empty selection");
  o.labels = LabelSelection::list({0});
  expectMessage(o, view, "is the background");
  o.labels = LabelSelection::list({70000});
  expectMessage(o, view, "label 70000 is not a value of uint16");
  o.labels = LabelSelection::range(4, 10);
  expectMessage(o, view, "empty selection: no label in [4, 10]");
  o.labels = LabelSelection::all();
  o.background = 3;
  const std::vector<std::uint16_t> threes(dims.count(), 3);
  expectMessage(o, VolumeView::of(threes.data(), dims), "empty selection");
  o.background = -1;
  expectMessage(o, view, "background -1 is not a value of uint16");
  o.background = 0;
  o.seeds = {Voxel{1, 0, 0}};
  o.boundaries = LabelBoundaries::Largest;
  expectMessage(o, view, "not both");
  o.boundaries = LabelBoundaries::All;
  o.seeds = {Voxel{0, 0, 0}};
  expectMessage(o, view, "on the background");
  o.seeds = {Voxel{9, 0, 0}};
  expectMessage(o, view, "outside the image domain");
}

// ---------------------------------------------------------------------------------------------
// The atlases of mricron-data, when installed.

const char* const kAtlasDirectory = "/usr/share/mricron/templates";

class Atlas : public ::testing::TestWithParam<const char*> {};

/// f(image) on the atlas file's image, which must hold integer labels.
template <class F>
void onAtlasImage(const std::string& path, F&& f) {
  std::visit(
      [&](const auto& image) {
        using T = typename std::decay_t<decltype(image)>::value_type;
        if constexpr (std::is_integral_v<T>)
          f(image);
        else
          FAIL() << path << " holds " << toString(scalarTypeOf<T>()) << " voxels, not labels";
      },
      io::readVolume(path));
}

TEST_P(Atlas, EveryLabelIsAClosedManifoldMeetingItsNeighboursExactly) {
  const std::string path = std::string(kAtlasDirectory) + "/" + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not installed (mricron-data)";
  onAtlasImage(path, [&](const auto& image) {
    LabelVolume volume;
    volume.dims = image.dims();
    volume.labels.assign(image.data().begin(), image.data().end());
    const VolumeView view = VolumeView::of(image.data().data(), image.dims(), image.geometry());
    // Both pairs on the small atlases (2 mm voxels), the default pair on the 1 mm ones (each
    // ctest under a minute on the 2-vCPU machine while other tests run).
    for (AdjacencyPair pair : {AdjacencyPair::k26_6, AdjacencyPair::k6_26}) {
      if (pair != AdjacencyPair::k26_6 && (volume.dims.count() > 2000000 || surftrack::testing::kSanitizedBuild))
        continue;
      SCOPED_TRACE(toString(pair));
      LabelOptions options;
      options.pair = pair;
      const auto surfaces = extractLabels(view, options);
      // The binary path scans the whole image per label: every 8th label.
      CheckOptions checks;
      checks.binaryPathEvery = 8;
      checkLabelSurfaces(volume, view, 0, pair, surfaces, checks);
    }
  });
}

// Shared walls (docs/theory.md §12) on the atlas: each triangle of a label has its reversed twin
// in exactly one other label, or lies on the background's wall (each vertex's surfel then has a
// background voxel); each label a closed oriented 2-manifold (its pinches split or joined, no
// edge left of four triangles) whose vertices at one point are exactly its pinch copies. Points
// as doubled voxel indices (c + d of the vertex's surfel): exact.
TEST_P(Atlas, SharedWallsAreTwinsAndEveryLabelIsAManifold) {
  const std::string path = std::string(kAtlasDirectory) + "/" + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not installed (mricron-data)";
  onAtlasImage(path, [&](const auto& image) {
    const VolumeView view = VolumeView::of(image.data().data(), image.dims(), image.geometry());
    const Dims dims = image.dims();
    auto labelAt = [&](const Voxel& v) -> long long {  // outside the domain: the background
      if (v.x < 0 || v.y < 0 || v.z < 0 || v.x >= dims.nx || v.y >= dims.ny || v.z >= dims.nz) return 0;
      return (long long)image.data()[std::size_t(v.x + std::int64_t(dims.nx) * (v.y + std::int64_t(dims.ny) * v.z))];
    };
    LabelOptions options;
    options.walls = LabelWalls::Shared;
    const auto surfaces = extractLabels(view, options);
    using Key = std::array<int, 3>;
    using Tri = std::array<Key, 3>;
    auto keyOf = [](const Surfel& s) {
      const Voxel c = s.inside(), d = s.outside();
      return Key{c.x + d.x, c.y + d.y, c.z + d.z};
    };
    auto directed = [](Tri t) {
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      return t;
    };
    std::vector<std::pair<Tri, std::size_t>> owners;  // (directed triangle, label index)
    std::size_t copies = 0, joined = 0, pinched = 0;
    for (std::size_t l = 0; l < surfaces.size(); ++l) {
      const LabelSurface& ls = surfaces[l];
      const Surface& s = ls.surface;
      SCOPED_TRACE("label " + ls.label.text());
      EXPECT_EQ(ls.unsplitEdges, 0u);
      const checks::Topology topology = checks::topologyOf(s.vertices.size(), s.triangles);
      EXPECT_TRUE(topology.manifoldVertices) << topology.problem;
      EXPECT_EQ(topology.euler, s.euler);
      std::vector<Key> keys;
      for (const Surfel& f : s.surfels) keys.push_back(keyOf(f));
      for (const auto& t : s.triangles) owners.push_back({directed({keys[t[0]], keys[t[1]], keys[t[2]]}), l});
      std::sort(keys.begin(), keys.end());
      EXPECT_EQ(s.vertices.size() - std::size_t(std::unique(keys.begin(), keys.end()) - keys.begin()), ls.pinchCopies);
      copies += ls.pinchCopies, joined += ls.joinedEdges, pinched += ls.pinchedEdges;
    }
    std::size_t twins = 0, onBackground = 0;
    std::sort(owners.begin(), owners.end());
    for (std::size_t i = 0; i < owners.size(); ++i) {
      const auto& [t, label] = owners[i];
      ASSERT_TRUE(i == 0 || owners[i - 1].first != t) << "a triangle twice the same way";
      const Tri reverse = directed({t[0], t[2], t[1]});
      const auto back = std::lower_bound(owners.begin(), owners.end(), std::pair<Tri, std::size_t>{reverse, 0});
      if (back != owners.end() && back->first == reverse) {
        ASSERT_NE(back->second, label) << "a triangle and its reverse in one label";
        ++twins;
        continue;
      }
      ++onBackground;
      for (const Key& k : t) {  // the vertex's surfel: the voxels k / 2 and (k + 1) / 2
        const Voxel c{k[0] >> 1, k[1] >> 1, k[2] >> 1}, d{(k[0] + 1) >> 1, (k[1] + 1) >> 1, (k[2] + 1) >> 1};
        ASSERT_TRUE(labelAt(c) == 0 || labelAt(d) == 0) << "a triangle without its twin off the background";
      }
    }
    EXPECT_GT(twins, 0u);
    std::cout << "[ study ] " << GetParam() << ": " << surfaces.size() << " labels, " << twins
              << " wall triangles with their twin, " << onBackground << " on the background; " << pinched
              << " pinched edges (" << joined << " taken as joined), " << copies << " vertex copies\n";
  });
}

// The complex smoothed (10 iterations) and decimated (reduce 0.8) on a label map (docs/theory.md
// §12): each triangle of a label has its reversed twin at bit-identical points in another label,
// or lies on the background's wall (labelAt(v) == 0 for a voxel of each vertex's surfel); each
// label closed, oriented, with the Euler characteristic and components of its undecimated self;
// the labels' triangles, summed, within 5 % of their target both ways, and no label below 95 % of
// its own (a label at its target gives at most 4 % more to a neighbour above its own; one label
// alone may keep more than its target where its thin tracts refuse collapses: counted).
template <class LabelAt>
void checkSmoothedDecimatedComplex(const VolumeView& view, LabelAt&& labelAt, const std::string& name) {
  LabelOptions options;
  options.walls = LabelWalls::Shared;
  const auto before = extractLabels(view, options);
  SmoothOptions smooth;
  smooth.iterations = 10;
  options.smooth = smooth;
  DecimateOptions decimate;
  decimate.reduction = 0.8;
  options.decimate = decimate;
  const auto after = extractLabels(view, options);
  ASSERT_EQ(before.size(), after.size());
  std::map<surftrack::testing::DirectedTriangle, std::size_t> owner;
  std::size_t triangles = 0, target = 0, above = 0;
  double mostAbove = 0;
  for (std::size_t l = 0; l < after.size(); ++l) {
    const Surface &s0 = before[l].surface, &s = after[l].surface;
    SCOPED_TRACE("label " + after[l].label.text());
    const checks::Topology t0 = checks::topologyOf(s0.vertices.size(), s0.triangles);
    const checks::Topology t1 = checks::topologyOf(s.vertices.size(), s.triangles);
    EXPECT_TRUE(t1.manifoldVertices) << t1.problem;
    EXPECT_EQ(t1.euler, t0.euler);
    EXPECT_EQ(t1.components, t0.components);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : s.triangles) {
      for (int j = 0; j < 3; ++j) ++uses[{t[std::size_t(j)], t[std::size_t((j + 1) % 3)]}];
      const auto d = surftrack::testing::directed(surftrack::testing::bitsOf(s.vertices[t[0]]),
                                                  surftrack::testing::bitsOf(s.vertices[t[1]]),
                                                  surftrack::testing::bitsOf(s.vertices[t[2]]));
      ASSERT_TRUE(owner.emplace(d, l).second) << "a triangle twice the same way";
    }
    for (const auto& [e, n] : uses) {
      const auto back = uses.find({e.second, e.first});
      ASSERT_TRUE(back != uses.end() && back->second == n) << "not closed";
    }
    ASSERT_TRUE(after[l].decimate.has_value());
    const double own = double(after[l].decimate->targetTriangles);
    EXPECT_GE(double(s.triangles.size()), 0.95 * own) << "below its target";
    above += double(s.triangles.size()) > 1.05 * own;
    if (own > 0) mostAbove = std::max(mostAbove, double(s.triangles.size()) / own - 1);
    triangles += s.triangles.size();
    target += after[l].decimate->targetTriangles;
  }
  std::size_t twins = 0;
  for (std::size_t l = 0; l < after.size(); ++l) {
    const Surface& s = after[l].surface;
    for (const auto& t : s.triangles) {
      const auto reverse = surftrack::testing::directed(surftrack::testing::bitsOf(s.vertices[t[0]]),
                                                        surftrack::testing::bitsOf(s.vertices[t[2]]),
                                                        surftrack::testing::bitsOf(s.vertices[t[1]]));
      const auto twin = owner.find(reverse);
      if (twin != owner.end()) {
        ASSERT_NE(twin->second, l) << "a triangle and its reverse in one label";
        ++twins;
        continue;
      }
      for (std::uint32_t v : t)
        ASSERT_TRUE(labelAt(s.surfels[v].inside()) == 0 || labelAt(s.surfels[v].outside()) == 0)
            << "a triangle without its twin off the background";
    }
  }
  EXPECT_GT(twins, 0u);
  EXPECT_LE(double(triangles), 1.05 * double(target));
  EXPECT_GE(double(triangles), 0.95 * double(target));
  std::cout << "[ study ] " << name << ", smooth 10, reduce 0.8: " << triangles << " triangles for a target of "
            << target << ", " << twins << " with their twin; " << above << " of " << after.size()
            << " labels above 5 % of their own target (at most +" << std::lround(100 * mostAbove) << " %)\n";
}

TEST_P(Atlas, SmoothedAndDecimatedComplexKeepsItsWallsAndTopology) {
  const std::string path = std::string(kAtlasDirectory) + "/" + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not installed (mricron-data)";
  if (surftrack::testing::kSanitizedBuild) GTEST_SKIP() << "a whole atlas decimated: too slow sanitized";
  onAtlasImage(path, [&](const auto& image) {
    const Dims dims = image.dims();
    checkSmoothedDecimatedComplex(
        VolumeView::of(image.data().data(), dims, image.geometry()),
        [&](const Voxel& v) -> long long {  // outside the domain: the background
          if (!dims.contains(v)) return 0;
          return (long long)image.data()[std::size_t(v.x + std::int64_t(dims.nx) * (v.y + std::int64_t(dims.ny) * v.z))];
        },
        GetParam());
  });
}

TEST(Labels, SmoothedAndDecimatedVoronoiComplexKeepsItsWallsAndTopology) {
  // 60 Voronoi cells in 40^3 (fixed seed), no background: every wall between two cells but the
  // domain's border.
  const Dims dims{40, 40, 40};
  std::mt19937_64 rng(2512);
  std::uniform_real_distribution<double> at(0, 40);
  std::vector<std::array<double, 3>> sites(60);
  for (auto& p : sites) p = {at(rng), at(rng), at(rng)};
  std::vector<std::uint16_t> labels(dims.count());
  for (int z = 0, i = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x, ++i) {
        double best = 1e300;
        for (std::size_t k = 0; k < sites.size(); ++k) {
          const double d = std::hypot(x - sites[k][0], y - sites[k][1], z - sites[k][2]);
          if (d < best) best = d, labels[std::size_t(i)] = std::uint16_t(k + 1);
        }
      }
  checkSmoothedDecimatedComplex(
      VolumeView::of(labels.data(), dims),
      [&](const Voxel& v) -> long long {
        return dims.contains(v) ? labels[std::size_t(v.x + dims.nx * (v.y + std::int64_t(dims.ny) * v.z))] : 0;
      },
      "Voronoi 40^3, 60 cells");
}

INSTANTIATE_TEST_SUITE_P(MricronData, Atlas,
                         ::testing::Values("aal.nii.gz", "AICHAmc.nii.gz", "JHU-WhiteMatter-labels-1mm.nii.gz",
                                           "JHU-WhiteMatter-labels-2mm.nii.gz", "brodmann.nii.gz",
                                           "HarvardOxford-cort-maxprob-thr0-1mm.nii.gz", "jhu189.nii.gz"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           name = name.substr(0, name.find('.'));
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
