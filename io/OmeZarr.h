// OME-Zarr 0.4 multiscale images (docs/api.md "Chunked stores"): a zarr group whose `.zattrs`
// holds "multiscales", each a list of datasets (zarr arrays, the resolution levels, finest
// first) sharing named axes (time, channel, then 2 or 3 space axes, in numpy's order). Each
// level maps its array indices to physical coordinates by its coordinateTransformations (one
// scale, then optionally one translation), followed by those of the whole multiscale:
//   scale = s_d * s_m,   translation = t_d * s_m + t_m.
#pragma once

#include <string>
#include <vector>

namespace surftrack::io {

struct OmeAxis {
  std::string name;  ///< "z", "y", "x", "c", "t", ...
  std::string type;  ///< "space", "time", "channel", or another (empty: not stated)
  std::string unit;  ///< "micrometer", ... (empty: not stated)
};

/// The first multiscale image of an OME-Zarr group, its transformations composed per level.
struct OmeMultiscale {
  std::string version;
  std::vector<OmeAxis> axes;                      ///< numpy's order
  std::vector<std::string> paths;                 ///< each level's array, relative to the group
  std::vector<std::vector<double>> scale, translation;  ///< per level, one per axis (composed)
  int spatialAxes = 3;                            ///< the trailing "space" axes: 2 or 3
  std::string unit;                               ///< the space axes' unit (the same for all; empty: none stated)
};

/// Whether `<dir>/.zattrs` exists and holds "multiscales". Throws ReadError for a .zattrs
/// that is not JSON.
bool isOmeZarr(const std::string& dir);

/// Reads the first multiscale of `<dir>/.zattrs`. Throws ReadError naming the file: version
/// other than 0.4, axes that are not 2 or 3 trailing space axes after at most one time and one
/// channel axis, space axes of different units, no datasets, transformations that are not one
/// scale (positive) and an optional translation per level (values of one per axis).
OmeMultiscale readOmeMultiscale(const std::string& dir);

}  // namespace surftrack::io
