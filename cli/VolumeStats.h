// Value statistics of a volume: range, a 256-bin histogram, Otsu's threshold (the default
// iso-value), the labels of an integer image with few distinct values.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <cstdint>
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

  /// The value below which a fraction q of the voxels lie (from the histogram).
  double quantile(double q) const;
};

VolumeStats computeStats(const VolumeView& volume);

/// The smallest and largest finite values (one pass), or nothing if no value is finite.
std::optional<std::array<double, 2>> valueRange(const VolumeView& volume);

/// The number of voxels with f > s, and with f = label.
std::size_t countAbove(const VolumeView& volume, double s);
std::size_t countEqual(const VolumeView& volume, const LabelValue& label);

}  // namespace surftrack::cli
