// A label's figures from its block fragments without its whole mesh in memory
// (LabelBlockFiles.h; docs/theory.md, "A label larger than one merge"). The blocks are grouped
// into the cells of an octree; a cell small enough is merged as one mesh (mergeLabelFragments),
// whose components' figures are kept with only the surfel keys some block outside the cell may
// also hold; sibling cells are combined by joining, through the project's one union-find
// (MeshComponents.h), the components that share such a key. Counts are exact: a surfel is
// counted once, by the smallest cell that holds all four cubes it is a cut edge of.
#include <algorithm>
#include <bit>
#include <limits>
#include <map>

#include "BlockOwnership.h"
#include "Errors.h"
#include "LabelBlockFiles.h"
#include "MeshComponents.h"

namespace surftrack {
namespace {

/// A component of a cell's part of the label: its surfels counted so far (those interior to
/// the cell), triangles, area and volume sums, and its smallest key (which orders components
/// of equal size as the single pass numbers them: by smallest vertex).
struct Part {
  std::uint64_t surfels = 0, triangles = 0;
  double area = 0, volume = 0;
  std::uint64_t firstKey = std::numeric_limits<std::uint64_t>::max();
};

/// A cell's partial result: its components, and the keys on its outer border (by increasing
/// key), each with its component.
struct Partial {
  std::vector<Part> parts;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> border;
};

/// The min corners of the cubes a cell of blocks owns, [lo, hi) per axis (docs/theory.md,
/// "Label maps by blocks": -1 for the cells at the volume's low faces).
struct CubeBox {
  Voxel lo, hi;

  /// Whether every cube the surfel of `key` is a cut edge of lies in the box: then no block
  /// outside it holds the key. Along the surfel's axis the cubes' min corner is min(c, d); on
  /// the two other axes it is c - 1 and c.
  bool holds(std::uint64_t key) const {
    const Surfel s = Surfel::fromKey(key);
    const int axis = axisOf(s.n);
    for (int a = 0; a < 3; ++a) {
      const int first = a == axis ? std::min(s.inside()[a], s.outside()[a]) : s.inside()[a] - 1;
      const int last = a == axis ? first : s.inside()[a];
      if (first < lo[a] || last >= hi[a]) return false;
    }
    return true;
  }
};

struct BlockFile {
  Voxel cell;  ///< the block's index in the grid
  const std::string* path;
  FragmentFileIndex::Entry entry;
};

class Tree {
 public:
  Tree(Dims volume, Dims block, const ImageGeometry& geometry, const LabelOptions& options, std::uint64_t budget)
      : volume_(volume), block_(block), geometry_(geometry), options_(options),
        budget_(budget) {
    options_.figures = false;  // the merges of cells give meshes; the figures are taken here
  }

  /// The partial of the cell of `side` blocks a side from block `at`; `levels` receives the
  /// depth of its tree.
  Partial cell(Voxel at, int side, const std::vector<const BlockFile*>& inside, int& levels) {
    std::uint64_t bytes = 0;
    for (const BlockFile* f : inside) bytes += 8 * f->entry.keys + 12 * f->entry.triangles;
    const CubeBox box = cubes(at, side);
    levels = 0;
    if (side == 1 || bytes <= budget_) return leaf(inside, box);
    const int half = side / 2;
    std::vector<Partial> children;
    for (int k = 0; k < 8; ++k) {
      const Voxel child{at.x + (k & 1) * half, at.y + (k >> 1 & 1) * half, at.z + (k >> 2 & 1) * half};
      std::vector<const BlockFile*> in;
      for (const BlockFile* f : inside)
        if (f->cell.x >= child.x && f->cell.x < child.x + half && f->cell.y >= child.y &&
            f->cell.y < child.y + half && f->cell.z >= child.z && f->cell.z < child.z + half)
          in.push_back(f);
      if (in.empty()) continue;
      int depth = 0;
      children.push_back(cell(child, half, in, depth));
      levels = std::max(levels, depth + 1);
    }
    return combine(children, box);
  }

  std::size_t leaves = 0;

 private:
  CubeBox cubes(Voxel at, int side) const {
    CubeBox box;
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = at[a] == 0 ? -1 : at[a] * block_[a];
      box.hi[a] = int(std::min<long long>((long long)(at[a] + side) * block_[a], volume_[a]));
    }
    return box;
  }

  /// A cell merged as one mesh: its components' figures (componentFigures, as the single pass
  /// computes them), each surfel counted if the cell holds it whole, else kept on the border.
  Partial leaf(const std::vector<const BlockFile*>& inside, const CubeBox& box) {
    ++leaves;
    std::vector<LabelFragment> fragments;
    for (const BlockFile* f : inside) fragments.push_back(readLabelFragment(*f->path, f->entry));
    const LabelSurface merged = mergeLabelFragments(fragments, geometry_, options_);
    std::vector<LabelFragment>().swap(fragments);
    const Surface& s = merged.surface;
    std::vector<std::uint32_t> componentOf;
    const std::vector<ComponentFigures> figures = componentFigures(s.vertices, s.triangles, &componentOf);
    Partial p;
    p.parts.resize(figures.size());
    for (std::size_t c = 0; c < figures.size(); ++c)
      p.parts[c] = {0, figures[c].triangles, figures[c].area, figures[c].volume,
                    std::numeric_limits<std::uint64_t>::max()};
    for (std::size_t v = 0; v < s.surfels.size(); ++v) {
      const std::uint64_t key = s.surfels[v].key();
      Part& part = p.parts[componentOf[v]];
      part.firstKey = std::min(part.firstKey, key);
      if (box.holds(key))
        ++part.surfels;
      else
        p.border.push_back({key, componentOf[v]});
    }
    return p;
  }

