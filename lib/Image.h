// Images (paper §2.1.1, §3.1): a dense scalar volume with its physical geometry, and the
// binary images the engine works on — a threshold (f > s), a label selection (f = L), or an
// implicit predicate with no storage at all. Every binary image answers `(x, y, z)` for any
// voxel of Z^3: voxels outside the domain take the value `outside` (0 unless asked otherwise).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "Geometry.h"
#include "HugePages.h"
#include "Voxel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace surftrack {

/// A dense volume of scalars (uint8, int16, uint16, int32, float, double, ...), x fastest.
template <class T>
class DenseImage {
 public:
  using value_type = T;

  DenseImage() = default;
  explicit DenseImage(Dims dims, T fill = T{}, ImageGeometry geometry = {})
      : dims_(dims), geometry_(geometry) {
    if (dims.empty()) throw std::invalid_argument("image dimensions must be positive");
    reserveHugePages(data_, dims.count());
    data_.assign(dims.count(), fill);
  }

  const Dims& dims() const { return dims_; }
  const ImageGeometry& geometry() const { return geometry_; }
  ImageGeometry& geometry() { return geometry_; }

  std::size_t index(int x, int y, int z) const {
    return (std::size_t(z) * std::size_t(dims_.ny) + std::size_t(y)) * std::size_t(dims_.nx) +
           std::size_t(x);
  }
  T& at(int x, int y, int z) { return data_[index(x, y, z)]; }
  const T& at(int x, int y, int z) const { return data_[index(x, y, z)]; }
  T& at(Voxel v) { return at(v.x, v.y, v.z); }
  const T& at(Voxel v) const { return at(v.x, v.y, v.z); }

  std::vector<T>& data() { return data_; }
  const std::vector<T>& data() const { return data_; }

 private:
  Dims dims_;
  ImageGeometry geometry_;
  std::vector<T> data_;
};

/// A read-only, non-owning view of a scalar volume held by someone else (a DenseImage, a numpy
/// array, an ITK buffer, a memory-mapped file): voxel (x, y, z) is data[x sx + y sy + z sz],
/// strides in elements. Nothing is copied; the owner keeps the memory alive.
template <class T>
struct VolumeRef {
  using value_type = T;

  const T* data = nullptr;
  Dims dims;
  std::ptrdiff_t sx = 1, sy = 0, sz = 0;

  VolumeRef() = default;
  VolumeRef(const T* data, Dims dims, std::ptrdiff_t sx, std::ptrdiff_t sy, std::ptrdiff_t sz)
      : data(data), dims(dims), sx(sx), sy(sy), sz(sz) {}
  /// The view of a whole DenseImage (x fastest).
  VolumeRef(const DenseImage<T>& image)  // NOLINT: a DenseImage is a view of itself
      : VolumeRef(image.data().data(), image.dims(), 1, image.dims().nx,
                  std::ptrdiff_t(image.dims().nx) * image.dims().ny) {}

  std::ptrdiff_t offset(int x, int y, int z) const { return x * sx + y * sy + z * sz; }
  const T& at(int x, int y, int z) const { return data[offset(x, y, z)]; }
  const T& at(Voxel v) const { return at(v.x, v.y, v.z); }
  /// Rows of x are contiguous and y, z go forwards: whole rows can be read with vector loads.
  bool rowsContiguous() const { return sx == 1 && sy >= 0 && sz >= 0; }
  /// With rowsContiguous(): the elements from data on that belong to the view.
  std::size_t extent() const {
    return std::size_t(offset(dims.nx - 1, dims.ny - 1, dims.nz - 1)) + 1;
  }
};

