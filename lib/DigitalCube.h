// Digital 3-cubes (paper §2.1.2): the 8 voxels m + {0,1}^3 of a "marching cube" with min
// corner m. Conventions shared by the configuration tables, the converter and the scanner:
//  - corner i in 0..7 is m + (i & 1, (i >> 1) & 1, (i >> 2) & 1);
//  - a configuration is the byte whose bit i is the value of corner i;
//  - edge k in 0..11 is parallel to axis a = k / 4; with b < c the two other axes, its low
//    corner has bit b = k & 1 and bit c = (k >> 1) & 1 and bit a = 0, its high corner bit a = 1.
// A surfel lies on exactly one grid edge, and each edge belongs to 4 digital 3-cubes.
#pragma once

#include <array>
#include <cstdint>

#include "Surfel.h"
#include "Voxel.h"

namespace surftrack::cube {

constexpr int kCorners = 8;
constexpr int kEdges = 12;

constexpr Voxel cornerOffset(int i) { return Voxel{i & 1, (i >> 1) & 1, (i >> 2) & 1}; }

constexpr int edgeAxis(int k) { return k >> 2; }

/// The two axes other than `a`, in increasing order.
constexpr std::array<int, 2> otherAxes(int a) {
  return a == 0 ? std::array<int, 2>{1, 2} : a == 1 ? std::array<int, 2>{0, 2} : std::array<int, 2>{0, 1};
}

constexpr int edgeLowCorner(int k) {
  auto [b, c] = otherAxes(edgeAxis(k));
  return ((k & 1) << b) | (((k >> 1) & 1) << c);
}
constexpr int edgeHighCorner(int k) { return edgeLowCorner(k) | (1 << edgeAxis(k)); }

/// The edge joining corners i and j (which must differ in exactly one bit), or -1.
constexpr int edgeBetween(int i, int j) {
  int diff = i ^ j;
  if (diff != 1 && diff != 2 && diff != 4) return -1;
  int a = diff == 1 ? 0 : diff == 2 ? 1 : 2;
  int lo = i & ~diff;
  auto [b, c] = otherAxes(a);
  return 4 * a + ((lo >> b) & 1) + 2 * ((lo >> c) & 1);
}

/// Corner index of voxel v in the cube with min corner m, or -1 if v is not in the cube.
constexpr int cornerOf(Voxel m, Voxel v) {
  Voxel d = v - m;
  if (unsigned(d.x) > 1u || unsigned(d.y) > 1u || unsigned(d.z) > 1u) return -1;
  return d.x | (d.y << 1) | (d.z << 2);
}

/// The cube edge on which surfel s lies, or -1 if s is not in the cube with min corner m.
constexpr int edgeOf(Voxel m, const Surfel& s) {
  int i = cornerOf(m, s.inside());
  if (i < 0) return -1;
  int j = cornerOf(m, s.outside());
  if (j < 0) return -1;
  return edgeBetween(i, j);
}

/// The surfel on edge k of the cube with min corner m, for configuration `config` (the edge
/// must join a 1-corner and a 0-corner).
constexpr Surfel surfelOnEdge(Voxel m, int k, std::uint8_t config) {
  int lo = edgeLowCorner(k), hi = edgeHighCorner(k);
  int a = edgeAxis(k);
  bool loIsOne = (config >> lo) & 1;
  return loIsOne ? Surfel{m + cornerOffset(lo), directionOf(a, +1)}
                 : Surfel{m + cornerOffset(hi), directionOf(a, -1)};
}

/// True when edge k joins a 1-corner and a 0-corner, i.e. carries a boundary surfel.
constexpr bool edgeIsCut(int k, std::uint8_t config) {
  return ((config >> edgeLowCorner(k)) & 1) != ((config >> edgeHighCorner(k)) & 1);
}

/// The 4 digital 3-cubes around the grid edge of a surfel with normal n, q = 0..3: bit 0 of q
/// set when the cube extends towards -b from the edge, bit 1 towards -c (b < c the two axes
/// orthogonal to n). `offset` is the cube's min corner minus the surfel's 1-voxel, `edge` the
/// cube edge the surfel lies on.
struct CubeAroundSurfel {
  Voxel offset;
  int edge = 0;
};
inline constexpr std::array<std::array<CubeAroundSurfel, 4>, 6> kCubesAroundSurfel = [] {
  std::array<std::array<CubeAroundSurfel, 4>, 6> out{};
  for (Direction n = 0; n < 6; ++n) {
    const int a = axisOf(n);
    const auto [b, c] = otherAxes(a);
    for (int q = 0; q < 4; ++q) {
      Voxel m = signOf(n) > 0 ? Voxel{} : unitVector(n);  // low end of the edge along a
      m[b] -= q & 1;
      m[c] -= (q >> 1) & 1;
      out[n][q] = {m, edgeOf(m, Surfel{Voxel{}, n})};
    }
  }
  return out;
}();

/// Min corners of the 4 digital 3-cubes that contain the grid edge of surfel s.
inline std::array<Voxel, 4> cubesOf(const Surfel& s) {
  std::array<Voxel, 4> out{};
  for (int q = 0; q < 4; ++q) out[q] = s.inside() + kCubesAroundSurfel[s.n][q].offset;
  return out;
}

/// Reads the configuration byte of the cube with min corner m from any binary image.
template <class BinaryImage>
inline std::uint8_t configurationAt(const BinaryImage& image, Voxel m) {
  std::uint8_t config = 0;
  for (int i = 0; i < kCorners; ++i) {
    Voxel v = m + cornerOffset(i);
    if (image(v.x, v.y, v.z)) config |= std::uint8_t(1u << i);
  }
  return config;
}

}  // namespace surftrack::cube
