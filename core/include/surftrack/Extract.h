// The front door (docs/api.md): one call from a volume to a closed, oriented surface mesh.
//
//   surftrack::ExtractOptions options;
//   options.selection = surftrack::Selection::threshold(100);
//   options.seed = surftrack::SeedRule::point({12.5, -40, 8});
//   surftrack::Surface s = surftrack::extract(surftrack::VolumeView::of(data, dims), options);
//
// Underneath: a seed rule resolved to a boundary surfel, trackComponent (paper §4.3, §5.2) from
// it, loop extraction into triangles, a boundary mapping (§3.1), physical coordinates — or the
// scanning method (§5.1) over every cube for `largest` and `all`. Nothing on a seeded path
// reads the volume away from the surface.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "AdjacencyPair.h"
#include "Errors.h"
#include "Geometry.h"
#include "Surfel.h"
#include "VolumeView.h"
#include "VoxelSource.h"

namespace surftrack {

/// How to choose the boundary (or boundaries) to extract.
struct SeedRule {
  enum class Kind {
    Surfel,   ///< this boundary surfel
    Voxel,    ///< the boundary surfel nearest this voxel's centre (its own face if it has one)
    Point,    ///< the boundary surfel nearest this physical point
    Ray,      ///< walk from this voxel along +x, -x, +y, -y, +z, -z to the first surfel crossed
    Largest,  ///< the boundary with the most surfels (scans the whole image)
    All       ///< every boundary of the image (scans the whole image)
  };
  Kind kind = Kind::Largest;
  surftrack::Surfel surfel;
  surftrack::Voxel voxel;
  std::array<double, 3> physical{};

  static SeedRule fromSurfel(const surftrack::Surfel& s) { return {Kind::Surfel, s, {}, {}}; }
  static SeedRule fromVoxel(surftrack::Voxel v) { return {Kind::Voxel, {}, v, {}}; }
  static SeedRule ray(surftrack::Voxel v) { return {Kind::Ray, {}, v, {}}; }
  static SeedRule point(const std::array<double, 3>& p) { return {Kind::Point, {}, {}, p}; }
  static SeedRule largest() { return {Kind::Largest, {}, {}, {}}; }
  static SeedRule all() { return {Kind::All, {}, {}, {}}; }
};

/// Where a vertex is placed on its surfel's segment ]c, d[ (paper §3.1).
enum class Mapping {
  Default,   ///< Linear for a threshold, Midpoint for a label
  Midpoint,  ///< (c + d) / 2
  Linear     ///< where the linear interpolation of f along [c, d] crosses the iso-value
};

/// "midpoint", "linear" (Default: "default").
std::string toString(Mapping mapping);
/// Parses "midpoint", "linear" or "default"; throws InvalidInput otherwise.
Mapping parseMapping(const std::string& text);

/// A stage of the extraction has started: its name and its number among `stages`.
struct ProgressEvent {
  std::string stage;  ///< "seed", "track", "convert", "scan", "place", "figures"
  int index = 0, stages = 0;
  std::size_t surfels = 0;  ///< during "track": surfels found so far
};

struct ExtractOptions {
  Selection selection;
  SeedRule seed;
  AdjacencyPair pair = AdjacencyPair::k26_6;
  Mapping mapping = Mapping::Default;
  /// The linear mapping keeps t in [epsilon, 1 - epsilon], so that vertices never reach a voxel.
  double epsilon = 1e-3;
  /// The seed rules Voxel and Point take the nearest boundary surfel within this distance, in
  /// voxels of the smallest spacing (a surfel's midpoint at most maxSeedDistance * min(spacing)
  /// away in physical distance), and fail beyond it rather than read the whole image for a
  /// seed far from any object: the search reads at most about the ball of this radius. Any
  /// positive number; infinity for no bound.
  double maxSeedDistance = 256;
  /// Called at each stage and now and then while tracking; runs on the calling thread.
  std::function<void(const ProgressEvent&)> progress;
  /// If set and raised, the extraction stops at the next check and throws Cancelled.
  const std::atomic<bool>* cancel = nullptr;
  /// Threads for the scanning method (largest, all), the second pass of tracking and the loop
  /// extraction and the placement of the vertices: 0 for all cores. The surface is the same for
  /// any number. The source is then read from several threads at once.
  int threads = 0;
  /// Per-component figures (a union-find over the vertices): off, `components` stays empty,
  /// `euler` 0 and, for `all`, `boundariesInImage` 0 — for callers that need only the mesh.
  bool figures = true;
};

/// The figures of one connected component (one kappa-lambda-boundary, Proposition 39).
struct ComponentFigures {
  std::size_t surfels = 0, triangles = 0, edges = 0;
  long long euler = 0;        ///< V - E + F
  double area = 0;            ///< physical units^2
  double volume = 0;          ///< enclosed, physical units^3 (negative for a cavity's boundary)
  /// (2 - chi) / 2: an integer for a closed orientable surface.
  double genus() const { return (2.0 - double(euler)) / 2.0; }
};

/// What the seed rule resolved to.
struct SeedReport {
  std::optional<surftrack::Surfel> surfel;  ///< the surfel tracking started from (seeded rules)
  std::optional<surftrack::Voxel> voxel;    ///< Voxel / Ray: the start voxel
  bool voxelInside = false;                  ///< the start voxel is a 1-voxel
  std::optional<double> distance;            ///< Voxel / Point: physical distance to the surfel's midpoint
  std::optional<Direction> walkDirection;    ///< Ray: the ray that reached the surfel
  int walkSteps = 0;                         ///< Ray: voxels walked along it
};

struct StageTime {
  std::string stage;
  double seconds = 0;
};

/// A closed, oriented 2-manifold (one per component) whose vertices are boundary surfels.
struct Surface {
  /// Vertex positions in physical coordinates (geometry applied).
  std::vector<std::array<double, 3>> vertices;
  /// Triangles as vertex indices, oriented so that their normals (right-hand rule) point from
  /// the 1-voxels to the 0-voxels in physical space (a mirrored geometry is compensated).
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// surfels[v] is the surfel (c, d) of vertex v, in voxel indices.
  std::vector<surftrack::Surfel> surfels;
  /// One entry per component, by decreasing surfel count.
  std::vector<ComponentFigures> components;
  long long euler = 0;  ///< of the whole surface
  /// largest / all: the number of boundaries in the image (the scan sees them all).
  std::size_t boundariesInImage = 0;

