// The scanning method ("method 1" of Figure 9, paper §5.1): the kappa-lambda-iso-surface of a
// whole binary image, built like marching cubes by visiting every digital 3-cube that meets the
// domain and emitting the triangles of its configuration table entry. Vertex v of the result is
// a boundary surfel, and every boundary surfel of the image is exactly one vertex.
//
// How it works (see ScanIsoSurface.cpp):
//  - The image is read once, one row of voxels at a time, into bit sets (64 voxels a word; one
//    bit per voxel of the domain padded by one voxel, 1/8 of a uint8 image). The surfels are
//    counted (popcounts) so that the mesh is allocated up front. The cubes of a row whose 8
//    corners are all equal (configurations 0x00 and 0xFF, the vast majority) are skipped by a
//    few word operations per 64 cubes.
//  - Vertices are shared between cubes without a global hash map (as in flying edges and
//    OpenVDB's VolumeToMesh): before the cubes of a slab z..z+1 are visited, every cut grid edge
//    of the slab gets its vertex index in small per-plane arrays indexed by edge position.
//  - scanBoundaryCounts runs the same slabs but, instead of writing triangles, joins the
//    surfels of each cube's patches in a union-find (Boost's disjoint sets): every boundary's
//    surfel count and first surfel, for `--largest`, with no mesh built.
//  - A dense ThresholdImage (any gray type, in particular the binaryView of a BinaryVolume) is
//    binarised straight from its buffer, 16 uint8 voxels per SSE2 instruction; any other binary
//    image (LabelImage, ImplicitImage, ...) is read through its operator().
//
// The image must be constant outside its domain (as every image of Image.h is): the cubes
// scanned are those with min corner in [-1, n - 1] on each axis, so that every boundary is
// closed, also where an object touches the domain border (docs/theory.md, 'Images, voxels and the
// domain').
#pragma once

#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "AdjacencyPair.h"
#include "Image.h"
#include "Surfel.h"
#include "TriangleMesh.h"

namespace surftrack {

/// One kappa-lambda-boundary of a scanned image, as a component of the scanned mesh.
struct BoundaryCount {
  std::size_t surfels = 0;       ///< its number of surfels
  std::uint64_t firstVertex = 0;  ///< its first vertex in the scanned mesh (scanRows' numbering)
  Surfel seed;                    ///< the surfel of that vertex
};

namespace scan {

/// In a row bit set, voxel x (for x in [-1, nx]) is bit x + kRowOffset: the voxels of the
/// domain start on a word boundary and x = -1 is the top bit of word 0.
inline constexpr int kRowOffset = 64;

/// Words of one row bit set for a domain nx voxels wide (one spare zero word at the end).
constexpr int rowWords(int nx) { return (nx + kRowOffset) / 64 + 2; }

/// Where the scanner gets its voxels from, one row of x at a time.
class RowSource {
 public:
  virtual ~RowSource() = default;
  /// Sets bit x + kRowOffset of `row` (rowWords(nx) words, zero on entry) to the value of voxel
  /// (x, y, z), for every x in [-1, nx]; y and z may lie one voxel outside the domain.
  virtual void fillRow(int y, int z, std::uint64_t* row) const = 0;
};

/// The scanning engine: the kappa-lambda-iso-surface of the binary image that `rows`
/// describes on the domain `dims` (cubes with min corner in [-1, n - 1] on each axis), on
/// `threads` threads (0: all cores). The mesh is the same for any number of threads.
TriangleMesh scanRows(const Dims& dims, AdjacencyPair pair, const RowSource& rows, int threads = 0);

/// Every kappa-lambda-boundary of the binary image that `rows` describes, without a triangle:
/// its surfel count and its first surfel, in the order of meshComponents on the mesh scanRows
/// would give (that of their first vertex). Same for any number of threads.
std::vector<BoundaryCount> countRows(const Dims& dims, AdjacencyPair pair, const RowSource& rows, int threads = 0);

/// Rows of any binary image, one operator() call per voxel.
template <class BinaryImage>
class GenericRows final : public RowSource {
 public:
  explicit GenericRows(const BinaryImage& image) : image_(image), nx_(image.dims().nx) {}
  void fillRow(int y, int z, std::uint64_t* row) const override {
    for (int x = -1; x <= nx_; ++x)
      if (image_(x, y, z)) row[(x + kRowOffset) >> 6] |= std::uint64_t(1) << ((x + kRowOffset) & 63);
  }

