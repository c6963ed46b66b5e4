// smooth() and decimate() of the front door (docs/api.md): a Surface through the half-edge
// SurfaceMesh to the refine/ algorithms and back, with the figures recomputed.
#include "Refine.h"

#include <stdexcept>

#include "ConstrainedSmoothing.h"
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
  s.components = componentFigures(s.vertices, s.triangles);
  s.euler = 0;
  for (const ComponentFigures& c : s.components) s.euler += c.euler;
}

double volumeOf(const Surface& s) {
  double v = 0;
  for (const ComponentFigures& c : componentFigures(s.vertices, s.triangles)) v += c.volume;
  return v;
}

}  // namespace

SmoothReport smooth(Surface& surface, const SmoothOptions& o) {
  refine::SmoothingParameters p;
  p.iterations = o.iterations;
  p.lambda = o.lambda;
  p.mu = o.mu;
  p.epsilon = o.epsilon;
  SmoothReport report;
  report.volumeBefore = volumeOf(surface);
  SurfaceMesh mesh = meshOf(surface);
  refine::SmoothingReport r;
  try {
    r = refine::smoothOnSegments(mesh, surface.geometry, p);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {
    throw InternalError(e.what());
  }
  store(mesh, surface);
  report.iterations = o.iterations;
  report.cubes = r.cubes;
  report.unguardedCubes = r.unguardedCubes;
  report.stepsBack = r.stepsBack;
  report.maxDisplacement = r.maxDisplacement;
  report.volumeAfter = volumeOf(surface);
  return report;
}

DecimateReport decimate(Surface& surface, const DecimateOptions& o) {
  if (!o.maxError && !o.reduction)
    throw InvalidInput("decimation needs a max error, a reduction or both");
  refine::DecimationParameters p;
  p.maxError = o.maxError;
  p.targetReduction = o.reduction;
  p.maxNormalDeviation = o.maxNormalDeviation;
  DecimateReport report;
  report.volumeBefore = volumeOf(surface);
  SurfaceMesh mesh = meshOf(surface);
  refine::DecimationReport r;
  try {
    r = refine::decimateSafely(mesh, p);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {
    throw InternalError(e.what());
  }
  store(mesh, surface);
  report.trianglesBefore = r.trianglesBefore;
  report.trianglesAfter = r.trianglesAfter;
  report.targetTriangles = r.targetTriangles;
  report.volumeAfter = volumeOf(surface);
  return report;
}

}  // namespace surftrack
