#include "TopologySafeDecimation.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include "CheckedDecimater.h"
#include "DistanceGuard.h"
#include "EmbeddingGuard.h"
#include "GridLockGuard.h"
#include "TopologyGuard.h"

namespace surftrack::refine {

void requireDecimationParameters(const DecimationParameters& p) {
  std::ostringstream msg;
  if (p.maxError && !(*p.maxError > 0 && std::isfinite(*p.maxError)))
    msg << "decimation max error " << *p.maxError << " is not a positive distance";
  else if (p.targetReduction && !(*p.targetReduction >= 0 && *p.targetReduction < 1))
    msg << "decimation reduction " << *p.targetReduction << " is outside [0, 1[";
  else if (!(p.maxNormalDeviation > 0 && p.maxNormalDeviation <= 180))
    msg << "decimation normal deviation " << p.maxNormalDeviation << " is outside ]0, 180]";
  if (!msg.str().empty()) throw std::invalid_argument(msg.str());
}

DecimationReport decimateSafely(SurfaceMesh& mesh, const DecimationParameters& p) {
  requireDecimationParameters(p);
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h)) throw std::invalid_argument("decimation needs a closed mesh: it has a boundary edge");

  DecimationReport report;
  report.trianglesBefore = mesh.n_faces();
  prepareForDecimation(mesh);

  CheckedDecimaterT<SurfaceMesh> decimater(mesh);
  OpenMesh::Decimater::ModQuadricT<SurfaceMesh>::Handle quadric;
  ModSampledDistanceT<SurfaceMesh>::Handle distance;
  OpenMesh::Decimater::ModNormalFlippingT<SurfaceMesh>::Handle flipping;
  ModTopologyGuardT<SurfaceMesh>::Handle guard;
  ModEmbeddingGuardT<SurfaceMesh>::Handle embedding;
  decimater.add(quadric);
  decimater.add(flipping);
  decimater.add(guard);
  decimater.add(embedding);
  decimater.module(quadric).unset_max_err();
  if (p.maxError) {
    decimater.module(quadric).set_max_err(*p.maxError * *p.maxError, false);
    decimater.add(distance);
    decimater.module(distance).set_tolerance(*p.maxError);
  }
  decimater.module(flipping).set_max_normal_deviation(p.maxNormalDeviation);
  ModGridLockT<SurfaceMesh>::Handle lock;
  if (p.grid) {
    decimater.add(lock);
    decimater.module(lock).set_grid(*p.grid, p.gridLevel);
  }
  if (!decimater.initialize()) throw std::logic_error("decimateSafely: the decimater refused its modules");
  if (p.targetReduction)
    report.targetTriangles = std::size_t(std::llround((1 - *p.targetReduction) * double(report.trianglesBefore)));
  auto& quadricModule = decimater.module(quadric);
  decimater.decimateToFaces(
      report.targetTriangles, [&](const auto& ci) { return quadricModule.collapse_priority(ci); }, p.cancel);
  mesh.garbage_collection();
  report.trianglesAfter = mesh.n_faces();
  return report;
}

}  // namespace surftrack::refine
