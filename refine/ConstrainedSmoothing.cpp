#include "ConstrainedSmoothing.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "BoundaryMapping.h"
#include "CubeFoldCheck.h"

namespace surftrack::refine {

namespace {

using Vec = std::array<double, 3>;

double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// cos^2 of the largest angle between a segment and the vertex normal for which the move
/// follows the normal (cos = 0.3, about 72.5 degrees).
constexpr double kMinNormalCosine2 = 0.09;

void requireParameters(const SmoothingParameters& p) {
  std::ostringstream msg;
  if (p.iterations < 0) msg << "smoothing iterations " << p.iterations << " is negative";
  else if (!(p.lambda > 0 && p.lambda <= 1)) msg << "smoothing lambda " << p.lambda << " is outside ]0, 1]";
  else if (!(p.mu < -p.lambda)) msg << "smoothing mu " << p.mu << " is not below -lambda = " << -p.lambda;
  else if (!(p.mu >= -1)) msg << "smoothing mu " << p.mu << " is below -1";
  else if (!(p.epsilon > 0 && p.epsilon < 0.5)) msg << "smoothing epsilon " << p.epsilon << " is outside ]0, 0.5[";
  else if (p.halvings < 0) msg << "smoothing halvings " << p.halvings << " is negative";
  else return;
  throw std::invalid_argument(msg.str());
}

/// Compressed lists: the items of list i are items[start[i] .. start[i + 1]).
struct Lists {
  std::vector<std::uint32_t> start, items;
  std::span<const std::uint32_t> operator[](std::size_t i) const {
    return {items.data() + start[i], items.data() + start[i + 1]};
  }
};

Lists invert(const std::vector<std::uint32_t>& owner, std::size_t count) {
  Lists out;
  out.start.assign(count + 1, 0);
  for (std::uint32_t o : owner) ++out.start[o + 1];
  for (std::size_t i = 0; i < count; ++i) out.start[i + 1] += out.start[i];
  out.items.resize(owner.size());
  std::vector<std::uint32_t> next(out.start.begin(), out.start.end() - 1);
  for (std::size_t k = 0; k < owner.size(); ++k) out.items[next[owner[k]]++] = std::uint32_t(k);
  return out;
}

}  // namespace

SmoothingReport smoothOnSegments(SurfaceMesh& mesh, const ImageGeometry& geometry,
                                 const SmoothingParameters& p) {
  requireParameters(p);
  const auto surfelHandle = surfelProperty(mesh);
  const std::size_t nv = mesh.n_vertices(), nf = mesh.n_faces();
  SmoothingReport report;
  report.passes = 2 * p.iterations;

  // Each vertex's segment in physical space: P(c) + t (P(d) - P(c)) (toPhysical is affine).
  std::vector<Surfel> surfel(nv);
  std::vector<Vec> base(nv), axis(nv), start(nv);
  std::vector<double> inverseLength2(nv), t(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    const auto vh = mesh.vertex_handle(unsigned(v));
    const Surfel s = mesh.property(surfelHandle, vh);
    surfel[v] = s;
    const Voxel c = s.inside(), d = s.outside();
    base[v] = geometry.toPhysical({double(c.x), double(c.y), double(c.z)});
    const Vec pd = geometry.toPhysical({double(d.x), double(d.y), double(d.z)});
    for (int k = 0; k < 3; ++k) axis[v][k] = pd[k] - base[v][k];
    inverseLength2[v] = 1.0 / dot(axis[v], axis[v]);
    const auto& q = mesh.point(vh);
    start[v] = {q[0], q[1], q[2]};
    const Vec r{q[0] - base[v][0], q[1] - base[v][1], q[2] - base[v][2]};
    const double tv = dot(r, axis[v]) * inverseLength2[v];
    double off = 0;
    for (int k = 0; k < 3; ++k) off = std::max(off, std::abs(r[k] - tv * axis[v][k]));
    if (!(tv > 0 && tv < 1) || off > 1e-6 * std::sqrt(dot(axis[v], axis[v]))) {
      std::ostringstream msg;
      msg << "vertex " << v << " is not inside the segment of its " << s;
      throw std::invalid_argument(msg.str());
    }
    t[v] = std::clamp(tv, p.epsilon, 1 - p.epsilon);
  }

  // Triangles by digital 3-cube (section 8: each has one), the cubes of each vertex, and
  // each triangle's reference normal: its normal in index space at the midpoint mapping.
  std::vector<std::array<std::uint32_t, 3>> triangle(nf);
  std::vector<std::uint32_t> cubeOfFace(nf);
  std::unordered_map<Voxel, std::uint32_t> cubeIndex;  // std::hash<Voxel>: lib/Voxel.h
  cubeIndex.reserve(nf);
  std::vector<Point3> reference(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    int k = 0;
    for (auto vh : mesh.fv_range(mesh.face_handle(unsigned(f)))) triangle[f][k++] = std::uint32_t(vh.idx());
    const auto& tr = triangle[f];
    const std::optional<Voxel> m = cubeOfTriangle(surfel[tr[0]], surfel[tr[1]], surfel[tr[2]]);
    if (!m) {
      std::ostringstream msg;
      msg << "triangle " << f << " has its vertices in no single digital 3-cube: constrained smoothing "
          << "needs the continuous analog itself (smooth before decimating)";
      throw std::invalid_argument(msg.str());
    }
    cubeOfFace[f] = cubeIndex.try_emplace(*m, std::uint32_t(cubeIndex.size())).first->second;
    reference[f] = triangleNormal({pointOnSurfel(surfel[tr[0]], 0.5), pointOnSurfel(surfel[tr[1]], 0.5),
                                   pointOnSurfel(surfel[tr[2]], 0.5)});
  }
  const std::size_t nc = cubeIndex.size();
  report.cubes = nc;
  const Lists facesOfCube = invert(cubeOfFace, nc);
  std::vector<std::uint32_t> cubeOfCorner;  // vertex -> its cubes, through its faces
  std::vector<std::uint32_t> cornerVertex;
  cubeOfCorner.reserve(3 * nf);
  cornerVertex.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f)
    for (std::uint32_t v : triangle[f]) {
      cornerVertex.push_back(v);
      cubeOfCorner.push_back(cubeOfFace[f]);
    }
  Lists cornersOfVertex = invert(cornerVertex, nv);
  Lists cubesOfVertex;  // deduplicated
  cubesOfVertex.start.assign(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    const std::size_t first = cubesOfVertex.items.size();
    for (std::uint32_t corner : cornersOfVertex[v]) {
      const std::uint32_t c = cubeOfCorner[corner];
      if (std::find(cubesOfVertex.items.begin() + std::ptrdiff_t(first), cubesOfVertex.items.end(), c) ==
          cubesOfVertex.items.end())
        cubesOfVertex.items.push_back(c);
    }
    cubesOfVertex.start[v + 1] = std::uint32_t(cubesOfVertex.items.size());
  }
  // One-ring neighbours (uniform Laplacian).
  Lists ring;
  ring.start.assign(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    for (auto w : mesh.vv_range(mesh.vertex_handle(unsigned(v)))) ring.items.push_back(std::uint32_t(w.idx()));
    ring.start[v + 1] = std::uint32_t(ring.items.size());
  }

