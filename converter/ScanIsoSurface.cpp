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

class Scanner {
 public:
  Scanner(const Dims& dims, AdjacencyPair pair, const RowSource& rows)
      : dims_(dims), words_(rowWords(dims.nx)), rowCount_(dims.ny + 2),
        columns_(std::size_t(dims.nx) + 2) {
    for (int config = 0; config < 256; ++config)
      table_[config] = &configurationTable(pair, std::uint8_t(config));
    // Valid bits: cubes and x-edges have their low voxel x in [-1, nx - 1]; voxels, y- and
    // z-edges have x in [-1, nx].
    cubeMask_.assign(words_, 0);
    voxelMask_.assign(words_, 0);
    for (int x = -1; x <= dims.nx; ++x) {
      const int b = x + kRowOffset;
      voxelMask_[b >> 6] |= bit(b);
      if (x < dims.nx) cubeMask_[b >> 6] |= bit(b);
    }
    // The whole binary image, planes z = -1 .. nz, read once.
    bits_.assign(std::size_t(dims.nz + 2) * rowCount_ * words_, 0);
    for (int z = -1; z <= dims.nz; ++z)
      for (int j = 0; j < rowCount_; ++j) rows.fillRow(j - 1, z, mutableRow(z, j));
    for (PlaneEdges* p : {&bottom_, &top_}) {
      p->x.assign(std::size_t(rowCount_) * columns_, 0);
      p->y.assign(std::size_t(rowCount_) * columns_, 0);
    }
    zEdge_.assign(2 * columns_, 0);
  }

  TriangleMesh run() {
    // Allocating the mesh once costs much less than growing it (copies, page faults) on
    // noisy images. A closed surface of genus g with V vertices has 2V - 4 + 4g triangles.
    const std::size_t surfels = countSurfels();
    mesh_.surfels.reserve(surfels);
    mesh_.triangles.reserve(2 * surfels);
    for (int j = 0; j < rowCount_; ++j) numberPlaneEdges(-1, j, bottom_);
    for (int z = -1; z < dims_.nz; ++z) {
      // Row by row, so that the indices just written are still in cache when read: the cubes
      // of row j need the edges of rows j and j + 1.
      for (int j = 0; j < rowCount_; ++j) {
        numberPlaneEdges(z + 1, j, top_);
        numberSlabEdges(z, j);
        if (j > 0) marchRow(z, j - 1);
      }
      std::swap(bottom_, top_);
    }
    return std::move(mesh_);
  }

 private:
  std::uint64_t* mutableRow(int z, int j) {
    return bits_.data() + (std::size_t(z + 1) * rowCount_ + j) * words_;
  }
  const std::uint64_t* row(int z, int j) const {
    return bits_.data() + (std::size_t(z + 1) * rowCount_ + j) * words_;
  }

  /// The number of cut grid edges, i.e. of boundary surfels.
  std::size_t countSurfels() const {
    std::size_t n = 0;
    for (int z = -1; z <= dims_.nz; ++z)
      for (int j = 0; j < rowCount_; ++j) {
        const std::uint64_t* r = row(z, j);
        const std::uint64_t* up = j + 1 < rowCount_ ? row(z, j + 1) : r;  // y-edges
        const std::uint64_t* next = z < dims_.nz ? row(z + 1, j) : r;     // z-edges
        for (int w = 0; w < words_ - 1; ++w) {
          const std::uint64_t cuts = ((r[w] ^ nextBits(r, w)) & cubeMask_[w]) |
                                     ((r[w] ^ up[w]) & voxelMask_[w]) | ((r[w] ^ next[w]) & voxelMask_[w]);
          if (cuts)  // most words of most images: no popcount at all
            n += std::popcount((r[w] ^ nextBits(r, w)) & cubeMask_[w]) +
                 std::popcount((r[w] ^ up[w]) & voxelMask_[w]) +
                 std::popcount((r[w] ^ next[w]) & voxelMask_[w]);
        }
      }
    return n;
  }

