// The scanning engine of ScanIsoSurface.h. It reads the binary image once into bit sets (one
// bit per voxel, planes z = -1 .. nz), counts the boundary surfels to allocate the mesh once,
// then visits the slabs z..z+1 in order, and each slab row by row: give the cut edges of row j
// their vertex indices, then emit the triangles of the non-trivial cubes of row j - 1 (whose
// edges lie in rows j - 1 and j). Index conventions used throughout:
//  - rows of a plane are numbered j = y + 1 for y in [-1, ny], so a plane has ny + 2 rows;
//  - in a row bit set, voxel x is bit b = x + kRowOffset (see ScanIsoSurface.h);
//  - in the vertex-index arrays, the grid edge whose low voxel is x has column i = x + 1; the
//    x- and y-edges of the two planes of the slab are kept for whole planes (the top plane is
//    the bottom plane of the next slab), the z-edges for two rows only.
// The cube with min corner (x, y, z) has its corners in rows j, j + 1 of planes z, z + 1, bits
// b, b + 1. Its 12 edges (DigitalCube.h) lie in the two planes (x- and y-edges) or between
// them (z-edges); each cut edge gets its vertex index before the first cube around it is visited.
// The vertex order this gives (a function of the edge alone) is reproduced by the merge of a
// threshold's block fragments (core/src/ThresholdBlocks.cpp, scanOrder): change both together.
#include "ScanIsoSurface.h"

#include "MeshComponents.h"

#include <algorithm>
#include <array>
#include <bit>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "ConfigurationTable.h"
#include "DigitalCube.h"
#include "HugePages.h"

