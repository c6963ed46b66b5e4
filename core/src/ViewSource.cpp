// VoxelSource over a view of memory (VolumeView) and over a function: the two sources the
// front door ships. The per-type work is templated on the voxel type and instantiated here
// once for the ten scalar types, so that users and the CLI never recompile it.
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include "Errors.h"
#include "Image.h"
#include "SelectionValue.h"
#include "Surfel.h"
#include "VoxelSource.h"

namespace surftrack {
namespace {

template <class T>
class ViewSource final : public VoxelSource {
 public:
  ViewSource(VolumeRef<T> ref, const ImageGeometry& geometry) : ref_(ref), geometry_(geometry) {}

  Dims dims() const override { return ref_.dims; }
  ImageGeometry geometry() const override { return geometry_; }
  ScalarType type() const override { return scalarTypeOf<T>(); }

  void binaryBlock(const Selection& selection, Voxel origin, int width, int ny, int nz,
                   std::uint16_t* out) const override {
    if (selection.isLabel()) {
      const LabelImage<T> image(ref_, selectionValue<T>(selection));
      for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
          *out++ = std::uint16_t(image.row(origin.x, origin.y + j, origin.z + k, width));
    } else {
      ThresholdImage<T>(ref_, selection.value).rows(origin.x, origin.y, origin.z, width, ny, nz, out);
    }
  }

  std::uint64_t binaryRow(const Selection& selection, Voxel start, int count) const override {
    if (selection.isLabel())
      return LabelImage<T>(ref_, selectionValue<T>(selection)).row(start.x, start.y, start.z, count);
    return ThresholdImage<T>(ref_, selection.value).row(start.x, start.y, start.z, count);
  }

  void values(const Voxel* voxels, std::size_t n, double* out) const override {
    for (std::size_t i = 0; i < n; ++i) out[i] = double(ref_.at(voxels[i]));
  }

 private:
  VolumeRef<T> ref_;
  ImageGeometry geometry_;
};

class FunctionSource final : public VoxelSource {
 public:
  FunctionSource(Dims dims, std::function<double(int, int, int)> f, const ImageGeometry& geometry)
      : dims_(dims), f_(std::move(f)), geometry_(geometry) {}

  Dims dims() const override { return dims_; }
  ImageGeometry geometry() const override { return geometry_; }
  ScalarType type() const override { return ScalarType::Float64; }

  void binaryBlock(const Selection& selection, Voxel origin, int width, int ny, int nz,
                   std::uint16_t* out) const override {
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        *out++ = std::uint16_t(binaryRow(selection, origin + Voxel{0, j, k}, width));
  }

  std::uint64_t binaryRow(const Selection& selection, Voxel start, int count) const override {
    std::uint64_t bits = 0;
    for (int i = 0; i < count; ++i) {
      if (!dims_.contains(start.x + i, start.y, start.z)) continue;
      const double f = f_(start.x + i, start.y, start.z);
      // A label selection reached here fits a double (requireSelectable): exact comparison.
      const bool one = selection.isLabel() ? f == selection.labelValue.toDouble() : f > selection.value;
      bits |= std::uint64_t(one) << i;
    }
    return bits;
  }

  void values(const Voxel* voxels, std::size_t n, double* out) const override {
    for (std::size_t i = 0; i < n; ++i) out[i] = f_(voxels[i].x, voxels[i].y, voxels[i].z);
  }

 private:
  Dims dims_;
  std::function<double(int, int, int)> f_;
  ImageGeometry geometry_;
};

void requireDomain(Dims dims) {
  for (int a = 0; a < 3; ++a)
    if (dims[a] <= 0 || dims[a] >= Surfel::kCoordinateLimit - 2) {
      std::ostringstream msg;
      msg << "volume dimensions " << dims.nx << "x" << dims.ny << "x" << dims.nz
          << " are not supported: each must be in [1, " << Surfel::kCoordinateLimit - 3 << "]";
      throw InvalidInput(msg.str());
    }
}

}  // namespace

std::unique_ptr<VoxelSource> makeViewSource(const VolumeView& view) {
  if (!view.data) throw InvalidInput("the volume view has no data (null pointer)");
  requireDomain(view.dims);
  return visitScalarType(view.type, [&](auto v) -> std::unique_ptr<VoxelSource> {
    using T = decltype(v);
    const VolumeRef<T> ref(static_cast<const T*>(view.data), view.dims, view.strides[0],
                           view.strides[1], view.strides[2]);
    return std::make_unique<ViewSource<T>>(ref, view.geometry);
  });
}

std::unique_ptr<VoxelSource> makeFunctionSource(Dims dims, std::function<double(int, int, int)> f,
                                                const ImageGeometry& geometry) {
  if (!f) throw InvalidInput("the function source has no function");
  requireDomain(dims);
  return std::make_unique<FunctionSource>(dims, std::move(f), geometry);
}

}  // namespace surftrack
