// Physical coordinates a mesh can hold (internal to core/). Mesh files store vertices as 32-bit
// floats (PLY, STL; OBJ and OFF are read back as such), so a spacing or origin that puts a
// vertex beyond the float range — or beyond the double range, where toPhysical gives inf — is
// the caller's error (InvalidInput), not a mesh of infinite vertices. Checked up front over the
// whole domain (8 corners: the map is affine), and again wherever vertices are placed from the
// geometry (placeSurface, the label scan, smoothing).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "Errors.h"
#include "Geometry.h"

namespace surftrack {

/// |x| within the float range (false for inf and NaN).
inline bool fitsFloat(double x) { return std::abs(x) <= double(std::numeric_limits<float>::max()); }

inline bool fitsFloat(const std::array<double, 3>& p) { return fitsFloat(p[0]) && fitsFloat(p[1]) && fitsFloat(p[2]); }

/// The message: the geometry, and one index point it sends out of range and where.
inline std::string outOfRangeText(const ImageGeometry& g, const std::array<double, 3>& index,
                                  const std::array<double, 3>& physical) {
  std::ostringstream s;
  s.precision(6);
  s << "the spacing (" << g.spacing[0] << ", " << g.spacing[1] << ", " << g.spacing[2] << ") and origin ("
    << g.origin[0] << ", " << g.origin[1] << ", " << g.origin[2]
    << ") put vertices beyond the float range of mesh coordinates (|x| <= " << std::numeric_limits<float>::max()
    << "): index (" << index[0] << ", " << index[1] << ", " << index[2] << ") maps to (" << physical[0] << ", "
    << physical[1] << ", " << physical[2] << ")";
  return s.str();
}

/// Throws InvalidInput unless every point of the index-space box [lo, hi] maps into the float
/// range (its 8 corners do).
inline void requirePhysicalBox(const ImageGeometry& g, const std::array<double, 3>& lo,
                               const std::array<double, 3>& hi) {
  for (int corner = 0; corner < 8; ++corner) {
    std::array<double, 3> index{};
    for (int a = 0; a < 3; ++a) index[a] = (corner >> a) & 1 ? hi[a] : lo[a];
    const std::array<double, 3> p = g.toPhysical(index);
    if (!fitsFloat(p)) throw InvalidInput(outOfRangeText(g, index, p));
  }
}

/// The same for every vertex a surface of `dims` can have: vertices lie on surfel segments
/// ]c, d[, c in the domain, d at most one voxel outside it, so in the box [-1, n]^3.
inline void requirePhysicalDomain(const ImageGeometry& g, const Dims& dims) {
  requirePhysicalBox(g, {-1.0, -1.0, -1.0}, {double(dims.nx), double(dims.ny), double(dims.nz)});
}

/// Throws InvalidInput if a placed vertex is beyond the float range (rounding at the edge of
/// a domain that passed requirePhysicalDomain); `index` gives the point it was placed from.
template <class IndexOf>
void requirePlacedVertices(const ImageGeometry& g, const std::vector<std::array<double, 3>>& vertices,
                           IndexOf index) {
  for (std::size_t v = 0; v < vertices.size(); ++v)
    if (!fitsFloat(vertices[v])) throw InvalidInput(outOfRangeText(g, index(v), vertices[v]));
}

}  // namespace surftrack