#include <boost/pending/disjoint_sets.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace surftrack {
namespace scan {
namespace {

constexpr std::uint64_t bit(int b) { return std::uint64_t(1) << (b & 63); }

/// The word of a bit set shifted down by one bit: bit b of the result is bit b + 1 of `row`.
inline std::uint64_t nextBits(const std::uint64_t* row, int w) {
  return (row[w] >> 1) | (row[w + 1] << 63);
}

/// Bits b and b + 1 of `row`, as a 2-bit number.
inline unsigned twoBits(const std::uint64_t* row, int b) {
  const int w = b >> 6, s = b & 63;
  // For s = 63 the second bit is bit 0 of the next word; otherwise the next word lands at bit
  // 64 - s >= 2 and is masked off.
  return unsigned(((row[w] >> s) | ((row[w + 1] << 1) << (63 - s))) & 3u);
}

/// Word w of the mask of non-trivial cubes (not 0x00 nor 0xFF) of a row of cubes whose corner
/// rows are r0 (y, z), r1 (y + 1, z), r2 (y, z + 1), r3 (y + 1, z + 1): a cube is trivial when
/// its corner columns x and x + 1 are each uniform over the 4 rows and agree with each other.
inline std::uint64_t mixedCubes(const std::uint64_t* r0, const std::uint64_t* r1,
                                const std::uint64_t* r2, const std::uint64_t* r3, int w) {
  auto mixed = [&](int v) { return (r0[v] ^ r1[v]) | (r0[v] ^ r2[v]) | (r0[v] ^ r3[v]); };
  const std::uint64_t column = mixed(w), nextColumn = (column >> 1) | (mixed(w + 1) << 63);
  return column | nextColumn | (r0[w] ^ nextBits(r0, w));
}

/// Calls f(b) for every set bit b of the word w of a bit set.
template <class F>
inline void forEachBit(std::uint64_t word, int w, F&& f) {
  while (word) {
    f(64 * w + std::countr_zero(word));
    word &= word - 1;
  }
}

/// The vertex indices of the cut x- and y-edges of one plane (stale entries of uncut edges are
/// never read): (ny + 2) rows of nx + 2 columns.
struct PlaneEdges {
  std::vector<std::uint32_t> x;  // edge (x, y, z)-(x + 1, y, z)
  std::vector<std::uint32_t> y;  // edge (x, y, z)-(x, y + 1, z)
};

/// The scan of one binary image. Count, prefix sum, fill (as OpenVDB's VolumeToMesh does): the
/// image is binarised plane by plane, the vertices and triangles of every slab z..z+1 are
/// counted, and then runs of slabs are filled in parallel, each writing its vertices and
/// triangles at the offsets the counts give. Vertex indices do not depend on who numbers them,
/// so the mesh is the same, to the byte, for any number of threads.
class Scanner {
 public:
  Scanner(const Dims& dims, AdjacencyPair pair, const RowSource& rows, int threads)
      : dims_(dims), words_(rowWords(dims.nx)), rowCount_(dims.ny + 2),
        columns_(std::size_t(dims.nx) + 2),
        // Left to choose (0), small images take one thread: waking threads would cost more.
        threads_(threads == 0 && dims.count() < (std::size_t(1) << 18) ? 1 : threads),
        arena_(threads_ > 0 ? threads_ : tbb::task_arena::automatic) {
    for (int config = 0; config < 256; ++config) {
      const CubeTriangulation& table = configurationTable(pair, std::uint8_t(config));
      table_[config] = &table;
      std::array<int, CubeTriangulation::kMaxPatches> firstEdge;
      firstEdge.fill(-1);
      for (int k = 0; k < 12; ++k) {
        const int p = table.patchOfEdge[k];
        if (p < 0) continue;
        if (firstEdge[p] < 0)
          firstEdge[p] = k;
        else
          joins_[config].edge[joins_[config].count++] = {std::uint8_t(firstEdge[p]), std::uint8_t(k)};
      }
    }
    // Valid bits: cubes and x-edges have their low voxel x in [-1, nx - 1]; voxels, y- and
    // z-edges have x in [-1, nx].
    cubeMask_.assign(words_, 0);
    voxelMask_.assign(words_, 0);
    for (int x = -1; x <= dims.nx; ++x) {
      const int b = x + kRowOffset;
      voxelMask_[b >> 6] |= bit(b);
      if (x < dims.nx) cubeMask_[b >> 6] |= bit(b);
    }
    // The whole binary image, planes z = -1 .. nz, read once (RowSource::fillRow may be called
    // from several threads at once).
    bits_.assign(std::size_t(dims.nz + 2) * rowCount_ * words_, 0);
    forEach(-1, dims.nz + 1, [&](int z) {
      for (int j = 0; j < rowCount_; ++j) rows.fillRow(j - 1, z, mutableRow(z, j));
    });
  }