 private:
  const BinaryImage& image_;
  int nx_;
};

/// A binary image that reads up to 64 voxels of a row in one call: row(x0, y, z, count) gives
/// voxels (x0 + i, y, z) as bits i (ThresholdImage, LabelImage, the front door's sources).
template <class Image>
concept RowReadable = requires(const Image& image) {
  { image.row(0, 0, 0, 64) } -> std::convertible_to<std::uint64_t>;
};

/// Rows of a RowReadable image, binarised 64 voxels at a time by its row().
template <RowReadable Image>
class WordRows final : public RowSource {
 public:
  explicit WordRows(const Image& image)
      : image_(image), dims_(image.dims()), outside_(image(-1, -1, -1)) {}

  void fillRow(int y, int z, std::uint64_t* row) const override {
    const int nx = dims_.nx;
    if (outside_) {
      setBit(row, -1);
      setBit(row, nx);
    }
    if (!dims_.contains(0, y, z)) {  // a row of the one-voxel frame around the domain
      if (outside_)
        for (int x = 0; x < nx; ++x) setBit(row, x);
      return;
    }
    std::uint64_t* out = row + kRowOffset / 64;
    int x = 0;
    for (; x + 64 <= nx; x += 64) *out++ |= image_.row(x, y, z, 64);
    if (x < nx) *out |= image_.row(x, y, z, nx - x);  // this word may hold the bit of x = nx
  }

 private:
  static void setBit(std::uint64_t* row, int x) {
    row[(x + kRowOffset) >> 6] |= std::uint64_t(1) << ((x + kRowOffset) & 63);
  }

  const Image& image_;
  Dims dims_;
  bool outside_;
};

}  // namespace scan

/// The kappa-lambda-iso-surface of a binary image through its generic operator() (any image).
template <class BinaryImage>
TriangleMesh scanIsoSurfaceGeneric(const BinaryImage& image, AdjacencyPair pair, int threads = 0) {
  return scan::scanRows(image.dims(), pair, scan::GenericRows<BinaryImage>(image), threads);
}

/// The kappa-lambda-iso-surface of a whole binary image (paper §5.1): the triangles of the
/// configuration table of `pair` in every digital 3-cube meeting the domain, oriented from the
/// 1-voxels to the 0-voxels, one vertex per boundary surfel. Reads whole rows of a RowReadable
/// image (ThresholdImage, and so binaryView; LabelImage), voxel by voxel otherwise; both give
/// the same mesh, on `threads` threads (0: all cores; `image` is then read from several threads
/// at once), the same mesh for any number.
template <class BinaryImage>
TriangleMesh scanIsoSurface(const BinaryImage& image, AdjacencyPair pair, int threads = 0) {
  if constexpr (scan::RowReadable<BinaryImage>)
    return scan::scanRows(image.dims(), pair, scan::WordRows<BinaryImage>(image), threads);
  else
    return scanIsoSurfaceGeneric(image, pair, threads);
}

/// Every kappa-lambda-boundary of a whole binary image with its surfel count and one surfel
/// of it, without building the iso-surface: what meshComponents tells of scanIsoSurface's
/// mesh (the same boundaries, in the same order, each with its first vertex), from a scan that
/// joins the surfels of each cube's patches in a union-find instead of writing triangles. On
/// `threads` threads (0: all cores), the same result for any number.
template <class BinaryImage>
std::vector<BoundaryCount> scanBoundaryCounts(const BinaryImage& image, AdjacencyPair pair, int threads = 0) {
  if constexpr (scan::RowReadable<BinaryImage>)
    return scan::countRows(image.dims(), pair, scan::WordRows<BinaryImage>(image), threads);
  else
    return scan::countRows(image.dims(), pair, scan::GenericRows<BinaryImage>(image), threads);
}

/// Connected components of a mesh's triangles through shared vertices: returns the component
/// of every vertex (a triangle's component is that of its vertices), numbered 0, 1, ... in the
/// order of their smallest vertex; `count` receives the number of components. On a scanned
/// mesh the components are exactly the kappa-lambda-boundaries (Proposition 39).
std::vector<std::uint32_t> meshComponents(const TriangleMesh& mesh, std::size_t& count);

/// The component of `mesh` that contains the vertex of `seed`, vertices renumbered in their
/// original order ("method 1b": what a marching-cubes user must do to get one boundary).
/// Throws std::invalid_argument if seed is not a vertex of the mesh.
TriangleMesh extractComponent(const TriangleMesh& mesh, const Surfel& seed);

/// Every component of `mesh` as a mesh of its own, in the order of meshComponents.
std::vector<TriangleMesh> splitComponents(const TriangleMesh& mesh);

/// The kappa-lambda-iso-surface of each kappa-lambda-boundary of the image.
template <class BinaryImage>
std::vector<TriangleMesh> scanComponents(const BinaryImage& image, AdjacencyPair pair) {
  return splitComponents(scanIsoSurface(image, pair));
}

}  // namespace surftrack
