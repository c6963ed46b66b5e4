// A VoxelSource with a selection, seen as the binary image the engine's templates read
// (internal to core/): BinaryBrickCache takes whole bricks through rows(), the scanner whole
// rows through row(), seed walks single voxels through operator(). It counts the voxels the
// seeded paths ask for (Surface::voxelsRead); the scanner's rows, read from several threads,
// are not counted one by one (a scan reads every voxel: extract counts the domain).
#pragma once

#include <atomic>
#include <cstdint>

#include "Geometry.h"
#include "VoxelSource.h"

namespace surftrack {

class SourceImage {
 public:
  SourceImage(const VoxelSource& source, const Selection& selection)
      : source_(&source), selection_(selection), dims_(source.dims()) {}

  bool operator()(int x, int y, int z) const {
    if (!dims_.contains(x, y, z)) return false;
    count(1);
    return source_->binaryRow(selection_, Voxel{x, y, z}, 1) & 1u;
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
  const Dims& dims() const { return dims_; }

  void rows(int x0, int y0, int z0, int width, int ny, int nz, std::uint16_t* out) const {
    count(std::uint64_t(width) * std::uint64_t(ny) * std::uint64_t(nz));
    source_->binaryBlock(selection_, Voxel{x0, y0, z0}, width, ny, nz, out);
  }
  std::uint64_t row(int x0, int y, int z, int count) const {
    return source_->binaryRow(selection_, Voxel{x0, y, z}, count);
  }
  /// Voxels asked of the source so far through operator() and rows().
  std::uint64_t voxelsRead() const { return read_.load(std::memory_order_relaxed); }

 private:
  void count(std::uint64_t n) const { read_.fetch_add(n, std::memory_order_relaxed); }

  const VoxelSource* source_;
  mutable std::atomic<std::uint64_t> read_{0};
  Selection selection_;
  Dims dims_;
};

}  // namespace surftrack
