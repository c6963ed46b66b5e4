// Boundary mappings (paper §3.1; docs/theory.md, 'Boundary mappings'): a mapping h sends each
// boundary surfel (c, d) to a point of the open segment ]c, d[. The mesh connectivity comes
// from the midpoint tables (§5.1) whatever h is; h only places the vertices ("move the boundary
// vertices according to h but on the triangles computed with the trivial boundary mapping",
// §5.1).
//
// A mapping is any callable `std::array<double, 3>(const Surfel&)` giving index-space
// coordinates; physical coordinates are applied afterwards with ImageGeometry::toPhysical.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "Image.h"
#include "Surfel.h"

namespace surftrack {

/// The point c + t (d - c) of surfel s = (c, d).
inline std::array<double, 3> pointOnSurfel(const Surfel& s, double t) {
  const Voxel c = s.inside(), d = s.outside();
  return {c.x + t * (d.x - c.x), c.y + t * (d.y - c.y), c.z + t * (d.z - c.z)};
}

/// The interpolation parameter of the iso-value mapping (below) from the gray values f(c), f(d)
/// of a surfel's voxels: (s - f(c)) / (f(d) - f(c)) clamped into [epsilon, 1 - epsilon], or
/// 0.5 where it is undefined (f(c) = f(d), a NaN). One expression for every caller, so that a
/// vertex placed from a block's fragment is bit-equal to the single pass's (docs/theory.md,
/// "Thresholds by blocks").
inline double linearParameter(double isoValue, double fc, double fd, double epsilon) {
  const double t = (isoValue - fc) / (fd - fc);
  if (!std::isfinite(t)) return 0.5;
  return std::clamp(t, epsilon, 1.0 - epsilon);
}

/// The trivial boundary mapping g(c, d) = (c + d) / 2 (§3.1).
struct MidpointMapping {
  std::array<double, 3> operator()(const Surfel& s) const { return pointOnSurfel(s, 0.5); }
};

/// The iso-value boundary mapping h_s of §3.1 on a gray image J = (E, f):
///   h_s(c, d) = c + t (d - c),  t = (s - f(c)) / (f(d) - f(c)),
/// the linear interpolation of the crossing of level s along [c, d]. t is clamped into
/// [epsilon, 1 - epsilon]: when f(d) = s (or f(c) = s) the unclamped t would put the vertex on a
/// voxel, where several surfels could meet; clamped, every vertex stays strictly inside its own
/// segment, so vertices stay pairwise distinct (distinct surfels lie on distinct grid edges).
/// When t is undefined — a voxel outside the domain, or f(c) = f(d) because the binary image is
/// not this gray image thresholded at s — the vertex falls back to the midpoint.
template <class T>
class IsoValueMapping {
 public:
  static constexpr double kDefaultEpsilon = 1e-3;

  IsoValueMapping(VolumeRef<T> gray, double isoValue, double epsilon = kDefaultEpsilon)
      : gray_(gray), iso_(isoValue), epsilon_(epsilon) {
    if (!(epsilon > 0.0 && epsilon < 0.5))
      throw std::invalid_argument("IsoValueMapping: epsilon must lie in ]0, 0.5[");
    if (std::isnan(isoValue)) throw std::invalid_argument("IsoValueMapping: iso-value is NaN");
  }
  /// The mapping matching a threshold view (same gray image, same iso-value).
  explicit IsoValueMapping(const ThresholdImage<T>& binary, double epsilon = kDefaultEpsilon)
      : IsoValueMapping(binary.gray(), binary.isoValue(), epsilon) {}

  /// The interpolation parameter t in [epsilon, 1 - epsilon] of surfel s.
  double parameter(const Surfel& s) const {
    const Voxel c = s.inside(), d = s.outside();
    const Dims& dims = gray_.dims;
    if (!dims.contains(c) || !dims.contains(d)) return 0.5;
    return linearParameter(iso_, double(gray_.at(c)), double(gray_.at(d)), epsilon_);
  }

  std::array<double, 3> operator()(const Surfel& s) const { return pointOnSurfel(s, parameter(s)); }

  double isoValue() const { return iso_; }
  double epsilon() const { return epsilon_; }

 private:
  VolumeRef<T> gray_;
  double iso_;
  double epsilon_;
};

template <class T>
IsoValueMapping(const ThresholdImage<T>&, double) -> IsoValueMapping<T>;
template <class T>
IsoValueMapping(const ThresholdImage<T>&) -> IsoValueMapping<T>;

}  // namespace surftrack
