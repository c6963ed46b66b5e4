#include "ConstrainedSmoothing.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "BoundaryMapping.h"
#include "CubeFoldCheck.h"
#include "DigitalCube.h"
#include "FoldCertificate.h"
#include "VertexNormals.h"

namespace surftrack::refine {

namespace {

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

  // Each vertex's segment in physical space, P(c) + t (P(d) - P(c)) (toPhysical is affine),
  // and in index space, c + t (d - c), where the fold check works.
  std::vector<Surfel> surfel(nv);
  std::vector<Point3> base(nv), axis(nv), start(nv), indexBase(nv), indexAxis(nv);
  std::vector<double> inverseLength2(nv), t(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    const auto vh = mesh.vertex_handle(unsigned(v));
    const Surfel s = mesh.property(surfelHandle, vh);
    surfel[v] = s;
    const Voxel c = s.inside(), d = s.outside();
    indexBase[v] = {double(c.x), double(c.y), double(c.z)};
    indexAxis[v] = {double(d.x - c.x), double(d.y - c.y), double(d.z - c.z)};
    base[v] = geometry.toPhysical(indexBase[v]);
    axis[v] = sub(geometry.toPhysical({double(d.x), double(d.y), double(d.z)}), base[v]);
    inverseLength2[v] = 1.0 / dot(axis[v], axis[v]);
    const auto& q = mesh.point(vh);
    start[v] = {q[0], q[1], q[2]};
    const Point3 r = sub(start[v], base[v]);
    const double tv = dot(r, axis[v]) * inverseLength2[v];
    double off = 0;
    for (int k = 0; k < 3; ++k) off = std::max(off, std::abs(r[k] - tv * axis[v][k]));
    if (!(tv > 0 && tv < 1) || off > 1e-6 * norm(axis[v])) {
      std::ostringstream msg;
      msg << "vertex " << v << " is not inside the segment of its " << s;
      throw std::invalid_argument(msg.str());
    }
    t[v] = std::clamp(tv, p.epsilon, 1 - p.epsilon);
  }
  auto indexPoint = [&](std::uint32_t v) {
    return Point3{indexBase[v][0] + t[v] * indexAxis[v][0], indexBase[v][1] + t[v] * indexAxis[v][1],
                  indexBase[v][2] + t[v] * indexAxis[v][2]};
  };

  // Triangles by digital 3-cube (section 8: each has one), with the cube edges of their
  // vertices and their reference normals (in index space at the midpoint mapping).
  std::vector<std::array<std::uint32_t, 3>> triangle(nf);
  std::vector<std::uint32_t> cubeOfFace(nf);
  std::vector<CubeEdges> edgesOfFace(nf);
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
    for (int j = 0; j < 3; ++j) edgesOfFace[f][j] = std::uint8_t(cube::edgeOf(*m, surfel[tr[j]]));
    reference[f] = triangleNormal({pointOnSurfel(surfel[tr[0]], 0.5), pointOnSurfel(surfel[tr[1]], 0.5),
                                   pointOnSurfel(surfel[tr[2]], 0.5)});
  }
  const std::size_t nc = cubeIndex.size();
  report.cubes = nc;
  const Lists facesOfCube = invert(cubeOfFace, nc);

  // What the fold check of each cube must test in a pass: its triangles and pairs of triangles
  // without a certificate (FoldCertificate.h), single triangles first (the pair test needs
  // non-degenerate triangles). A cube with none is embedded at every position.
  FoldCertificates certificates(p.epsilon);
  struct Item {
    std::uint32_t f, g;  // f == g: one triangle
  };
  std::vector<Item> items;
  std::vector<std::uint32_t> itemStart(nc + 1, 0);
  for (std::uint32_t c = 0; c < nc; ++c) {
    const auto faces = facesOfCube[c];
    for (std::uint32_t f : faces)
      if (!certificates.triangleIsCertain(edgesOfFace[f])) items.push_back({f, f});
    for (std::size_t i = 0; i < faces.size(); ++i)
      for (std::size_t j = i + 1; j < faces.size(); ++j)
        if (!certificates.pairIsCertain(edgesOfFace[faces[i]], edgesOfFace[faces[j]]))
          items.push_back({faces[i], faces[j]});
    itemStart[c + 1] = std::uint32_t(items.size());
  }
  auto cubeTriangle = [&](std::uint32_t f) {
    CubeTriangle ct;
    ct.vertex = triangle[f];
    for (int k = 0; k < 3; ++k) ct.point[k] = indexPoint(ct.vertex[k]);
    ct.reference = reference[f];
    return ct;
  };
  auto embedded = [&](std::uint32_t c) {
    for (std::uint32_t i = itemStart[c]; i < itemStart[c + 1]; ++i) {
      const Item it = items[i];
      if (it.f == it.g ? !triangleKeepsItsSide(cubeTriangle(it.f))
                       : !trianglesAreEmbedded(cubeTriangle(it.f), cubeTriangle(it.g)))
        return false;
    }
    return true;
  };
  // The cubes the check guards are those embedded in the input (section 8); of those, only
  // the ones with something to test are checked in a pass.
  std::vector<std::uint32_t> checked, cubeOfChecked;  // checked cubes; vertex -> its checked cubes
  for (std::uint32_t c = 0; c < nc; ++c) {
    if (itemStart[c] == itemStart[c + 1]) continue;
    if (!embedded(c)) ++report.unguardedCubes;
    else checked.push_back(c);
  }
  report.checkedCubes = checked.size();
  Lists verticesOfChecked;  // deduplicated
  std::vector<std::uint32_t> vertexOfCorner;
  verticesOfChecked.start.assign(checked.size() + 1, 0);
  for (std::size_t i = 0; i < checked.size(); ++i) {
    const std::size_t first = verticesOfChecked.items.size();
    for (std::uint32_t f : facesOfCube[checked[i]])
      for (std::uint32_t v : triangle[f])
        if (std::find(verticesOfChecked.items.begin() + std::ptrdiff_t(first), verticesOfChecked.items.end(), v) ==
            verticesOfChecked.items.end()) {
          verticesOfChecked.items.push_back(v);
          vertexOfCorner.push_back(v);
          cubeOfChecked.push_back(std::uint32_t(i));
        }
    verticesOfChecked.start[i + 1] = std::uint32_t(verticesOfChecked.items.size());
  }
  const Lists checkedOfVertex = [&] {
    Lists l = invert(vertexOfCorner, nv);
    for (std::uint32_t& k : l.items) k = cubeOfChecked[k];
    return l;
  }();
  // One-ring neighbours (uniform Laplacian).
  Lists ring;
  ring.start.assign(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    for (auto w : mesh.vv_range(mesh.vertex_handle(unsigned(v)))) ring.items.push_back(std::uint32_t(w.idx()));
    ring.start[v + 1] = std::uint32_t(ring.items.size());
  }