  std::vector<CubeTriangle> scratch;
  auto embedded = [&](std::uint32_t c) {
    scratch.clear();
    for (std::uint32_t f : facesOfCube[c]) {
      CubeTriangle ct;
      ct.vertex = triangle[f];
      for (int k = 0; k < 3; ++k) ct.point[k] = pointOnSurfel(surfel[ct.vertex[k]], t[ct.vertex[k]]);
      ct.reference = reference[f];
      scratch.push_back(ct);
    }
    return cubeIsEmbedded(scratch);
  };
  // The cubes the check guards: those embedded in the input (section 8).
  std::vector<char> guarded(nc);
  for (std::uint32_t c = 0; c < nc; ++c) {
    guarded[c] = embedded(c);
    if (!guarded[c]) ++report.unguardedCubes;
  }

  std::vector<double> previous(nv);
  std::vector<Vec> x(nv), normal(nv);
  std::vector<int> halved(nv);
  std::vector<char> queued(nc, 0);
  std::vector<std::uint32_t> queue, cubeVertices;
  auto pass = [&](double factor) {
    for (std::size_t v = 0; v < nv; ++v)
      for (int k = 0; k < 3; ++k) x[v][k] = base[v][k] + t[v] * axis[v][k];
    previous = t;
    // Area-weighted vertex normals of the current surface.
    std::fill(normal.begin(), normal.end(), Vec{0, 0, 0});
    for (const auto& tr : triangle) {
      const Point3 n = triangleNormal({x[tr[0]], x[tr[1]], x[tr[2]]});
      for (std::uint32_t v : tr)
        for (int k = 0; k < 3; ++k) normal[v][k] += n[k];
    }
    for (std::size_t v = 0; v < nv; ++v) {
      const auto neighbours = ring[v];
      if (neighbours.empty()) continue;
      Vec laplacian{0, 0, 0};
      for (std::uint32_t w : neighbours)
        for (int k = 0; k < 3; ++k) laplacian[k] += x[w][k];
      for (int k = 0; k < 3; ++k) laplacian[k] = laplacian[k] / double(neighbours.size()) - x[v][k];
      // Only the Laplacian's normal part moves the surface; its tangential part, projected on
      // the segment, would push the vertex off the surface. So the vertex goes where its
      // segment meets the plane through x + factor (L . n) n normal to n, unless the segment is
      // nearly tangent (then the orthogonal projection of the move on the segment).
      const Vec& n = normal[v];
      const double nn = dot(n, n), an = dot(axis[v], n);
      double step;
      if (an * an > kMinNormalCosine2 * nn * dot(axis[v], axis[v])) step = factor * dot(laplacian, n) / an;
      else step = factor * dot(laplacian, axis[v]) * inverseLength2[v];
      t[v] = std::clamp(t[v] + step, p.epsilon, 1 - p.epsilon);
    }
    // The fold check: every guarded cube is checked after the last change of its vertices; a
    // failing cube halves its vertices' moves (or undoes them after `halvings`) and requeues
    // the cubes of those vertices. A cube whose vertices are all back is as it was before the
    // pass, embedded, so this ends with every guarded cube embedded.
    std::fill(halved.begin(), halved.end(), 0);
    queue.clear();
    for (std::uint32_t c = 0; c < nc; ++c)
      if (guarded[c]) {
        queue.push_back(c);
        queued[c] = 1;
      }
    while (!queue.empty()) {
      const std::uint32_t c = queue.back();
      queue.pop_back();
      queued[c] = 0;
      if (embedded(c)) continue;
      bool moved = false;
      cubeVertices.clear();
      for (std::uint32_t f : facesOfCube[c])
        for (std::uint32_t v : triangle[f])
          if (std::find(cubeVertices.begin(), cubeVertices.end(), v) == cubeVertices.end()) cubeVertices.push_back(v);
      for (std::uint32_t v : cubeVertices) {
          if (t[v] == previous[v]) continue;
          moved = true;
          ++report.stepsBack;
          t[v] = ++halved[v] > p.halvings ? previous[v] : previous[v] + (t[v] - previous[v]) / 2;
          for (std::uint32_t c2 : cubesOfVertex[v])
            if (guarded[c2] && !queued[c2]) {
              queue.push_back(c2);
              queued[c2] = 1;
            }
        }
      if (!moved) throw std::logic_error("smoothOnSegments: a guarded cube is not embedded at its previous state");
    }
  };
  for (int i = 0; i < p.iterations; ++i) {
    pass(p.lambda);
    pass(p.mu);
  }

  for (std::size_t v = 0; v < nv; ++v) {
    Vec q;
    for (int k = 0; k < 3; ++k) q[k] = base[v][k] + t[v] * axis[v][k];
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (q[k] - start[v][k]) * (q[k] - start[v][k]);
    report.maxDisplacement = std::max(report.maxDisplacement, std::sqrt(d2));
    mesh.set_point(mesh.vertex_handle(unsigned(v)), SurfaceMesh::Point(q[0], q[1], q[2]));
  }
  return report;
}

}  // namespace surftrack::refine
