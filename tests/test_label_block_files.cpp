// Fragment files and the tree of a label's figures (LabelBlockFiles.h; docs/api.md, "Fragment
// files and labels larger than one merge"; docs/theory.md, "A label larger than one merge")
// against the single pass extractLabels, on random int64 label images (labels at both ends of
// the range, negative ones, noise for many components, boxes with tunnels for genus) cut into
// random regular grids of blocks:
// - a file read back gives the fragments written, label for label, and the same bytes when
//   written again;
// - mergeLabelFragmentFiles is the single pass's surface, array for array, and
//   writeLabelMeshStreamed writes writeSurface's bytes of it (small chunks and whole fragments);
// - labelFiguresByTree with budget 0 (single-block leaves, the grid's whole depth) and with a
//   random budget gives every count, Euler characteristic and the components' order exactly,
//   area and volume within 1e-9 relative (summed by groups: another order of the same terms).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "LabelBlockFiles.h"

using namespace surftrack;

namespace {

const std::int64_t kPool[] = {std::numeric_limits<std::int64_t>::min(), -7, -1, 1, 2, 300,
                              std::numeric_limits<std::int64_t>::max()};

std::string bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void expectNear(double got, double want) {
  EXPECT_LE(std::abs(got - want), 1e-9 * std::max(1.0, std::abs(want))) << got << " vs " << want;
}

TEST(LabelBlockFiles, FilesMergesAndTreeFiguresAreTheSinglePass) {
  std::mt19937_64 rng(20261203);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("surftrack-block-files-" + std::to_string(rng()));
  std::filesystem::create_directories(dir);
  int deepest = 0;
  for (int iteration = 0; iteration < 60; ++iteration) {
    const Dims dims{uniform(5, 14), uniform(5, 14), uniform(5, 14)};
    std::vector<std::int64_t> labels(dims.count(), 0);
    auto at = [&](int x, int y, int z) -> std::int64_t& {
      return labels[(std::size_t(z) * dims.ny + y) * dims.nx + x];
    };
    for (int b = uniform(1, 8); b > 0; --b) {
      const std::int64_t L = kPool[std::size_t(uniform(0, int(std::size(kPool)) - 1))];
      const int x0 = uniform(0, dims.nx - 1), y0 = uniform(0, dims.ny - 1), z0 = uniform(0, dims.nz - 1);
      const int x1 = std::min(dims.nx, x0 + uniform(1, 8)), y1 = std::min(dims.ny, y0 + uniform(1, 8)),
                z1 = std::min(dims.nz, z0 + uniform(1, 8));
      for (int z = z0; z < z1; ++z)
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x)
            // A tunnel along z through the middle of wide boxes: a handle.
            at(x, y, z) = (x1 - x0 >= 3 && y1 - y0 >= 3 && x == (x0 + x1) / 2 && y == (y0 + y1) / 2) ? 0 : L;
    }
    for (int n = uniform(0, int(labels.size()) / 10); n > 0; --n)
      labels[std::size_t(uniform(0, int(labels.size()) - 1))] = kPool[std::size_t(uniform(0, 6))];
    ImageGeometry geometry;
    geometry.spacing = {0.5, 2.0, 1.25};
    geometry.origin = {1.0, -3.0, 0.5};
    if (iteration % 4 == 3) geometry.direction = {{{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}};  // mirrored
    LabelOptions o;
    o.threads = 1;
    std::vector<LabelSurface> single;
    try {
      single = extractLabels(VolumeView::of(labels.data(), dims, geometry), o);
    } catch (const InvalidInput&) {
      continue;  // no label
    }

    const Dims block{uniform(2, 6), uniform(2, 6), uniform(1, 6)};  // at most 7 x 7 x 14 files
    std::vector<std::string> paths;
    for (int z = 0; z < dims.nz; z += block.nz)
      for (int y = 0; y < dims.ny; y += block.ny)
        for (int x = 0; x < dims.nx; x += block.nx) {
          const Voxel lo{x, y, z}, hi{std::min(x + block.nx, dims.nx), std::min(y + block.ny, dims.ny),
                                      std::min(z + block.nz, dims.nz)};
          const Voxel end{std::min(hi.x + 1, dims.nx), std::min(hi.y + 1, dims.ny), std::min(hi.z + 1, dims.nz)};
          const VolumeView box = VolumeView::strided(&at(x, y, z), Dims{end.x - x, end.y - y, end.z - z},
                                                     {1, std::ptrdiff_t(dims.nx), std::ptrdiff_t(dims.nx) * dims.ny});
          const std::vector<LabelFragment> fragments = scanLabelBlock(box, lo, dims, lo, hi, o);
          const std::string path = (dir / std::to_string(paths.size()).append(".frag")).string();
          writeLabelFragmentFile(path, dims, lo, hi, fragments);
          paths.push_back(path);
          // Read back: the same fragments; written again: the same bytes.
          const FragmentFileIndex index = readFragmentFileIndex(path);
          ASSERT_EQ(index.entries.size(), fragments.size());
          EXPECT_EQ(index.volume, dims);
          for (std::size_t i = 0; i < fragments.size(); ++i) {
            const LabelFragment back = readLabelFragment(path, index.entries[i]);
            EXPECT_EQ(back.label, fragments[i].label);
            EXPECT_EQ(back.voxels, fragments[i].voxels);
            EXPECT_EQ(back.keys, fragments[i].keys);
            EXPECT_EQ(back.triangles, fragments[i].triangles);
          }
          if (iteration % 10 == 0) {
            const std::string first = bytesOf(path);
            writeLabelFragmentFile(path, dims, lo, hi, fragments);
            EXPECT_EQ(bytesOf(path), first);
          }
        }

    for (const LabelSurface& want : single) {
      const LabelSurface got = mergeLabelFragmentFiles(want.label, paths, geometry, o);
      ASSERT_EQ(got.surface.vertices, want.surface.vertices);
      ASSERT_EQ(got.surface.triangles, want.surface.triangles);
      EXPECT_EQ(got.voxels, want.voxels);
      // Streamed (chunks of 16 items, and whole fragments): writeSurface's bytes (odd
      // iterations, the mirrored geometries among them).
      if (iteration % 2 == 1) writeSurface(want.surface, (dir / "want.ply").string());
      for (const std::uint64_t budget : {std::uint64_t(0), std::uint64_t(1) << 32}) {
        if (iteration % 2 == 0) break;
        const LabelMeshCounts n = writeLabelMeshStreamed(want.label, paths, geometry, (dir / "got.ply").string(), budget);
        EXPECT_EQ(n.vertices, want.surface.vertices.size());
        EXPECT_EQ(n.triangles, want.surface.triangles.size());
        ASSERT_EQ(bytesOf((dir / "got.ply").string()), bytesOf((dir / "want.ply").string())) << want.label.text();
      }
      std::uint64_t weight = 0;
      for (const std::string& p : paths) {
        const FragmentFileIndex index = readFragmentFileIndex(p);  // find() points into it
        if (const auto* e = index.find(want.label)) weight += 8 * e->keys + 12 * e->triangles;
      }
      for (const std::uint64_t budget : {std::uint64_t(0), std::uniform_int_distribution<std::uint64_t>(0, weight)(rng)}) {
        const LabelFigures f = labelFiguresByTree(want.label, paths, dims, block, geometry, o, budget);
        if (budget == 0) deepest = std::max(deepest, f.levels);
        EXPECT_EQ(f.voxels, want.voxels);
        const auto& w = want.surface.components;
        ASSERT_EQ(f.components.size(), w.size()) << want.label.text();
        for (std::size_t c = 0; c < w.size(); ++c) {
          EXPECT_EQ(f.components[c].surfels, w[c].surfels);
          EXPECT_EQ(f.components[c].triangles, w[c].triangles);
          EXPECT_EQ(f.components[c].edges, w[c].edges);
          EXPECT_EQ(f.components[c].euler, w[c].euler);
          expectNear(f.components[c].area, w[c].area);
          expectNear(f.components[c].volume, w[c].volume);
        }
      }
    }
    for (const std::string& p : paths) std::filesystem::remove(p);
  }
  std::filesystem::remove_all(dir);
  EXPECT_GE(deepest, 3);  // some grid was 8 blocks or more a side: a tree of 3 levels or more
}

}  // namespace
