// A VoxelSource with a selection, seen as the binary image the engine's templates read
// (internal to core/): BinaryBrickCache takes whole bricks through rows(), the scanner whole
// rows through row(), seed walks single voxels through operator().
#pragma once

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
    return source_->binaryRow(selection_, Voxel{x, y, z}, 1) & 1u;
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
  const Dims& dims() const { return dims_; }

  void rows(int x0, int y0, int z0, int width, int ny, int nz, std::uint16_t* out) const {
    source_->binaryBlock(selection_, Voxel{x0, y0, z0}, width, ny, nz, out);
  }
  std::uint64_t row(int x0, int y, int z, int count) const {
    return source_->binaryRow(selection_, Voxel{x0, y, z}, count);
  }

 private:
  const VoxelSource* source_;
  Selection selection_;
  Dims dims_;
};

}  // namespace surftrack