namespace detail {

inline std::uint64_t lowBits(int n) { return n >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1; }

/// The row(x0, y, z, count) of a binary image on the domain `d` (ThresholdImage, LabelImage):
/// bits i of the count <= 64 voxels (x0 + i, y, z), `outside` for those outside the domain and
/// inDomain(lo, hi) (the bits i in [lo, hi), in place) for the others, lo < hi.
template <class InDomain>
std::uint64_t rowBits(const Dims& d, int x0, int y, int z, int count, bool outside, InDomain&& inDomain) {
  const std::uint64_t all = lowBits(count);
  if (y < 0 || z < 0 || y >= d.ny || z >= d.nz || x0 >= d.nx || x0 + count <= 0) return outside ? all : 0;
  const int lo = x0 < 0 ? -x0 : 0, hi = x0 + count > d.nx ? d.nx - x0 : count;
  const std::uint64_t bits = outside ? all & ~(lowBits(hi - lo) << lo) : 0;
  return bits | inDomain(lo, hi);
}

}  // namespace detail

/// Binary image of a gray image J at iso-value s (§3.1): f(v) > s is a 1-voxel.
template <class T>
class ThresholdImage {
 public:
  ThresholdImage(VolumeRef<T> image, double isoValue, bool outside = false)
      : image_(image), iso_(isoValue), outside_(outside) {
    if (std::isnan(isoValue)) throw std::invalid_argument("iso-value is NaN");
    if constexpr (std::is_integral_v<T> && sizeof(T) <= 4) {
      // For an integer f, f > s <=> f > floor(s); s below (above) the range: all 1 (all 0).
      const double t = std::floor(iso_);
      if (t < double(std::numeric_limits<T>::lowest())) mode_ = Mode::AllOnes;
      else if (t >= double(std::numeric_limits<T>::max())) mode_ = Mode::AllZeros;
      else threshold_ = T(t);
    }
  }
  bool operator()(int x, int y, int z) const {
    if (!image_.dims.contains(x, y, z)) return outside_;
    return double(image_.at(x, y, z)) > iso_;
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
  const Dims& dims() const { return image_.dims; }
  const VolumeRef<T>& gray() const { return image_; }
  double isoValue() const { return iso_; }

  /// row(x0, y0 + j, z0 + k, width) into out[k * ny + j] for a block of nz x ny rows, width <= 16:
  /// the tracker's bricks. Inside the image, uint8 rows take one vector compare each and no
  /// bounds checks; elsewhere, row by row.
  void rows(int x0, int y0, int z0, int width, int ny, int nz, std::uint16_t* out) const {
#if defined(__SSE2__)
    if constexpr (std::is_same_v<T, std::uint8_t>) {
      const Dims& d = image_.dims;
      // Loads of 16 may run into the next row (masked off), never past the data.
      if (mode_ == Mode::Compare && image_.rowsContiguous() && x0 >= 0 && y0 >= 0 && z0 >= 0 &&
          x0 + width <= d.nx && y0 + ny <= d.ny && z0 + nz <= d.nz &&
          std::size_t(image_.offset(x0, y0 + ny - 1, z0 + nz - 1)) + 16 <= image_.extent()) {
        const unsigned keep = (1u << width) - 1;
        const T* slice = &image_.at(x0, y0, z0);
        for (int k = 0; k < nz; ++k, slice += image_.sz) {
          const T* row = slice;
          for (int j = 0; j < ny; ++j, row += image_.sy) *out++ = std::uint16_t(compare16(row) & keep);
        }
        return;
      }
    }
#endif
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) *out++ = std::uint16_t(row(x0, y0 + j, z0 + k, width));
  }

  /// Values of the `count` <= 64 voxels (x0 + i, y, z) as bits i: the fast path of the
  /// scanner and of the tracker's brick cache, which binarise whole rows.
  std::uint64_t row(int x0, int y, int z, int count) const {
    return detail::rowBits(image_.dims, x0, y, z, count, outside_, [&](int lo, int hi) {
      if (image_.sx != 1) [[unlikely]] {
        std::uint64_t strided = 0;
        for (int i = lo; i < hi; ++i) strided |= std::uint64_t(double(image_.at(x0 + i, y, z)) > iso_) << i;
        return strided;
      }
      return compare(&image_.at(x0 + lo, y, z), hi - lo) << lo;
    });
  }

 private:
  enum class Mode { Compare, AllOnes, AllZeros };

