#include "VolumeStats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace surftrack::cli {

namespace {

constexpr int kBins = 256;

/// Calls f(v) for every voxel value of `view` (of type T), rows of x in memory order.
template <class T, class F>
void forEachValue(const VolumeView& view, F&& f) {
  const T* base = static_cast<const T*>(view.data);
  const Dims d = view.dims;
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y) {
      const T* row = base + z * view.strides[2] + y * view.strides[1];
      const std::ptrdiff_t sx = view.strides[0];
      if (sx == 1) {  // (contiguous rows: a loop the compiler can vectorise)
        for (int x = 0; x < d.nx; ++x) f(row[x]);
      } else {
        for (int x = 0; x < d.nx; ++x) f(row[x * sx]);
      }
    }
}

template <class T>
VolumeStats statsOf(const VolumeView& view) {
  VolumeStats s;
  s.integral = std::is_integral_v<T>;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0;
  // The integer extremes in T: 64-bit ids differ where their doubles do not (2^53 + 1).
  T least = std::numeric_limits<T>::max(), most = std::numeric_limits<T>::lowest();
  forEachValue<T>(view, [&](T v) {
    const double d = double(v);
    if (!std::isfinite(d)) {
      ++s.nonFinite;
      return;
    }
    lo = std::min(lo, d);
    hi = std::max(hi, d);
    least = std::min(least, v);
    most = std::max(most, v);
    sum += d;
  });
  s.voxels = view.dims.count() - s.nonFinite;
  if (s.voxels == 0) {
    s.histogram.assign(kBins, 0);
    return s;
  }
  s.min = lo;
  s.max = hi;
  s.mean = sum / double(s.voxels);
  // Integer data with a range of at most 256 values: one bin per value.
  if (s.integral && hi - lo < kBins) s.binWidth = 1;
  else s.binWidth = hi > lo ? (hi - lo) / kBins : 1;
  s.histogram.assign(kBins, 0);
  // Integer data over a range of at most 2^20 values: count every value (a direct array, not a
  // map: this runs over every voxel), then list them as labels when there are at most 256.
  // The span and the offsets in uint64 arithmetic: exact for every integer type (modular for
  // the signed ones, whose differences are then still right).
  const std::uint64_t span = s.integral ? std::uint64_t(most) - std::uint64_t(least) : 0;
  const bool countValues = s.integral && span < (std::uint64_t(1) << 20);
  std::vector<std::size_t> valueCount(countValues ? std::size_t(span) + 1 : 0, 0);
  forEachValue<T>(view, [&](T v) {
    const double d = double(v);
    if (!std::isfinite(d)) return;
    if (countValues) {
      if constexpr (std::is_integral_v<T>) ++valueCount[std::size_t(std::uint64_t(v) - std::uint64_t(least))];
    } else {
      const int b = int((d - lo) / s.binWidth);
      s.histogram[std::clamp(b, 0, kBins - 1)]++;
    }
  });
  if (countValues) {
    std::size_t distinct = 0;
    for (std::size_t i = 0; i < valueCount.size(); ++i) {
      if (!valueCount[i]) continue;
      ++distinct;
      const int b = int(double(i) / s.binWidth);
      s.histogram[std::clamp(b, 0, kBins - 1)] += valueCount[i];
    }
    if (distinct <= 256)
      for (std::size_t i = 0; i < valueCount.size(); ++i)
        if (valueCount[i]) {
          if constexpr (std::is_integral_v<T>) s.labels.emplace_back(T(std::uint64_t(least) + i), valueCount[i]);
        }
  }

  // Otsu: the split between bins k and k + 1 maximising the between-class variance.
  double total = 0, totalSum = 0;
  for (int b = 0; b < kBins; ++b) {
    total += double(s.histogram[b]);
    totalSum += double(s.histogram[b]) * b;
  }
  // Equal maxima (empty bins between two classes: a 0/255 image) give a range of splits; take
  // its middle, so that the threshold sits halfway between the classes.
  std::vector<double> between(kBins - 1, -1);
  double w0 = 0, sum0 = 0, best = -1;
  for (int k = 0; k < kBins - 1; ++k) {
    w0 += double(s.histogram[k]);
    sum0 += double(s.histogram[k]) * k;
    const double w1 = total - w0;
    if (w0 == 0 || w1 == 0) continue;
    const double m0 = sum0 / w0, m1 = (totalSum - sum0) / w1;
    between[k] = w0 * w1 * (m0 - m1) * (m0 - m1);
    best = std::max(best, between[k]);
  }
  int first = -1, last = 0;
  for (int k = 0; k < kBins - 1; ++k)
    if (between[k] >= 0 && between[k] >= best * (1 - 1e-12)) {
      if (first < 0) first = k;
      last = k;
    }
  const int bestK = first < 0 ? 0 : (first + last) / 2;
  // Class 0 is bins [0, bestK]; the iso-value is the top of bin bestK. With one bin per
  // integer value, class 0 is the values <= lo + bestK, and s = lo + bestK + 0.5 sits halfway.
  if (s.integral && s.binWidth == 1) s.otsu = lo + bestK + 0.5;
  else s.otsu = lo + (bestK + 1) * s.binWidth;
  if (hi > lo) s.otsu = std::clamp(s.otsu, lo, std::nextafter(hi, lo));
  else s.otsu = lo;
  return s;
}

}  // namespace

double VolumeStats::quantile(double q) const {
  const double target = q * double(voxels);
  double seen = 0;
  for (int b = 0; b < int(histogram.size()); ++b) {
    seen += double(histogram[b]);
    if (seen >= target) return std::min(max, min + (b + 1) * binWidth);
  }
  return max;
}

std::optional<std::array<double, 2>> valueRange(const VolumeView& volume) {
  return visitScalarType(volume.type, [&](auto type) -> std::optional<std::array<double, 2>> {
    using T = decltype(type);
    if constexpr (std::is_integral_v<T>) {  // in T: every value is finite
      T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
      forEachValue<T>(volume, [&](T v) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      });
      return std::array<double, 2>{double(lo), double(hi)};
    } else {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      forEachValue<T>(volume, [&](T v) {
        const double d = double(v);
        if (std::isfinite(d)) {  // (NaN fails both comparisons below as well)
          lo = std::min(lo, d);
          hi = std::max(hi, d);
        }
      });
      if (lo > hi) return std::nullopt;
      return std::array<double, 2>{lo, hi};
    }
  });
}

VolumeStats computeStats(const VolumeView& volume) {
  return visitScalarType(volume.type, [&](auto type) { return statsOf<decltype(type)>(volume); });
}

std::size_t countAbove(const VolumeView& volume, double s) {
  return visitScalarType(volume.type, [&](auto type) {
    std::size_t n = 0;
    forEachValue<decltype(type)>(volume, [&](auto v) { n += double(v) > s; });
    return n;
  });
}

std::size_t countEqual(const VolumeView& volume, const LabelValue& label) {
  return visitScalarType(volume.type, [&](auto type) {
    using T = decltype(type);
    std::size_t n = 0;
    if (!label.fits<T>()) return n;
    const T L = label.as<T>();
    forEachValue<T>(volume, [&](T v) { n += v == L; });
    return n;
  });
}

}  // namespace surftrack::cli