  SeedReport seed;
  /// Things the caller should know, one line each: e.g. that a seeded surface is a speck.
  std::vector<std::string> warnings;
  AdjacencyPair pair = AdjacencyPair::k26_6;
  Selection selection;
  Mapping mapping = Mapping::Midpoint;  ///< the mapping used (never Default)
  /// The source's geometry: a surfel's segment ]c, d[ is [toPhysical(c), toPhysical(d)] in
  /// physical space (smooth() keeps every vertex on it).
  ImageGeometry geometry;
  std::vector<StageTime> timings;
  /// Voxels the extraction asked of the source: its bricks (apron included), rows and gray
  /// values. What a lazy source (a memory-mapped file) has to read; a seeded extraction keeps
  /// it proportional to the surface, a scan (all, largest) counts the whole domain.
  std::uint64_t voxelsRead = 0;

  std::size_t vertexCount() const { return vertices.size(); }
  std::size_t triangleCount() const { return triangles.size(); }
};

/// Extracts the surface the options ask for from `source`.
/// \throw InvalidInput for a selection the source cannot hold (a label of a float volume, a
///        label that is not a value of the type, a NaN threshold), a seed outside the domain
///        or on no boundary, no boundary surfel within maxSeedDistance of a Voxel or Point
///        seed (SeedTooFar, an InvalidInput), an empty selection (largest / all find no boundary), a geometry (spacing,
///        origin) that puts vertices beyond the float range of mesh coordinates.
/// \throw Cancelled when options.cancel is raised.
/// \throw InternalError when an engine invariant fails (a bug).
Surface extract(const VoxelSource& source, const ExtractOptions& options);

/// extract() over a view of memory the caller owns; no voxel is copied.
Surface extract(const VolumeView& view, const ExtractOptions& options);

/// Unit outward vertex normals: the area-weighted sum of the incident triangles' normals.
std::vector<std::array<double, 3>> vertexNormals(const Surface& surface);

/// The figures of each connected component of a triangle mesh (vertices, triangles, edges as
/// 3F / 2, Euler characteristic, area, signed enclosed volume), by decreasing vertex count,
/// and through `componentOf` (if not null) the component index of every vertex.
std::vector<ComponentFigures> componentFigures(
    const std::vector<std::array<double, 3>>& vertices,
    const std::vector<std::array<std::uint32_t, 3>>& triangles,
    std::vector<std::uint32_t>* componentOf = nullptr);

/// Writes the surface to `path` with OpenMesh's IO, the format from the extension (.ply, .obj,
/// .off, .stl; `binary` for .ply and .stl), through a temporary file renamed over `path`, so a
/// failure never leaves a partial file. `cancel`, if set, is checked every 2^16 vertices or
/// triangles written. \throw InvalidInput for an unknown extension; std::system_error (a
/// std::runtime_error) when `path` cannot be written, its code() the system's errno and its
/// message naming the path and the reason ("cannot write 'out/a.ply': directory 'out' does not
/// exist"); Cancelled when `cancel` is raised (the temporary file removed, `path` untouched).
void writeSurface(const Surface& surface, const std::string& path, bool binary = true,
                  const std::atomic<bool>* cancel = nullptr);

/// Writes each connected component of the surface (each boundary, with the scanning rules) to
/// its own file as writeSurface does: paths[k] receives the k-th component of componentFigures'
/// order (by decreasing vertex count, ties by smallest vertex: Surface::components' order), its
/// vertices and triangles in the surface's order, renumbered from 0 (docs/cli.md, "One file per
/// boundary"). \throw InvalidInput when paths.size() is not the number of components; as
/// writeSurface otherwise (the files written before a failure stay: stage them).
void writeSurfaceComponents(const Surface& surface, const std::vector<std::string>& paths, bool binary = true,
                            const std::atomic<bool>* cancel = nullptr);

}  // namespace surftrack
