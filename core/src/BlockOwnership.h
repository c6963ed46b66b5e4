// What the block scans of label maps (LabelBlocks.cpp) and of thresholds (ThresholdBlocks.cpp)
// share (internal to core/; docs/theory.md, "Label maps by blocks" and "Thresholds by blocks"):
// the contract of a block's core and box, the drop of the surfels no owned cube uses, and the
// owning cube of a triangle, by which the merges restore the single pass's order of triangles.
#pragma once

#include "ScanLabels.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "Errors.h"
#include "Surfel.h"
#include "VolumeView.h"

namespace surftrack {

inline std::string boxText(Voxel lo, Voxel hi) {
  std::ostringstream s;
  s << "[" << lo.x << "," << hi.x << ")x[" << lo.y << "," << hi.y << ")x[" << lo.z << "," << hi.z << ")";
  return s.str();
}

/// The block's core, box and volume fit together (scanLabelBlock's and scanThresholdBlock's
/// contract), or InvalidInput.
inline void requireBlock(const VolumeView& view, Voxel origin, Dims volume, Voxel lo, Voxel hi) {
  for (int a = 0; a < 3; ++a)
    if (volume[a] <= 0 || volume[a] >= Surfel::kCoordinateLimit - 2) {
      std::ostringstream msg;
      msg << "volume dimensions " << volume.nx << "x" << volume.ny << "x" << volume.nz
          << " are not supported: each must be in [1, " << Surfel::kCoordinateLimit - 3 << "]";
      throw InvalidInput(msg.str());
    }
  const Voxel end = origin + Voxel{view.dims.nx, view.dims.ny, view.dims.nz};
  const Voxel size{volume.nx, volume.ny, volume.nz};
  for (int a = 0; a < 3; ++a) {
    if (lo[a] < 0 || lo[a] >= hi[a] || hi[a] > volume[a])
      throw InvalidInput("block core " + boxText(lo, hi) + " is empty or not in the volume " +
                         boxText({}, size));
    if (origin[a] < 0 || end[a] > volume[a])
      throw InvalidInput("block box " + boxText(origin, end) + " is not in the volume " + boxText({}, size));
    if (origin[a] > lo[a] || end[a] < std::min(hi[a] + 1, volume[a]))
      throw InvalidInput("block box " + boxText(origin, end) + " does not hold the core " + boxText(lo, hi) +
                         " and its one-voxel apron on the high sides");
  }
}

/// Keeps the keys some triangle uses, still increasing, and renumbers the triangles: a block's
/// scan numbers every surfel of the planes it reads, but an owned cube's triangles use only
/// surfels of the volume with both voxels in the box or one outside the volume.
/// The cubes a block owns (docs/theory.md, "Label maps by blocks"), in the coordinates of its box
/// from `origin`: min corners in [lo, hi), and -1 where the core starts at the volume's low face
/// (the box then does too), for the cubes over that face.
inline ScanOwnership ownedCubes(Voxel origin, Voxel lo, Voxel hi) {
  ScanOwnership own;
  own.origin = origin;
  for (int a = 0; a < 3; ++a) {
    own.lo[std::size_t(a)] = lo[a] == 0 ? -1 : lo[a] - origin[a];
    own.hi[std::size_t(a)] = hi[a] - origin[a];
  }
  return own;
}

inline void dropUnusedKeys(std::vector<std::uint64_t>& keys, std::vector<std::array<std::uint32_t, 3>>& triangles) {
  std::vector<std::uint32_t> index(keys.size(), 0);
  for (const auto& t : triangles)
    for (std::uint32_t v : t) index[v] = 1;
  std::uint32_t next = 0;
  for (std::size_t v = 0; v < index.size(); ++v)
    if (index[v]) {
      keys[next] = keys[v];  // next <= v: in place, still increasing
      index[v] = next++;
    }
  keys.resize(next);
  keys.shrink_to_fit();
  for (auto& t : triangles)
    for (std::uint32_t& v : t) v = index[v];
}

/// A cube's min corner packed so that the order of the packed values is the scan's order of
/// the cubes (z, y, x).
inline std::uint64_t packedCube(Voxel m) {
  auto field = [](int v) { return std::uint64_t(v + Surfel::kCoordinateLimit) & 0x1FFFFFu; };
  return field(m.z) << 42 | field(m.y) << 21 | field(m.x);
}

/// The min corner of the cube that owns a triangle of these surfels: the componentwise minimum
/// of their six voxels (no table triangle lies in a cube face, tests/test_configuration_tables.cpp),
/// packed so that the order of the packed values is the scan's order of the cubes (z, y, x).
inline std::uint64_t owningCube(const std::array<std::uint64_t, 3>& keys) {
  Voxel m{std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::max()};
  for (std::uint64_t key : keys) {
    const Surfel s = Surfel::fromKey(key);
    for (const Voxel v : {s.inside(), s.outside()}) m = {std::min(m.x, v.x), std::min(m.y, v.y), std::min(m.z, v.z)};
  }
  return packedCube(m);
}

/// Whether a fragment's keys are surfel keys, strictly increasing.
inline bool validKeys(const std::vector<std::uint64_t>& keys) {
  for (std::size_t v = 0; v < keys.size(); ++v)
    if (keys[v] >> 63 || (keys[v] & 7) > 5 || (v > 0 && keys[v] <= keys[v - 1])) return false;
  return true;
}

}  // namespace surftrack
