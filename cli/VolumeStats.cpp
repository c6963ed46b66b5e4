#include "VolumeStats.h"

#include <algorithm>
#include <bit>
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

namespace {

/// The voxel types' values as unsigned integers of the same width in the same order
/// (radix selection): signed integers with the sign bit flipped, floats with the sign bit
/// flipped when positive and every bit flipped when negative.
template <class T>
using KeyOf = std::conditional_t<sizeof(T) == 1, std::uint8_t,
              std::conditional_t<sizeof(T) == 2, std::uint16_t,
              std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;

template <class T>
KeyOf<T> orderKey(T v) {
  using K = KeyOf<T>;
  constexpr K sign = K(K(1) << (8 * sizeof(T) - 1));
  const K bits = std::bit_cast<K>(v);
  if constexpr (std::is_floating_point_v<T>) return (bits & sign) ? K(~bits) : K(bits | sign);
  else if constexpr (std::is_signed_v<T>) return K(bits ^ sign);
  else return bits;
}

template <class T>
T fromOrderKey(KeyOf<T> key) {
  using K = KeyOf<T>;
  constexpr K sign = K(K(1) << (8 * sizeof(T) - 1));
  if constexpr (std::is_floating_point_v<T>) return std::bit_cast<T>((key & sign) ? K(key & ~sign) : K(~key));
  else if constexpr (std::is_signed_v<T>) return std::bit_cast<T>(K(key ^ sign));
  else return T(key);
}

/// The values of the given ranks (0-based, among the finite values in ascending order): a most
/// significant digit first radix selection on orderKey, 16 bits a pass. Each rank keeps the
/// digits fixed so far (its prefix) and its rank among the values of that prefix; ranks with
/// the same prefix share a pass's histogram.
template <class T>
std::vector<double> valuesAtRanks(const VolumeView& view, const std::vector<std::uint64_t>& ranks) {
  using K = KeyOf<T>;
  constexpr int kBits = 8 * sizeof(T);
  constexpr int kDigit = kBits < 16 ? kBits : 16;
  struct Search {
    std::uint64_t prefix = 0, rank = 0;
  };
  std::vector<Search> searches;
  for (std::uint64_t r : ranks) searches.push_back({0, r});
  for (int shift = kBits - kDigit; shift >= 0; shift -= kDigit) {
    std::vector<std::uint64_t> prefixes;  // the distinct prefixes, one histogram each
    for (const Search& s : searches)
      if (std::find(prefixes.begin(), prefixes.end(), s.prefix) == prefixes.end()) prefixes.push_back(s.prefix);
    std::vector<std::vector<std::uint64_t>> histograms(prefixes.size(), std::vector<std::uint64_t>(1u << kDigit, 0));
    const bool first = shift + kDigit == kBits;  // no digit fixed yet: every value has prefix 0
    forEachValue<T>(view, [&](T v) {
      if constexpr (std::is_floating_point_v<T>)
        if (!std::isfinite(v)) return;
      const std::uint64_t key = orderKey(v);
      const std::uint64_t prefix = first ? 0 : key >> (shift + kDigit);
      const std::size_t digit = std::size_t((key >> shift) & ((std::uint64_t(1) << kDigit) - 1));
      for (std::size_t p = 0; p < prefixes.size(); ++p)
        if (prefixes[p] == prefix) ++histograms[p][digit];
    });
    for (Search& s : searches) {
      const auto& h = histograms[std::size_t(std::find(prefixes.begin(), prefixes.end(), s.prefix) - prefixes.begin())];
      std::size_t digit = 0;
      while (digit + 1 < h.size() && s.rank >= h[digit]) s.rank -= h[digit++];
      s.prefix = (s.prefix << kDigit) | digit;
    }
  }
  std::vector<double> values;
  for (const Search& s : searches) values.push_back(double(fromOrderKey<T>(K(s.prefix))) + 0.0);  // (-0 as 0)
  return values;
}

/// numpy's linear interpolation (numpy.lib.function_base._lerp): from b backwards for t >= 0.5,
/// so that t = 1 gives b exactly.
double lerp(double a, double b, double t) {
  const double diff = b - a;
  return t >= 0.5 ? b - diff * (1 - t) : a + diff * t;
}

}  // namespace

void addQuantiles(const VolumeView& volume, VolumeStats& stats, const std::vector<double>& qs) {
  stats.quantiles.clear();
  if (stats.voxels == 0) return;
  const std::uint64_t last = stats.voxels - 1;
  std::vector<std::uint64_t> ranks;
  for (double q : qs) {
    const double h = double(last) * q;  // numpy: (n - 1) * q
    const std::uint64_t below = std::min(last, std::uint64_t(std::floor(h)));
    ranks.push_back(below);
    ranks.push_back(std::min(last, below + 1));
  }
  const std::vector<double> values = visitScalarType(
      volume.type, [&](auto type) { return valuesAtRanks<decltype(type)>(volume, ranks); });
  for (std::size_t i = 0; i < qs.size(); ++i) {
    const double h = double(last) * qs[i];
    stats.quantiles.emplace_back(qs[i], lerp(values[2 * i], values[2 * i + 1], h - std::floor(h)));
  }
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
