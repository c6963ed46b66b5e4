// Value statistics of a volume: range, a 256-bin histogram, Otsu's threshold (the default
// iso-value), the labels of an integer image with few distinct values, and exact quantiles.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <cstdint>
#include <utility>
#include <vector>

#include "LabelValue.h"
#include "VolumeView.h"

namespace surftrack::cli {

struct VolumeStats {
  double min = 0, max = 0, mean = 0;
  std::size_t voxels = 0;
  std::size_t nonFinite = 0;            ///< NaN / inf voxels (float types), ignored elsewhere
  std::vector<std::size_t> histogram;   ///< 256 bins over [min, max]
  double binWidth = 1;
  /// Otsu's threshold as an iso-value s (1-voxels are f > s), inside [min, max).
  double otsu = 0;
  /// Integer images with at most 256 distinct values: each value (exact, 64-bit ids included)
  /// and its voxel count.
  std::vector<std::pair<LabelValue, std::size_t>> labels;
  bool integral = false;
  /// (q, quantile) pairs, when addQuantiles computed them.
  std::vector<std::pair<double, double>> quantiles;
};

VolumeStats computeStats(const VolumeView& volume);

/// Sets stats.quantiles to the q-quantile of the finite values of `volume` for each q in
/// [0, 1], exactly as numpy.quantile's default ("linear") method defines it: with the n values
/// sorted, a[h] at h = (n - 1) q, interpolated linearly between a[floor h] and a[floor h + 1].
/// The ranks are found by a radix selection over the values' bits, 16 bits a pass (one pass
/// for 8- and 16-bit voxels, two for 32-bit, four for 64-bit), in constant memory.
/// \pre `stats` is computeStats(volume).
void addQuantiles(const VolumeView& volume, VolumeStats& stats, const std::vector<double>& qs);

/// The smallest and largest finite values (one pass), or nothing if no value is finite.
std::optional<std::array<double, 2>> valueRange(const VolumeView& volume);

/// The number of voxels with f > s, and with f = label.
std::size_t countAbove(const VolumeView& volume, double s);
std::size_t countEqual(const VolumeView& volume, const LabelValue& label);

}  // namespace surftrack::cli