  std::uint32_t addVertex(const Surfel& s) {
    if (mesh_.surfels.size() >= std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("scanIsoSurface: more than 2^32 - 1 boundary surfels");
    mesh_.surfels.push_back(s);
    return std::uint32_t(mesh_.surfels.size() - 1);
  }

  /// The surfel on the grid edge from `low` to low + e_axis, whose low voxel has value `lowValue`.
  static Surfel edgeSurfel(Voxel low, int axis, bool lowValue) {
    if (lowValue) return Surfel{low, directionOf(axis, +1)};
    Voxel high = low;
    high[axis] += 1;
    return Surfel{high, directionOf(axis, -1)};
  }

  /// Vertex indices for the cut x- and y-edges of row j (y = j - 1) of plane z.
  void numberPlaneEdges(int z, int j, PlaneEdges& ids) {
    const std::uint64_t* r = row(z, j);
    const std::uint64_t* up = j + 1 < rowCount_ ? row(z, j + 1) : nullptr;
    std::uint32_t* xIds = ids.x.data() + std::size_t(j) * columns_;
    std::uint32_t* yIds = ids.y.data() + std::size_t(j) * columns_;
    const int y = j - 1;
    for (int w = 0; w < words_ - 1; ++w) {
      forEachBit((r[w] ^ nextBits(r, w)) & cubeMask_[w], w, [&](int b) {
        const int x = b - kRowOffset;
        xIds[x + 1] = addVertex(edgeSurfel({x, y, z}, 0, (r[w] >> (b & 63)) & 1));
      });
      if (up)
        forEachBit((r[w] ^ up[w]) & voxelMask_[w], w, [&](int b) {
          const int x = b - kRowOffset;
          yIds[x + 1] = addVertex(edgeSurfel({x, y, z}, 1, (r[w] >> (b & 63)) & 1));
        });
    }
  }

  /// Vertex indices for the cut z-edges of row j between planes z and z + 1.
  void numberSlabEdges(int z, int j) {
    const std::uint64_t* lo = row(z, j);
    const std::uint64_t* hi = row(z + 1, j);
    std::uint32_t* zIds = zEdge_.data() + std::size_t(j & 1) * columns_;
    for (int w = 0; w < words_ - 1; ++w)
      forEachBit((lo[w] ^ hi[w]) & voxelMask_[w], w, [&](int b) {
        const int x = b - kRowOffset;
        zIds[x + 1] = addVertex(edgeSurfel({x, j - 1, z}, 2, (lo[w] >> (b & 63)) & 1));
      });
  }

  /// Emits the triangles of every non-trivial cube with min corner y = j - 1 in the slab
  /// between planes z and z + 1.
  void marchRow(int z, int j) {
    // Corner rows: rc holds the corners with y-bit c & 1 and z-bit c >> 1.
    const std::uint64_t* r0 = row(z, j);
    const std::uint64_t* r1 = row(z, j + 1);
    const std::uint64_t* r2 = row(z + 1, j);
    const std::uint64_t* r3 = row(z + 1, j + 1);
    // Vertex-index rows of the 12 cube edges (DigitalCube.h), to be read at column i = x + 1.
    const std::size_t at = std::size_t(j) * columns_, above = at + columns_;
    const std::size_t zAt = std::size_t(j & 1) * columns_, zAbove = std::size_t((j + 1) & 1) * columns_;
    const std::array<const std::uint32_t*, 12> edge = {
        bottom_.x.data() + at, bottom_.x.data() + above,  // x-edges: y-bit, z-bit
        top_.x.data() + at,    top_.x.data() + above,
        bottom_.y.data() + at, bottom_.y.data() + at + 1,  // y-edges: x-bit, z-bit
        top_.y.data() + at,    top_.y.data() + at + 1,
        zEdge_.data() + zAt,    zEdge_.data() + zAt + 1,     // z-edges: x-bit, y-bit
        zEdge_.data() + zAbove, zEdge_.data() + zAbove + 1};
    for (int w = 0; w < words_ - 1; ++w)
      forEachBit(mixedCubes(r0, r1, r2, r3, w) & cubeMask_[w], w, [&](int b) {
        const unsigned config =
            twoBits(r0, b) | (twoBits(r1, b) << 2) | (twoBits(r2, b) << 4) | (twoBits(r3, b) << 6);
        const int i = b - kRowOffset + 1;
        for (const auto& t : table_[config]->allTriangles())
          mesh_.triangles.push_back({edge[t[0]][i], edge[t[1]][i], edge[t[2]][i]});
      });
  }

  Dims dims_;
  int words_;
  int rowCount_;
  std::size_t columns_;
  std::array<const CubeTriangulation*, 256> table_{};
  std::vector<std::uint64_t> cubeMask_, voxelMask_;
  std::vector<std::uint64_t> bits_;  // planes z = -1 .. nz of rowCount_ rows of words_ words
  PlaneEdges bottom_, top_;          // planes z and z + 1 of the current slab
  std::vector<std::uint32_t> zEdge_;  // z-edges of the slab, rows j and j + 1 at j & 1
  TriangleMesh mesh_;
};

}  // namespace

TriangleMesh scanRows(const Dims& dims, AdjacencyPair pair, const RowSource& rows) {
  if (dims.empty()) return {};
  return Scanner(dims, pair, rows).run();
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