  std::vector<double> previous(nv);
  std::vector<Point3> x(nv), normal;
  std::vector<int> halved(nv);
  std::vector<char> queued(checked.size(), 0);
  std::vector<std::uint32_t> queue;
  auto pass = [&](double factor) {
    for (std::size_t v = 0; v < nv; ++v)
      for (int k = 0; k < 3; ++k) x[v][k] = base[v][k] + t[v] * axis[v][k];
    previous = t;
    sumTriangleNormals(x, triangle, normal);  // area-weighted vertex normals
    for (std::size_t v = 0; v < nv; ++v) {
      const auto neighbours = ring[v];
      if (neighbours.empty()) continue;
      Point3 laplacian{0, 0, 0};
      for (std::uint32_t w : neighbours)
        for (int k = 0; k < 3; ++k) laplacian[k] += x[w][k];
      for (int k = 0; k < 3; ++k) laplacian[k] = laplacian[k] / double(neighbours.size()) - x[v][k];
      // Only the Laplacian's normal part moves the surface; its tangential part, projected on
      // the segment, would push the vertex off the surface. So the vertex goes where its
      // segment meets the plane through x + factor (L . n) n normal to n, unless the segment is
      // nearly tangent (then the orthogonal projection of the move on the segment).
      const Point3& n = normal[v];
      const double nn = dot(n, n), an = dot(axis[v], n);
      double step;
      if (an * an > kMinNormalCosine2 * nn * dot(axis[v], axis[v])) step = factor * dot(laplacian, n) / an;
      else step = factor * dot(laplacian, axis[v]) * inverseLength2[v];
      t[v] = std::clamp(t[v] + step, p.epsilon, 1 - p.epsilon);
    }
    // The fold check: every checked cube is tested after the last change of its vertices; a
    // failing cube halves its vertices' moves (or undoes them after `halvings`) and requeues
    // the cubes of those vertices. A cube whose vertices are all back is as it was before the
    // pass, embedded, so this ends with every guarded cube embedded. A cube none of whose
    // vertices moved is as it was.
    std::fill(halved.begin(), halved.end(), 0);
    queue.clear();
    for (std::uint32_t i = 0; i < checked.size(); ++i)
      for (std::uint32_t v : verticesOfChecked[i])
        if (t[v] != previous[v]) {
          queue.push_back(i);
          queued[i] = 1;
          break;
        }
    while (!queue.empty()) {
      const std::uint32_t i = queue.back();
      queue.pop_back();
      queued[i] = 0;
      if (embedded(checked[i])) continue;
      bool moved = false;
      for (std::uint32_t v : verticesOfChecked[i]) {
        if (t[v] == previous[v]) continue;
        moved = true;
        ++report.stepsBack;
        t[v] = ++halved[v] > p.halvings ? previous[v] : previous[v] + (t[v] - previous[v]) / 2;
        for (std::uint32_t j : checkedOfVertex[v])
          if (!queued[j]) {
            queue.push_back(j);
            queued[j] = 1;
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
    const Point3 q{base[v][0] + t[v] * axis[v][0], base[v][1] + t[v] * axis[v][1], base[v][2] + t[v] * axis[v][2]};
    report.maxDisplacement = std::max(report.maxDisplacement, norm(sub(q, start[v])));
    mesh.set_point(mesh.vertex_handle(unsigned(v)), SurfaceMesh::Point(q[0], q[1], q[2]));
  }
  return report;
}

}  // namespace surftrack::refine