  /// Sibling cells' partials as one: components sharing a border key joined, the keys the
  /// larger cell holds whole counted.
  static Partial combine(std::vector<Partial>& children, const CubeBox& box) {
    std::size_t nodes = 0;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> border;
    for (const Partial& c : children) {
      for (const auto& [key, part] : c.border) border.push_back({key, std::uint32_t(nodes + part)});
      nodes += c.parts.size();
    }
    std::sort(border.begin(), border.end());
    std::vector<std::array<std::uint32_t, 2>> joins;
    for (std::size_t i = 1; i < border.size(); ++i)
      if (border[i].first == border[i - 1].first) joins.push_back({border[i - 1].second, border[i].second});
    std::size_t count = 0;
    const std::vector<std::uint32_t> componentOf = joinedComponents(nodes, joins, count);
    Partial p;
    p.parts.resize(count);
    std::size_t node = 0;
    for (Partial& c : children) {
      for (const Part& part : c.parts) {
        Part& into = p.parts[componentOf[node++]];
        into.surfels += part.surfels;
        into.triangles += part.triangles;
        into.area += part.area;
        into.volume += part.volume;
        into.firstKey = std::min(into.firstKey, part.firstKey);
      }
      std::vector<Part>().swap(c.parts);
      std::vector<std::pair<std::uint64_t, std::uint32_t>>().swap(c.border);
    }
    for (std::size_t i = 0; i < border.size(); ++i) {
      if (i > 0 && border[i].first == border[i - 1].first) continue;  // a key once
      const std::uint32_t c = componentOf[border[i].second];
      if (box.holds(border[i].first))
        ++p.parts[c].surfels;
      else
        p.border.push_back({border[i].first, c});
    }
    return p;
  }

  Dims volume_, block_;
  ImageGeometry geometry_;
  LabelOptions options_;
  std::uint64_t budget_;
};

}  // namespace

LabelFigures labelFiguresByTree(LabelValue label, const std::vector<std::string>& paths, Dims volume, Dims block,
                                const ImageGeometry& geometry, const LabelOptions& options, std::uint64_t budget) {
  for (int a = 0; a < 3; ++a)
    if (volume[a] < 1 || block[a] < 1) throw InvalidInput("the volume and the block need positive sizes");
  LabelFigures out;
  out.label = label;
  std::vector<BlockFile> files;
  std::map<std::array<int, 3>, const std::string*> seen;
  Voxel grid;
  for (int a = 0; a < 3; ++a) grid[a] = (volume[a] + block[a] - 1) / block[a];
  for (const std::string& path : paths) {
    const FragmentFileIndex index = readFragmentFileIndex(path);
    if (!(index.volume == volume)) throw InvalidInput("fragment file '" + path + "' is of another volume");
    Voxel cell;
    for (int a = 0; a < 3; ++a) {
      cell[a] = index.lo[a] / block[a];
      if (index.lo[a] % block[a] != 0 || index.hi[a] != std::min(index.lo[a] + block[a], volume[a]) ||
          cell[a] >= grid[a])
        throw InvalidInput("fragment file '" + path + "' is not a block of the grid " + boxText({}, grid));
    }
    if (!seen.emplace(std::array<int, 3>{cell.x, cell.y, cell.z}, &path).second)
      throw InvalidInput("fragment files '" + *seen[{cell.x, cell.y, cell.z}] + "' and '" + path +
                         "' are of the same block");
    if (const auto* e = index.find(label)) {
      files.push_back({cell, &path, *e});
      out.voxels += e->voxels;
    }
  }
  if (files.empty()) throw InvalidInput("no fragment file holds label " + label.text());

  const int side = int(std::bit_ceil(unsigned(std::max({grid.x, grid.y, grid.z}))));
  Tree tree(volume, block, geometry, options, budget);
  std::vector<const BlockFile*> all;
  for (const BlockFile& f : files) all.push_back(&f);
  Partial root = tree.cell(Voxel{0, 0, 0}, side, all, out.levels);
  out.leaves = tree.leaves;
  if (!root.border.empty()) throw InternalError("labelFiguresByTree: a key on the border of the whole volume");
  std::vector<Part>& parts = root.parts;
  // By decreasing size, then by smallest vertex: componentFigures' order on the whole mesh.
  std::sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) {
    return a.surfels != b.surfels ? a.surfels > b.surfels : a.firstKey < b.firstKey;
  });
  for (const Part& p : parts) {
    ComponentFigures f;
    f.surfels = p.surfels;
    f.triangles = p.triangles;
    f.edges = 3 * p.triangles / 2;  // closed: every edge borders two triangles
    f.euler = (long long)f.surfels - (long long)f.edges + (long long)f.triangles;
    f.area = p.area;
    f.volume = p.volume;
    out.components.push_back(f);
  }
  return out;
}

}  // namespace surftrack
