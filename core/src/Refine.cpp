// smooth() and decimate() of the front door (docs/api.md): a Surface to the refine/ algorithms
// (smoothing on its arrays, decimation through the half-edge SurfaceMesh and back), with the
// figures recomputed.
#include "Refine.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "ConstrainedSmoothing.h"
#include "PhysicalRange.h"
#include "PlaceSurface.h"
#include "SmoothingParameters.h"
#include "SurfaceMesh.h"
#include "TopologySafeDecimation.h"

namespace surftrack {

namespace {

SurfaceMesh meshOf(const Surface& s) {
  return toSurfaceMesh(TriangleMesh{s.surfels, s.triangles}, s.vertices);
}

/// Points, triangles and surfels back from the mesh (vertex order kept), figures recomputed.
void store(const SurfaceMesh& mesh, Surface& s) {
  const auto surfel = surfelProperty(mesh);
  s.vertices.resize(mesh.n_vertices());
  s.surfels.resize(mesh.n_vertices());
  for (auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    s.vertices[vh.idx()] = {p[0], p[1], p[2]};
    s.surfels[vh.idx()] = mesh.property(surfel, vh);
  }
  s.triangles.resize(mesh.n_faces());
  for (auto fh : mesh.faces()) {
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) s.triangles[fh.idx()][k++] = std::uint32_t(vh.idx());
  }
  addFigures(s);
}

/// The enclosed volume of the surface, from its triangles (its components may not be computed:
/// extract with figures off); a surface of one component (one tracked boundary) needs no
/// union-find to find it.
double volumeOf(const Surface& s) {
  if (s.components.size() == 1 && s.components[0].triangles == s.triangles.size())
    return connectedMeshFigures(s.vertices, s.triangles).volume;
  double v = 0;
  for (const ComponentFigures& c : componentFigures(s.vertices, s.triangles)) v += c.volume;
  return v;
}

/// The same after store(), from the figures it has just computed.
double storedVolume(const Surface& s) {
  double v = 0;
  for (const ComponentFigures& c : s.components) v += c.volume;
  return v;
}

/// Runs a refine/ algorithm with its errors as the front door's: a bad argument is the
/// caller's (InvalidInput), a broken invariant the engine's (InternalError). (The order of the
/// handlers matters: std::invalid_argument is a std::logic_error.)
template <class F>
auto translatingErrors(F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {
    throw InternalError(e.what());
  }
}

}  // namespace

namespace {

/// Throws InvalidInput if surface.geometry puts a point of a surfel's segment [c, d] — where
/// smoothing moves the vertex — beyond the float range (PhysicalRange.h): the box of the
/// surfels' voxels, checked at its corners, before any vertex moves.
void requireSegmentsInRange(const Surface& surface) {
  if (surface.surfels.empty()) return;
  std::array<double, 3> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const Surfel& s : surface.surfels)
    for (const Voxel v : {s.inside(), s.outside()})
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], double(v[a]));
        hi[a] = std::max(hi[a], double(v[a]));
      }
  requirePhysicalBox(surface.geometry, lo, hi);
}

}  // namespace

SmoothReport smooth(Surface& surface, const SmoothOptions& o) {
  const refine::SmoothingParameters p = smoothingParameters(o);
  requireSegmentsInRange(surface);
  SmoothReport report;
  report.volumeBefore = volumeOf(surface);
  // Smoothing moves points only: it works on the surface's arrays, with no half-edge mesh.
  const refine::SmoothingReport r = translatingErrors([&] {
    return refine::smoothOnSegments(surface.vertices, surface.surfels, surface.triangles, surface.geometry, p);
  });
  addFigures(surface, /*connected=*/surface.components.size() == 1);  // (the connectivity is unchanged)
  report.iterations = o.iterations;
  report.cubes = r.cubes;
  report.unguardedCubes = r.unguardedCubes;
  report.checkedCubes = r.checkedCubes;
  report.stepsBack = r.stepsBack;
  report.maxDisplacement = r.maxDisplacement;
  report.volumeAfter = storedVolume(surface);
  return report;
}

DecimateReport decimate(Surface& surface, const DecimateOptions& o) {
  if (!o.maxError && !o.reduction)
    throw InvalidInput("decimation needs a max error, a reduction or both");
  refine::DecimationParameters p;
  p.maxError = o.maxError;
  p.targetReduction = o.reduction;
  p.maxNormalDeviation = o.maxNormalDeviation;
  p.cancel = o.cancel;
  DecimateReport report;
  report.volumeBefore = volumeOf(surface);
  SurfaceMesh mesh = meshOf(surface);
  const refine::DecimationReport r = translatingErrors([&] { return refine::decimateSafely(mesh, p); });
  store(mesh, surface);
  report.trianglesBefore = r.trianglesBefore;
  report.trianglesAfter = r.trianglesAfter;
  report.targetTriangles = r.targetTriangles;
  report.volumeAfter = storedVolume(surface);
  return report;
}

RefineReport refineSurface(Surface& surface, const RefineOptions& o) {
  RefineReport report;
  const int steps = int(o.smooth.has_value()) + int(o.decimate.has_value());
  int step = 0;
  auto starting = [&](const char* stage) {
    if (o.progress) o.progress(ProgressEvent{stage, step++, steps, 0});
  };
  if (o.smooth) {
    starting("smooth");
    report.smooth = smooth(surface, *o.smooth);
  }
  if (o.decimate) {
    starting("decimate");
    report.decimate = decimate(surface, *o.decimate);
  }
  if (report.smooth) report.volumeBefore = report.smooth->volumeBefore;
  else if (report.decimate) report.volumeBefore = report.decimate->volumeBefore;
  else if (!surface.components.empty()) report.volumeBefore = storedVolume(surface);  // nothing to do: no pass
  else report.volumeBefore = volumeOf(surface);
  if (report.decimate) report.volumeAfter = report.decimate->volumeAfter;
  else if (report.smooth) report.volumeAfter = report.smooth->volumeAfter;
  else report.volumeAfter = report.volumeBefore;
  return report;
}

}  // namespace surftrack
