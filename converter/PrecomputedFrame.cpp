// The frames of the command line's Neuroglancer outputs (PrecomputedFrame.h).
#include "PrecomputedFrame.h"

#include <utility>

namespace surftrack {

ToNanometres legacyFrame(const ImageGeometry& g, double k) {
  ToNanometres m;
  for (int r = 0; r < 3; ++r) {
    m.linear[r] = {r == 0 ? k : 0.0, r == 1 ? k : 0.0, r == 2 ? k : 0.0};
    double shift = 0;
    for (int e = 0; e < 3; ++e) shift += g.direction[r][e] * g.spacing[e] / 2;
    m.offset[r] = k * shift;
  }
  return m;
}

ToNanometres multiresFrame(const ImageGeometry& g, double k) {
  ToNanometres m;
  for (int r = 0; r < 3; ++r) {
    double shift = 0;
    for (int c = 0; c < 3; ++c) {
      m.linear[r][c] = k * g.direction[r][c] * g.spacing[c];
      shift += g.direction[r][c] * g.spacing[c] / 2;
    }
    m.offset[r] = k * (g.origin[r] + shift);
  }
  return m;
}

void toVoxelIndices(const ImageGeometry& g, std::vector<std::array<double, 3>>& vertices,
                    std::vector<std::array<std::uint32_t, 3>>& triangles) {
  for (auto& p : vertices) p = g.toIndex(p);
  // Triangles face out in physical space; in index space too unless the geometry mirrors.
  if (g.handedness() < 0)
    for (auto& t : triangles) std::swap(t[1], t[2]);
}

}  // namespace surftrack