  TriangleMesh run() {
    const Layout layout = countSlabs(true);
    const int slabs = layout.slabs();
    if (layout.vertexStart[slabs] > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("scanIsoSurface: more than 2^32 - 1 boundary surfels");
    TriangleMesh mesh;
    // On huge pages (lib/HugePages.h): the mesh is written once, and the front door hands its
    // triangles to the caller as they are (python/src/MarchingCubes.cpp).
    resizeHugePages(mesh.surfels, layout.vertexStart[slabs]);
    resizeHugePages(mesh.triangles, layout.triangleStart[slabs]);
    const int runs = runCount(slabs);
    forEach(0, runs, [&](int r) {
      const auto [first, last] = runSlabs(r, runs, slabs);
      MeshOutput output{*this, mesh, layout.triangleStart[first]};
      Run<MeshOutput> run(*this, output);
      run.fill(layout, first, last);
    });
    return mesh;
  }

  /// The boundaries' surfel counts and first vertices, in the order of their first vertex.
  /// Count, prefix sum, fill as run() does, but a run of slabs joins the vertices of each
  /// patch of its cubes in a union-find (Boost's disjoint sets, as MeshComponents.h) instead of
  /// writing triangles; the sets that reach the first or last slab of a run are joined to
  /// their neighbours' through the vertices the two runs share; then one more pass over the
  /// vertex numbering picks the surfel of each boundary's first vertex.
  std::vector<BoundaryCount> countBoundaries() {
    const Layout layout = countSlabs(false);
    const int slabs = layout.slabs();
    if (layout.vertexStart[slabs] > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("scanBoundaryCounts: more than 2^32 - 1 boundary surfels");
    const int runs = runCount(slabs);
    std::vector<RunSets> sets(runs);
    forEach(0, runs, [&](int r) {
      const auto [first, last] = runSlabs(r, runs, slabs);
      sets[r] = joinRun(layout, first, last, last < slabs);
    });

    // Sets that cross from run r - 1 into run r: one union-find over all of them, joined at
    // each vertex of the slab the two runs share.
    std::vector<std::size_t> openStart(runs + 1, 0);
    for (int r = 0; r < runs; ++r) openStart[r + 1] = openStart[r] + sets[r].open.size();
    const std::size_t openCount = openStart[runs];
    std::vector<std::uint8_t> rank(openCount);
    std::vector<std::uint32_t> parent(openCount);
    boost::disjoint_sets<std::uint8_t*, std::uint32_t*> joined(rank.data(), parent.data());
    for (std::uint32_t i = 0; i < openCount; ++i) joined.make_set(i);
    for (int r = 1; r < runs; ++r) {
      const std::vector<std::uint32_t>& below = sets[r - 1].topSet;
      const std::vector<std::uint32_t>& above = sets[r].bottomSet;
      for (std::size_t i = 0; i < above.size(); ++i)
        joined.union_set(std::uint32_t(openStart[r - 1] + below[i]), std::uint32_t(openStart[r] + above[i]));
    }
    std::vector<BoundaryCount> crossing;  // by root, then compacted
    std::vector<std::uint32_t> slot(openCount, kNone);
    for (int r = 0; r < runs; ++r)
      for (std::size_t i = 0; i < sets[r].open.size(); ++i) {
        const std::uint32_t root = joined.find_set(std::uint32_t(openStart[r] + i));
        if (slot[root] == kNone) {
          slot[root] = std::uint32_t(crossing.size());
          crossing.push_back({0, kNoVertex, {}});
        }
        BoundaryCount& b = crossing[slot[root]];
        b.surfels += sets[r].open[i].surfels;
        b.firstVertex = std::min(b.firstVertex, sets[r].open[i].firstVertex);
      }
    // Each crossing boundary goes to the run that holds its first vertex, among the run's own
    // boundaries in order of first vertex.
    std::sort(crossing.begin(), crossing.end(),
              [](const BoundaryCount& a, const BoundaryCount& b) { return a.firstVertex < b.firstVertex; });
    std::vector<std::size_t> start(runs + 1, 0);
    std::vector<std::vector<BoundaryCount>> merged(runs);
    {
      std::size_t c = 0;
      for (int r = 0; r < runs; ++r) {
        const std::uint64_t end = layout.vertexStart[runSlabs(r, runs, slabs).second];
        std::vector<BoundaryCount>& own = sets[r].closed;
        std::vector<BoundaryCount>& out = merged[r];
        out.reserve(own.size());
        std::size_t k = 0;
        for (; c < crossing.size() && crossing[c].firstVertex < end; ++c) {
          for (; k < own.size() && own[k].firstVertex < crossing[c].firstVertex; ++k) out.push_back(own[k]);
          out.push_back(crossing[c]);
        }
        out.insert(out.end(), own.begin() + std::ptrdiff_t(k), own.end());
        own = {};
        start[r + 1] = start[r] + out.size();
      }
    }
    std::vector<BoundaryCount> out(start[runs]);
    forEach(0, runs, [&](int r) {
      const auto [first, last] = runSlabs(r, runs, slabs);
      SeedOutput output{merged[r].data(), merged[r].data() + merged[r].size()};
      Run<SeedOutput> run(*this, output);
      run.number(layout, first, last);
      std::copy(merged[r].begin(), merged[r].end(), out.begin() + std::ptrdiff_t(start[r]));
    });
    return out;
  }

 private:
  /// f(i) for i in [begin, end): on the arena's threads, or in order on this one.
  template <class F>
  void forEach(int begin, int end, F&& f) {
    if (threads_ == 1) {
      for (int i = begin; i < end; ++i) f(i);
      return;
    }
    arena_.execute([&] { tbb::parallel_for(begin, end, f); });
  }

  const std::uint64_t* row(int z, int j) const {
    return bits_.data() + (std::size_t(z + 1) * rowCount_ + j) * words_;
  }
  std::uint64_t* mutableRow(int z, int j) {
    return bits_.data() + (std::size_t(z + 1) * rowCount_ + j) * words_;
  }

  /// Cut x- and y-edges of row j of plane z; cut z-edges of row j between planes z and z + 1.
  std::size_t planeRowCount(int z, int j) const {
    const std::uint64_t* r = row(z, j);
    const std::uint64_t* up = j + 1 < rowCount_ ? row(z, j + 1) : nullptr;
    std::size_t n = 0;
    for (int w = 0; w < words_ - 1; ++w) {
      n += std::popcount((r[w] ^ nextBits(r, w)) & cubeMask_[w]);
      if (up) n += std::popcount((r[w] ^ up[w]) & voxelMask_[w]);
    }
    return n;
  }
  std::size_t slabRowCount(int z, int j) const {
    const std::uint64_t* lo = row(z, j);
    const std::uint64_t* hi = row(z + 1, j);
    std::size_t n = 0;
    for (int w = 0; w < words_ - 1; ++w) n += std::popcount((lo[w] ^ hi[w]) & voxelMask_[w]);
    return n;
  }

  unsigned cubeConfig(const std::uint64_t* const r[4], int b) const {
    return twoBits(r[0], b) | (twoBits(r[1], b) << 2) | (twoBits(r[2], b) << 4) | (twoBits(r[3], b) << 6);
  }
  std::size_t rowTriangleCount(int z, int j) const {
    const std::uint64_t* const r[4] = {row(z, j), row(z, j + 1), row(z + 1, j), row(z + 1, j + 1)};
    std::size_t n = 0;
    for (int w = 0; w < words_ - 1; ++w)
      forEachBit(mixedCubes(r[0], r[1], r[2], r[3], w) & cubeMask_[w], w,
                 [&](int b) { n += table_[cubeConfig(r, b)]->allTriangles().size(); });
    return n;
  }

  /// The surfel on the grid edge from `low` to low + e_axis, whose low voxel has value `lowValue`.
  static Surfel edgeSurfel(Voxel low, int axis, bool lowValue) {
    if (lowValue) return Surfel{low, directionOf(axis, +1)};
    Voxel high = low;
    high[axis] += 1;
    return Surfel{high, directionOf(axis, -1)};
  }

  static constexpr std::uint32_t kNone = ~std::uint32_t(0);
  static constexpr std::uint64_t kNoVertex = ~std::uint64_t(0);

  /// Where each slab's vertices and triangles start (slab s = z + 1 in [0, nz + 1) numbers the
  /// x-, y-edges of plane z + 1 and the z-edges between z and z + 1, and holds the cubes
  /// between them; plane -1's edges come first of all, before vertexStart[0]).
  struct Layout {
    std::vector<std::size_t> vertexStart, triangleStart;
    int slabs() const { return int(vertexStart.size()) - 1; }
  };

  /// The count pass (triangles only if asked), and its prefix sums.
  Layout countSlabs(bool triangles) {
    const int slabs = dims_.nz + 1;
    Layout layout{std::vector<std::size_t>(slabs + 1), std::vector<std::size_t>(slabs + 1)};
    std::size_t prologue = 0;
    for (int j = 0; j < rowCount_; ++j) prologue += planeRowCount(-1, j);
    forEach(0, slabs, [&](int s) {
      const int z = s - 1;
      std::size_t v = 0, t = 0;
      for (int j = 0; j < rowCount_; ++j) {
        v += planeRowCount(z + 1, j) + slabRowCount(z, j);
        if (triangles && j > 0) t += rowTriangleCount(z, j - 1);
      }
      layout.vertexStart[s + 1] = v;
      layout.triangleStart[s + 1] = t;
    });
    layout.vertexStart[0] = prologue;
    std::partial_sum(layout.vertexStart.begin(), layout.vertexStart.end(), layout.vertexStart.begin());
    std::partial_sum(layout.triangleStart.begin(), layout.triangleStart.end(), layout.triangleStart.begin());
    return layout;
  }

  /// Runs of slabs of about equal work, several per thread; one on one thread.
  int runCount(int slabs) const {
    return threads_ == 1 ? 1 : std::min(slabs, 8 * std::max(1, arena_.max_concurrency()));
  }
  static std::pair<int, int> runSlabs(int r, int runs, int slabs) {
    return {int(std::int64_t(slabs) * r / runs), int(std::int64_t(slabs) * (r + 1) / runs)};
  }

  /// Writes the vertices and triangles of a run into the mesh.
  struct MeshOutput {
    const Scanner& s;
    TriangleMesh& mesh;
    std::size_t triangle;
    void vertex(std::uint32_t v, const Surfel& surfel) { mesh.surfels[v] = surfel; }
    void cube(unsigned config, const std::array<const std::uint32_t*, 12>& edge, int i) {
      for (const auto& t : s.table_[config]->allTriangles())
        mesh.triangles[triangle++] = {edge[t[0]][i], edge[t[1]][i], edge[t[2]][i]};
    }
  };

  /// Joins the vertices of each patch of a run's cubes; vertex v is element v - base.
  struct UnionOutput {
    const Scanner& s;
    boost::disjoint_sets<std::uint8_t*, std::uint32_t*>& sets;
    std::uint32_t base;
    void vertex(std::uint32_t, const Surfel&) {}
    void cube(unsigned config, const std::array<const std::uint32_t*, 12>& edge, int i) {
      // The root of a patch's first edge is found once for the patch's other edges.
      const PatchJoins& joins = s.joins_[config];
      int first = -1;
      std::uint32_t root = 0;
      for (int k = 0; k < joins.count; ++k) {
        if (joins.edge[k][0] != first) {
          first = joins.edge[k][0];
          root = sets.find_set(edge[first][i] - base);
        }
        const std::uint32_t other = sets.find_set(edge[joins.edge[k][1]][i] - base);
        if (other != root) {
          sets.link(root, other);
          root = sets.find_set(root);
        }
      }
    }
  };

  /// Picks the surfels of the vertices `next` .. `end` ask for (in increasing order).
  struct SeedOutput {
    BoundaryCount* next;
    BoundaryCount* end;
    void vertex(std::uint32_t v, const Surfel& surfel) {
      if (next != end && next->firstVertex == v) (next++)->seed = surfel;
    }
  };

  /// What one run of slabs found: its boundaries that lie in its slabs alone ("closed", in
  /// order of first vertex), those that may go on into the run below or above ("open"), and
  /// the open set of each vertex of the slab shared with the run below (the slab before its
  /// first: bottomSet) and of its own last slab, which the run above shares (topSet).
  struct RunSets {
    std::vector<BoundaryCount> closed, open;
    std::vector<std::uint32_t> bottomSet, topSet;
  };

  RunSets joinRun(const Layout& layout, int first, int last, bool sharesTop) const {
    const std::size_t base = first == 0 ? 0 : layout.vertexStart[first - 1];
    const std::size_t own = first == 0 ? 0 : layout.vertexStart[first];
    const std::size_t top = sharesTop ? layout.vertexStart[last - 1] : layout.vertexStart[last];
    const std::size_t end = layout.vertexStart[last], n = end - base;
    std::vector<std::uint8_t> rank(n);
    std::vector<std::uint32_t> parent(n);
    boost::disjoint_sets<std::uint8_t*, std::uint32_t*> sets(rank.data(), parent.data());
    for (std::uint32_t v = 0; v < n; ++v) sets.make_set(v);
    UnionOutput output{*this, sets, std::uint32_t(base)};
    Run<UnionOutput> run(*this, output);
    run.fill(layout, first, last);

    // Every vertex's root (full path compression: parent[v] is its root afterwards); the sets
    // are numbered in order of their first vertex, open ones (bit 31) those with a vertex in a
    // shared slab.
    for (std::uint32_t v = 0; v < n; ++v) parent[v] = sets.find_set(v);
    constexpr std::uint32_t kOpen = std::uint32_t(1) << 31;
    std::vector<std::uint32_t> number(n, kNone);
    RunSets out;
    auto markOpen = [&](std::size_t from, std::size_t to) {
      for (std::size_t g = from; g < to; ++g) {
        std::uint32_t& k = number[parent[g - base]];
        if (k == kNone) {
          k = kOpen | std::uint32_t(out.open.size());
          out.open.push_back({0, kNoVertex, {}});
        }
      }
    };
    markOpen(base, own);
    markOpen(top, end);
    for (std::size_t g = base; g < end; ++g) {
      std::uint32_t& k = number[parent[g - base]];
      if (k == kNone) {
        k = std::uint32_t(out.closed.size());
        out.closed.push_back({0, g, {}});
      }
      if (g < own) continue;  // the run below's vertex
      BoundaryCount& b = k & kOpen ? out.open[k & ~kOpen] : out.closed[k];
      ++b.surfels;
      b.firstVertex = std::min<std::uint64_t>(b.firstVertex, g);
    }
    auto setOf = [&](std::size_t g) { return number[parent[g - base]] & ~kOpen; };
    out.bottomSet.reserve(own - base);
    for (std::size_t g = base; g < own; ++g) out.bottomSet.push_back(setOf(g));
    if (sharesTop)
      for (std::size_t g = top; g < end; ++g) out.topSet.push_back(setOf(g));
    return out;
  }

  /// One thread's run of slabs: its edge-index planes and its cursor into the vertices.
  template <class Output>
  struct Run {
    Run(const Scanner& scanner, Output& output) : s(scanner), out(output) {
      for (PlaneEdges* p : {&bottom, &top}) {
        p->x.assign(std::size_t(s.rowCount_) * s.columns_, 0);
        p->y.assign(std::size_t(s.rowCount_) * s.columns_, 0);
      }
      zEdge.assign(2 * s.columns_, 0);
    }

    /// Numbers the vertices of slabs [first, last) and visits their cubes (a run re-numbers
    /// its first plane's edges itself).
    void fill(const Layout& layout, int first, int last) {
      start(layout, first);
      for (int sl = first; sl < last; ++sl) {
        const int z = sl - 1;
        // Row by row, so that the indices just written are still in cache when read: the
        // cubes of row j need the edges of rows j and j + 1.
        for (int j = 0; j < s.rowCount_; ++j) {
          numberPlaneEdges(z + 1, j, top, true);
          numberSlabEdges(z, j);
          if (j > 0) marchRow(z, j - 1);
        }
        std::swap(bottom, top);
      }
    }

    /// Numbers the vertices of slabs [first, last) only.
    void number(const Layout& layout, int first, int last) {
      vertex = first == 0 ? 0 : std::uint32_t(layout.vertexStart[first]);
      if (first == 0)
        for (int j = 0; j < s.rowCount_; ++j) numberPlaneEdges(-1, j, bottom, true);
      for (int sl = first; sl < last; ++sl)
        for (int j = 0; j < s.rowCount_; ++j) {
          numberPlaneEdges(sl, j, top, true);
          numberSlabEdges(sl - 1, j);
        }
    }

    void start(const Layout& layout, int first) {
      if (first == 0) {
        vertex = 0;
        for (int j = 0; j < s.rowCount_; ++j) numberPlaneEdges(-1, j, bottom, true);
        return;
      }
      // Plane first - 1 was numbered by slab first - 1, row by row between that slab's
      // z-edges: replay the indices without writing the vertices.
      vertex = std::uint32_t(layout.vertexStart[first - 1]);
      for (int j = 0; j < s.rowCount_; ++j) {
        numberPlaneEdges(first - 1, j, bottom, false);
        vertex += std::uint32_t(s.slabRowCount(first - 2, j));
      }
    }

    std::uint32_t addVertex(const Surfel& surfel, bool write) {
      if (write) out.vertex(vertex, surfel);
      return vertex++;
    }

    /// Vertex indices for the cut x- and y-edges of row j (y = j - 1) of plane z.
    void numberPlaneEdges(int z, int j, PlaneEdges& ids, bool write) {
      const std::uint64_t* r = s.row(z, j);
      const std::uint64_t* up = j + 1 < s.rowCount_ ? s.row(z, j + 1) : nullptr;
      std::uint32_t* xIds = ids.x.data() + std::size_t(j) * s.columns_;
      std::uint32_t* yIds = ids.y.data() + std::size_t(j) * s.columns_;
      const int y = j - 1;
      for (int w = 0; w < s.words_ - 1; ++w) {
        forEachBit((r[w] ^ nextBits(r, w)) & s.cubeMask_[w], w, [&](int b) {
          const int x = b - kRowOffset;
          xIds[x + 1] = addVertex(edgeSurfel({x, y, z}, 0, (r[w] >> (b & 63)) & 1), write);
        });
        if (up)
          forEachBit((r[w] ^ up[w]) & s.voxelMask_[w], w, [&](int b) {
            const int x = b - kRowOffset;
            yIds[x + 1] = addVertex(edgeSurfel({x, y, z}, 1, (r[w] >> (b & 63)) & 1), write);
          });
      }
    }

    /// Vertex indices for the cut z-edges of row j between planes z and z + 1.
    void numberSlabEdges(int z, int j) {
      const std::uint64_t* lo = s.row(z, j);
      const std::uint64_t* hi = s.row(z + 1, j);
      std::uint32_t* zIds = zEdge.data() + std::size_t(j & 1) * s.columns_;
      for (int w = 0; w < s.words_ - 1; ++w)
        forEachBit((lo[w] ^ hi[w]) & s.voxelMask_[w], w, [&](int b) {
          const int x = b - kRowOffset;
          zIds[x + 1] = addVertex(edgeSurfel({x, j - 1, z}, 2, (lo[w] >> (b & 63)) & 1), true);
        });
    }

    /// Hands every non-trivial cube with min corner y = j - 1 in the slab between planes z and
    /// z + 1 to the output, with the vertex indices of its 12 edges.
    void marchRow(int z, int j) {
      // Corner rows: r[c] holds the corners with y-bit c & 1 and z-bit c >> 1.
      const std::uint64_t* const r[4] = {s.row(z, j), s.row(z, j + 1), s.row(z + 1, j), s.row(z + 1, j + 1)};
      // Vertex-index rows of the 12 cube edges (DigitalCube.h), to be read at column i = x + 1.
      const std::size_t at = std::size_t(j) * s.columns_, above = at + s.columns_;
      const std::size_t zAt = std::size_t(j & 1) * s.columns_, zAbove = std::size_t((j + 1) & 1) * s.columns_;
      const std::array<const std::uint32_t*, 12> edge = {
          bottom.x.data() + at, bottom.x.data() + above,  // x-edges: y-bit, z-bit
          top.x.data() + at,    top.x.data() + above,
          bottom.y.data() + at, bottom.y.data() + at + 1,  // y-edges: x-bit, z-bit
          top.y.data() + at,    top.y.data() + at + 1,
          zEdge.data() + zAt,    zEdge.data() + zAt + 1,     // z-edges: x-bit, y-bit
          zEdge.data() + zAbove, zEdge.data() + zAbove + 1};
      for (int w = 0; w < s.words_ - 1; ++w)
        forEachBit(mixedCubes(r[0], r[1], r[2], r[3], w) & s.cubeMask_[w], w,
                   [&](int b) { out.cube(s.cubeConfig(r, b), edge, b - kRowOffset + 1); });
    }

    const Scanner& s;
    Output& out;
    PlaneEdges bottom, top;             // planes z and z + 1 of the current slab
    std::vector<std::uint32_t> zEdge;   // z-edges of the slab, rows j and j + 1 at j & 1
    std::uint32_t vertex = 0;
  };

  /// The vertex pairs of each configuration whose union joins the vertices of each patch
  /// (every cut edge to the first cut edge of its patch).
  struct PatchJoins {
    std::uint8_t count = 0;
    std::array<std::array<std::uint8_t, 2>, 12> edge{};
  };

  Dims dims_;
  int words_;
  int rowCount_;
  std::size_t columns_;
  int threads_;
  tbb::task_arena arena_;
  std::array<const CubeTriangulation*, 256> table_{};
  std::array<PatchJoins, 256> joins_{};
  std::vector<std::uint64_t> cubeMask_, voxelMask_;
  std::vector<std::uint64_t> bits_;  // planes z = -1 .. nz of rowCount_ rows of words_ words
};

}  // namespace

TriangleMesh scanRows(const Dims& dims, AdjacencyPair pair, const RowSource& rows, int threads) {
  if (dims.empty()) return {};
  return Scanner(dims, pair, rows, threads).run();
}

std::vector<BoundaryCount> countRows(const Dims& dims, AdjacencyPair pair, const RowSource& rows, int threads) {
  if (dims.empty()) return {};
  return Scanner(dims, pair, rows, threads).countBoundaries();
}

}  // namespace scan

std::vector<std::uint32_t> meshComponents(const TriangleMesh& mesh, std::size_t& count) {
  return triangleComponents(mesh.surfels.size(), mesh.triangles, count);
}

TriangleMesh extractComponent(const TriangleMesh& mesh, const Surfel& seed) {
  const auto it = std::find(mesh.surfels.begin(), mesh.surfels.end(), seed);
  if (it == mesh.surfels.end())
    throw std::invalid_argument("extractComponent: the seed is not a vertex of the mesh");
  std::size_t count = 0;
  const std::vector<std::uint32_t> label = meshComponents(mesh, count);
  const std::uint32_t root = label[std::size_t(it - mesh.surfels.begin())];
  TriangleMesh out;
  std::vector<std::uint32_t> renumber(mesh.surfels.size(), ~0u);
  for (std::size_t v = 0; v < mesh.surfels.size(); ++v)
    if (label[v] == root) {
      renumber[v] = std::uint32_t(out.surfels.size());
      out.surfels.push_back(mesh.surfels[v]);
    }
  for (const auto& t : mesh.triangles)
    if (renumber[t[0]] != ~0u) out.triangles.push_back({renumber[t[0]], renumber[t[1]], renumber[t[2]]});
  return out;
}

std::vector<TriangleMesh> splitComponents(const TriangleMesh& mesh) {
  std::size_t count = 0;
  const std::vector<std::uint32_t> label = meshComponents(mesh, count);
  std::vector<TriangleMesh> out(count);
  std::vector<std::uint32_t> renumber(mesh.surfels.size());
  for (std::size_t v = 0; v < mesh.surfels.size(); ++v) {
    TriangleMesh& m = out[label[v]];
    renumber[v] = std::uint32_t(m.surfels.size());
    m.surfels.push_back(mesh.surfels[v]);
  }
  for (const auto& t : mesh.triangles)
    out[label[t[0]]].triangles.push_back({renumber[t[0]], renumber[t[1]], renumber[t[2]]});
  return out;
}

}  // namespace surftrack