  static std::uint64_t lowBits(int n) { return detail::lowBits(n); }

#if defined(__SSE2__)
  /// Bit i is values[i] > s for the 16 uint8 values from `values` (mode Compare): unsigned
  /// bytes compared as signed after flipping their top bit.
  unsigned compare16(const std::uint8_t* values) const {
    const __m128i flip = _mm_set1_epi8(char(0x80));
    const __m128i t = _mm_set1_epi8(char(threshold_ ^ 0x80));
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(values));
    return unsigned(_mm_movemask_epi8(_mm_cmpgt_epi8(_mm_xor_si128(v, flip), t)));
  }
#endif

  /// Bit i is values[i] > s, for i < n <= 64 — exactly operator()'s test.
  std::uint64_t compare(const T* values, int n) const {
    if (mode_ == Mode::AllOnes) return lowBits(n);
    if (mode_ == Mode::AllZeros) return 0;
    std::uint64_t bits = 0;
    int i = 0;
    if constexpr (std::is_same_v<T, std::uint8_t>) {
#if defined(__SSE2__)
      for (; i + 16 <= n; i += 16) bits |= std::uint64_t(compare16(values + i)) << i;
#endif
    }
    if constexpr (std::is_integral_v<T> && sizeof(T) <= 4)
      for (; i < n; ++i) bits |= std::uint64_t(values[i] > threshold_) << i;
    else
      for (; i < n; ++i) bits |= std::uint64_t(double(values[i]) > iso_) << i;
    return bits;
  }

  VolumeRef<T> image_;
  double iso_;
  bool outside_;
  Mode mode_ = Mode::Compare;
  T threshold_{};
};

/// Binary image of a label image: f(v) = L is a 1-voxel.
template <class T>
class LabelImage {
 public:
  LabelImage(VolumeRef<T> image, T label, bool outside = false)
      : image_(image), label_(label), outside_(outside) {}
  bool operator()(int x, int y, int z) const {
    if (!image_.dims.contains(x, y, z)) return outside_;
    return image_.at(x, y, z) == label_;
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
  const Dims& dims() const { return image_.dims; }

  /// Values of the `count` <= 64 voxels (x0 + i, y, z) as bits i (ThresholdImage::row's
  /// contract): the scanner and the front door read label images a row at a time.
  std::uint64_t row(int x0, int y, int z, int count) const {
    return detail::rowBits(image_.dims, x0, y, z, count, outside_, [&](int lo, int hi) {
      std::uint64_t bits = 0;
      const T* p = &image_.at(x0 + lo, y, z);
      const std::ptrdiff_t sx = image_.sx;
      for (int i = lo; i < hi; ++i, p += sx) bits |= std::uint64_t(*p == label_) << i;
      return bits;
    });
  }

 private:
  VolumeRef<T> image_;
  T label_;
  bool outside_;
};

/// A binary image given by a predicate `bool(int x, int y, int z)` on a domain, with no storage:
/// it can describe volumes far too large to hold or scan (a 4096^3 ball, say).
template <class Predicate>
class ImplicitImage {
 public:
  ImplicitImage(Dims dims, Predicate predicate, bool outside = false)
      : dims_(dims), predicate_(std::move(predicate)), outside_(outside) {
    if (dims.empty()) throw std::invalid_argument("image dimensions must be positive");
  }
  bool operator()(int x, int y, int z) const {
    if (!dims_.contains(x, y, z)) return outside_;
    return predicate_(x, y, z);
  }
  bool operator()(Voxel v) const { return (*this)(v.x, v.y, v.z); }
  const Dims& dims() const { return dims_; }

 private:
  Dims dims_;
  Predicate predicate_;
  bool outside_;
};

/// A stored binary volume (one byte per voxel); handy for tests and small images.
using BinaryVolume = DenseImage<std::uint8_t>;

/// The binary image of a 0/1 volume (1 is a 1-voxel).
inline ThresholdImage<std::uint8_t> binaryView(const BinaryVolume& volume, bool outside = false) {
  return ThresholdImage<std::uint8_t>(volume, 0.5, outside);
}

}  // namespace surftrack
