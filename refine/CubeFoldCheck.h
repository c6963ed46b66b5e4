// The fold check of one digital 3-cube (docs/theory.md, section 8, "Smoothing inside the
// segments"): the triangles of the continuous analog that lie in one cube are embedded when each
// is non-degenerate, keeps the side of its reference normal, and any two meet only in the
// vertices or the edge they share. By section 8, point 4, triangles of different cubes never
// meet improperly while every vertex stays inside its segment, so a mesh whose cubes all pass
// has no self-intersection.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "Surfel.h"
#include "TriangleIntersection.h"

namespace surftrack::refine {

/// A triangle of one cube: its vertex ids (orientation order), its points (index space) and the
/// normal it must keep the side of.
struct CubeTriangle {
  std::array<std::uint32_t, 3> vertex{};
  Triangle3 point{};
  Point3 reference{};
};

/// Absolute tolerance of the fold check, in voxels (index space).
inline constexpr double kFoldTolerance = 1e-9;

/// True when triangle t is non-degenerate and keeps the side of its reference normal.
bool triangleKeepsItsSide(const CubeTriangle& t, double tolerance = kFoldTolerance);

/// True when triangles t and u of one cube meet only in the vertices they share (by id) and the
/// edge those span, up to `tolerance`.
/// \pre neither is degenerate (triangleKeepsItsSide).
bool trianglesAreEmbedded(const CubeTriangle& t, const CubeTriangle& u, double tolerance = kFoldTolerance);

/// True when the triangles of one cube are embedded (see above) up to `tolerance`: each keeps
/// its side, and every two are embedded.
bool cubeIsEmbedded(std::span<const CubeTriangle> triangles, double tolerance = kFoldTolerance);

/// The digital 3-cube (its minimum corner m, paper §2.1.2) whose edges carry the grid edges
/// of the three surfels, or nothing when there is none (section 8: every triangle of the
/// continuous analog has one).
std::optional<Voxel> cubeOfTriangle(const Surfel& a, const Surfel& b, const Surfel& c);

}  // namespace surftrack::refine
