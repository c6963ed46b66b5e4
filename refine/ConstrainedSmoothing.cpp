#include "ConstrainedSmoothing.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "BoundaryMapping.h"
#include "Cancellation.h"
#include "CompressedLists.h"
#include "CubeFoldCheck.h"
#include "DigitalCube.h"
#include "FoldCertificate.h"
#include "HugePages.h"
#include "SurfaceMesh.h"
#include "TrianglesByCube.h"

namespace surftrack::refine {

namespace {

/// cos^2 of the largest angle between a segment and the vertex normal for which the move
/// follows the normal (cos = 0.3, about 72.5 degrees).
constexpr double kMinNormalCosine2 = 0.09;

/// How many vertices ahead a pass asks for its neighbours' points, on meshes of more than
/// kPrefetchPoints points (24 MiB of them, beyond the caches of the machines measured).
constexpr std::size_t kPrefetchDistance = 8, kPrefetchPoints = std::size_t(1) << 20;

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

/// Calls body(begin, end) over blocks of [0, n): on this thread for one thread or a small n,
/// else in parallel. The bodies here write only their own items, from data no block writes,
/// so the result does not depend on the blocks or the thread count.
template <class Body>
void forBlocks(std::size_t n, bool parallel, Body&& body) {
  if (!parallel) body(std::size_t(0), n);
  else
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
}

/// The smoothing of both entry points (ConstrainedSmoothing.h): kComplex false for a closed,
/// oriented 2-manifold (each vertex's one-ring in cyclic order), true for a complex of
/// triangles, any number of them on an edge (each vertex's distinct neighbours and its
/// triangles). Everything else, the segments, the cubes, the certificates and the fold check,
/// is the same code (docs/theory.md §12, "Smoothing the complex").
template <bool kComplex>
SmoothingReport smoothImpl(std::vector<Point3>& points, const std::vector<Surfel>& surfel,
                           const std::vector<std::array<std::uint32_t, 3>>& triangle, const ImageGeometry& geometry,
                           const SmoothingParameters& p) {
  requireParameters(p);
  if (p.threads < 0) throw std::invalid_argument("smoothing threads " + std::to_string(p.threads) + " is negative");
  const std::size_t nv = points.size(), nf = triangle.size();
  if (surfel.size() != nv)
    throw std::invalid_argument("smoothing: " + std::to_string(surfel.size()) + " surfels for " + std::to_string(nv) +
                                " vertices");
  // The one-rings below read each vertex's neighbours off its corners, which takes a closed,
  // oriented 2-manifold (section 8: every continuous analog is one). A complex has no rings.
  if constexpr (!kComplex) requireClosedOrientedManifold(nv, triangle);
  else
    for (std::size_t f = 0; f < nf; ++f)
      for (std::uint32_t v : triangle[f])
        if (v >= nv)
          throw std::invalid_argument("smoothing: triangle " + std::to_string(f) + " has vertex " + std::to_string(v) +
                                      " of " + std::to_string(nv));
  throwIfCancelled(p.cancel, "smoothing");
  SmoothingReport report;
  // Passes over the vertices in parallel (threads 0: all cores) but for a small mesh, where a
  // pass costs less than waking the threads.
  const bool parallel = p.threads != 1 && nv >= (std::size_t(1) << 12);
  // More threads than cores would only wait for each other (and make TBB warn that its workers
  // are limited): the arena gets the cores at most.
  tbb::task_arena arena(p.threads > 0 ? std::min(p.threads, tbb::info::default_concurrency())
                                      : tbb::task_arena::automatic);

  // Each vertex's segment in physical space, P(c) + t a with a = P(d) - P(c) (P = toPhysical
  // is affine): a is the image of the surfel's direction d - c, one of the six unit vectors,
  // so a vertex's segment is its surfel's 1-voxel and direction, and the passes read one byte
  // for its axis. The fold check works in index space, on c + t (d - c). x holds the points.
  // The arrays as large as the mesh are first written front to back: they are backed by huge
  // pages, whose first writes cost a fifth of 4 KiB pages' (lib/HugePages.h;
  // docs/performance.md, "Fresh memory on this machine").
  std::array<Point3, 6> physicalAxis;  // by Direction (lib/Voxel.h)
  std::array<double, 6> inverseLength2Of;
  for (Direction n = 0; n < 6; ++n) {
    const Voxel u = unitVector(n);
    physicalAxis[n] = geometry.toPhysicalOffset({double(u.x), double(u.y), double(u.z)});
    inverseLength2Of[n] = 1.0 / dot(physicalAxis[n], physicalAxis[n]);
  }
  auto physicalPoint = [&](std::size_t v, double tv) {
    const Voxel c = surfel[v].inside();
    const Point3 b = geometry.toPhysical({double(c.x), double(c.y), double(c.z)});
    const Point3& a = physicalAxis[surfel[v].n];
    return Point3{b[0] + tv * a[0], b[1] + tv * a[1], b[2] + tv * a[2]};
  };
  // The table has the six directions of Z^3 only (Surfel::fromKey decodes 6 and 7 too).
  if (const auto bad = std::find_if(surfel.begin(), surfel.end(), [](const Surfel& s) { return s.n >= 6; });
      bad != surfel.end())
    throw std::invalid_argument("smoothing: vertex " + std::to_string(bad - surfel.begin()) +
                                " has a surfel of direction " + std::to_string(int(bad->n)) + ", not one of 0 to 5");
  std::vector<Direction> direction = hugePageVector<Direction>(nv);
  std::vector<double> t = hugePageVector<double>(nv);
  std::vector<Point3> x = hugePageVector<Point3>(nv);
  std::vector<char> offSegment = hugePageVector<char>(nv);
  arena.execute([&] {
    forBlocks(nv, parallel, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        direction[v] = surfel[v].n;
        const Point3 base = physicalPoint(v, 0);
        const Point3& a = physicalAxis[direction[v]];
        const Point3 r = sub(points[v], base);
        const double tv = dot(r, a) * inverseLength2Of[direction[v]];
        double off = 0;
        for (int k = 0; k < 3; ++k) off = std::max(off, std::abs(r[k] - tv * a[k]));
        offSegment[v] = !(tv > 0 && tv < 1) || off > 1e-6 * norm(a);
        t[v] = std::clamp(tv, p.epsilon, 1 - p.epsilon);
        x[v] = {base[0] + t[v] * a[0], base[1] + t[v] * a[1], base[2] + t[v] * a[2]};
      }
    });
  });
  if (const auto bad = std::find(offSegment.begin(), offSegment.end(), 1); bad != offSegment.end()) {
    const std::size_t v = std::size_t(bad - offSegment.begin());
    std::ostringstream msg;
    msg << "vertex " << v << " is not inside the segment of its " << surfel[v];
    throw std::invalid_argument(msg.str());
  }
  auto indexPoint = [&](std::uint32_t v) {
    const Voxel c = surfel[v].inside(), d = surfel[v].outside();
    return Point3{c.x + t[v] * (d.x - c.x), c.y + t[v] * (d.y - c.y), c.z + t[v] * (d.z - c.z)};
  };

  // Triangles by digital 3-cube (section 8: each has one), with the cube edges of their
  // vertices. The cubes are numbered in the order of their first triangles.
  std::vector<Voxel> cubeOf = hugePageVector<Voxel>(nf);
  std::vector<CubeEdges> edgesOfFace = hugePageVector<CubeEdges>(nf);
  std::vector<char> inNoCube = hugePageVector<char>(nf);
  arena.execute([&] {
    forBlocks(nf, parallel, [&](std::size_t begin, std::size_t end) {
      for (std::size_t f = begin; f < end; ++f) {
        const auto& tr = triangle[f];
        const std::optional<Voxel> m = cubeOfTriangle(surfel[tr[0]], surfel[tr[1]], surfel[tr[2]]);
        if (!m) {
          inNoCube[f] = 1;
          continue;
        }
        cubeOf[f] = *m;
        for (int j = 0; j < 3; ++j) edgesOfFace[f][j] = std::uint8_t(cube::edgeOf(*m, surfel[tr[j]]));
      }
    });
  });
  if (const auto bad = std::find(inNoCube.begin(), inNoCube.end(), 1); bad != inNoCube.end()) {
    std::ostringstream msg;
    msg << "triangle " << (bad - inNoCube.begin()) << " has its vertices in no single digital 3-cube: constrained "
        << "smoothing needs the continuous analog itself (smooth before decimating)";
    throw std::invalid_argument(msg.str());
  }
  const Lists facesOfCube = groupTrianglesByCube(cubeOf);
  const std::size_t nc = facesOfCube.size();
  report.cubes = nc;
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
  // A triangle of a cube at the current positions, in index space, with its reference normal
  // (its normal at the midpoint mapping).
  auto cubeTriangle = [&](std::uint32_t f) {
    CubeTriangle ct;
    ct.vertex = triangle[f];
    for (int k = 0; k < 3; ++k) ct.point[k] = indexPoint(ct.vertex[k]);
    ct.reference = triangleNormal({pointOnSurfel(surfel[ct.vertex[0]], 0.5), pointOnSurfel(surfel[ct.vertex[1]], 0.5),
                                   pointOnSurfel(surfel[ct.vertex[2]], 0.5)});
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
  std::vector<std::uint32_t> checkedVertices;  // the vertices of the checked cubes
  for (std::uint32_t v = 0; v < nv; ++v)
    if (!checkedOfVertex[v].empty()) checkedVertices.push_back(v);
  // Each vertex's one-ring in cyclic order r_0 .. r_{k-1}, its triangles being (v, r_i,
  // r_{i+1}) (indices mod k): in a closed, oriented manifold whose every vertex has a single fan
  // (requireClosedOrientedManifold) the triangle (v, b, c) is followed around v by the one of
  // the directed edge v -> c, (v, c, d). The ring gives both the uniform Laplacian and the
  // area-weighted normal, with one read of each neighbour. Each ring starts at the next vertex
  // of v's first triangle.
  std::vector<std::uint32_t> ringStart = hugePageVector<std::uint32_t>(nv + 1);
  for (const auto& tr : triangle)
    for (std::uint32_t v : tr) ++ringStart[v + 1];
  for (std::size_t v = 0; v < nv; ++v) ringStart[v + 1] += ringStart[v];
  // A complex (kComplex) instead: each vertex's distinct neighbours (the umbrella Laplacian of
  // its vertex graph) and each of its triangles as the pair (b, c) of its other vertices in
  // orientation order (the area-weighted normal), at ringStart[v] .. ringStart[v + 1].
  Lists neighbours;
  std::vector<std::array<std::uint32_t, 2>> star;
  if constexpr (kComplex) {
    star.resize(3 * nf);
    std::vector<std::uint32_t> next(ringStart.begin(), ringStart.end() - 1);
    for (const auto& tr : triangle)
      for (int j = 0; j < 3; ++j) star[next[tr[j]]++] = {tr[(j + 1) % 3], tr[(j + 2) % 3]};
    neighbours.start.assign(nv + 1, 0);
    std::vector<std::uint32_t> around;
    for (std::size_t v = 0; v < nv; ++v) {
      around.clear();
      for (std::uint32_t k = ringStart[v]; k < ringStart[v + 1]; ++k) around.insert(around.end(), star[k].begin(), star[k].end());
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      neighbours.items.insert(neighbours.items.end(), around.begin(), around.end());
      neighbours.start[v + 1] = std::uint32_t(neighbours.items.size());
    }
  }
  // Each ring is stored closed, r_0 .. r_{k-1} r_0, at ringStart[v] + v, so that the walk over
  // its triangles has no wrap-around test.
  std::vector<std::uint32_t> ring;
  if constexpr (!kComplex) {
    ring = hugePageVector<std::uint32_t>(3 * nf + nv);
    // First each corner's (next, previous) pair, in triangle order, then the chains.
    auto corner = hugePageVector<std::array<std::uint32_t, 2>>(3 * nf);
    std::vector<std::uint32_t> next(ringStart.begin(), ringStart.end() - 1);
    for (const auto& tr : triangle)
      for (int j = 0; j < 3; ++j) corner[next[tr[j]]++] = {tr[(j + 1) % 3], tr[(j + 2) % 3]};
    arena.execute([&] {
      forBlocks(nv, parallel, [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v) {
          const std::uint32_t first = ringStart[v], last = ringStart[v + 1];
          std::uint32_t b = corner[first][0], c = corner[first][1];
          for (std::uint32_t k = first; k < last; ++k) {
            ring[k + v] = b;
            // The corner whose next vertex is c comes next (a single fan: exactly one).
            std::uint32_t m = first;
            while (m < last && corner[m][0] != c) ++m;
            if (m == last) throw std::logic_error("smoothOnSegments: a vertex's triangles are not one fan");
            b = c;
            c = corner[m][1];
          }
          ring[last + v] = ring[first + v];
        }
      });
    });
  }

  // The passes are Jacobi updates: every vertex reads the points x of the pass's start and
  // writes its own t, next point and (in a λ pass) step alone, so a pass's result does not
  // depend on the order of the vertices or on the thread count. A vertex moves along its axis
  // by the change of its t; the final points are computed from t. The fold check keeps the t of
  // the pass's start of the vertices it may put back (`previous`, of the checked cubes'
  // vertices alone).
  std::vector<double> previous = hugePageVector<double>(nv);
  std::vector<Point3> xNext = hugePageVector<Point3>(nv);
  std::vector<int> halved = hugePageVector<int>(nv);
  std::vector<char> queued(checked.size(), 0);
  std::vector<std::uint32_t> queue;
  // Each vertex's step per unit of Laplacian, t += factor (L . w): w = n / (a . n) to move to
  // where the segment meets the plane through x + factor (L . n) n normal to n, or w = a / |a|^2
  // (the orthogonal projection of the move on the segment) where the segment is nearly tangent.
  // Only the Laplacian's normal part moves the surface; its tangential part, projected on the
  // segment, would push the vertex off the surface. The normals are those of the iteration's
  // start, shared by its two passes (section 8). stepOf holds w / degree, to apply to the sum of
  // the neighbours' offsets.
  std::vector<Point3> stepOf = hugePageVector<Point3>(nv);
  const bool prefetch = !kComplex && nv > kPrefetchPoints;
  // A complex's vertex: the same step as a ring's below, with the Laplacian over its distinct
  // neighbours and the normal summed over its triangles (b, c) as (b - v) x (c - v). Each wall
  // triangle is once in the complex, oriented from its higher priority to its lower
  // (converter/NestedWalls.h), so the normals of the nested walls through a vertex add up; the
  // step n / (a . n) does not depend on the normal's sign.
  auto complexStep = [&](std::size_t v, const Point3& xv, const Point3& axis, double factor, bool newNormals) {
    const Point3* const xs = x.data();
    const std::uint32_t first = neighbours.start[v], last = neighbours.start[v + 1];
    if (first == last) {  // a vertex of no triangle stays put
      xNext[v] = xv;
      return;
    }
    Point3 sum{0, 0, 0};
    for (std::uint32_t k = first; k < last; ++k) {
      const Point3& r = xs[neighbours.items[k]];
      for (int i = 0; i < 3; ++i) sum[i] += r[i] - xv[i];
    }
    if (newNormals) {
      Point3 n{0, 0, 0};
      for (std::uint32_t k = ringStart[v]; k < ringStart[v + 1]; ++k) {
        const Point3 tn = cross(sub(xs[star[k][0]], xv), sub(xs[star[k][1]], xv));
        for (int i = 0; i < 3; ++i) n[i] += tn[i];
      }
      const double nn = dot(n, n), an = dot(axis, n), inverseDegree = 1.0 / double(last - first);
      if (an * an > kMinNormalCosine2 * nn * dot(axis, axis))
        for (int i = 0; i < 3; ++i) stepOf[v][i] = n[i] * (inverseDegree / an);
      else
        for (int i = 0; i < 3; ++i) stepOf[v][i] = axis[i] * (inverseLength2Of[direction[v]] * inverseDegree);
    }
    const double before = t[v];
    t[v] = std::clamp(before + factor * dot(sum, stepOf[v]), p.epsilon, 1 - p.epsilon);
    const double dt = t[v] - before;
    xNext[v] = {xv[0] + dt * axis[0], xv[1] + dt * axis[1], xv[2] + dt * axis[2]};
  };
  auto move = [&](double factor, bool newNormals, std::size_t begin, std::size_t end) {
    const Point3* const xs = x.data();
    const std::uint32_t* const rs = ring.data();
    for (std::size_t v = begin; v < end; ++v) {
      // The neighbours' points are the only reads out of order: on a mesh whose points do not
      // fit the cache, those of the vertex kPrefetchDistance ahead are requested now, so that
      // the pass waits for memory less (docs/performance.md, "Current figures": the MRI
      // cortex's smoothing 2.05 -> 1.72 s; on a mesh that fits, the extra walk cost more than
      // it saved).
      if (const std::size_t w = v + kPrefetchDistance; prefetch && w < end)
        for (std::size_t k = ringStart[w] + w, e = ringStart[w + 1] + w; k < e; ++k) __builtin_prefetch(&xs[rs[k]]);
      const Point3 xv = xs[v];
      const Point3& axis = physicalAxis[direction[v]];
      if constexpr (kComplex) {
        complexStep(v, xv, axis, factor, newNormals);
        continue;
      }
      const std::size_t first = ringStart[v] + v, last = ringStart[v + 1] + v;
      // The umbrella Laplacian, the mean of the neighbours minus x (summed as offsets from x),
      // and with new normals the area-weighted normal, the sum over the triangles
      // (v, r_i, r_{i+1}) of (r_i - v) x (r_{i+1} - v).
      Point3 sum{0, 0, 0};
      if (newNormals) {
        Point3 n{0, 0, 0};
        Point3 a = sub(xs[rs[first]], xv);
        for (std::size_t k = first + 1; k <= last; ++k) {
          const Point3 b = sub(xs[rs[k]], xv);
          const Point3 tn = cross(a, b);
          for (int i = 0; i < 3; ++i) {
            sum[i] += a[i];
            n[i] += tn[i];
          }
          a = b;
        }
        const double nn = dot(n, n), an = dot(axis, n), inverseDegree = 1.0 / double(last - first);
        if (an * an > kMinNormalCosine2 * nn * dot(axis, axis))
          for (int i = 0; i < 3; ++i) stepOf[v][i] = n[i] * (inverseDegree / an);
        else
          for (int i = 0; i < 3; ++i) stepOf[v][i] = axis[i] * (inverseLength2Of[direction[v]] * inverseDegree);
      } else {
        for (std::size_t k = first; k < last; ++k) {
          const Point3& r = xs[rs[k]];
          for (int i = 0; i < 3; ++i) sum[i] += r[i] - xv[i];
        }
      }
      const double before = t[v];
      t[v] = std::clamp(before + factor * dot(sum, stepOf[v]), p.epsilon, 1 - p.epsilon);
      const double dt = t[v] - before;
      xNext[v] = {xv[0] + dt * axis[0], xv[1] + dt * axis[1], xv[2] + dt * axis[2]};
    }
  };
  auto pass = [&](double factor, bool newNormals) {
    // A pass costs about a tenth of a second per million vertices: checked before each one, a
    // raised flag stops the smoothing at once, whatever the iteration count.
    throwIfCancelled(p.cancel, "smoothing");
    for (std::uint32_t v : checkedVertices) previous[v] = t[v];
    arena.execute(
        [&] { forBlocks(nv, parallel, [&](std::size_t b, std::size_t e) { move(factor, newNormals, b, e); }); });
    // The fold check: every checked cube is tested after the last change of its vertices; a
    // failing cube halves its vertices' moves (or undoes them after `halvings`) and requeues
    // the cubes of those vertices. A cube whose vertices are all back is as it was before the
    // pass, embedded, so this ends with every guarded cube embedded. A cube none of whose
    // vertices moved is as it was.
    queue.clear();
    for (std::uint32_t i = 0; i < checked.size(); ++i)
      for (std::uint32_t v : verticesOfChecked[i])
        if (t[v] != previous[v]) {
          queue.push_back(i);
          queued[i] = 1;
          break;
        }
    if (!queue.empty())
      for (std::uint32_t v : checkedVertices) halved[v] = 0;
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
        const double dt = t[v] - previous[v];
        const Point3& axis = physicalAxis[direction[v]];
        xNext[v] = {x[v][0] + dt * axis[0], x[v][1] + dt * axis[1], x[v][2] + dt * axis[2]};
        for (std::uint32_t j : checkedOfVertex[v])
          if (!queued[j]) {
            queue.push_back(j);
            queued[j] = 1;
          }
      }
      if (!moved) throw std::logic_error("smoothOnSegments: a guarded cube is not embedded at its previous state");
    }
    x.swap(xNext);
  };
  for (int i = 0; i < p.iterations; ++i) {
    pass(p.lambda, true);
    pass(p.mu, false);
  }

  for (std::size_t v = 0; v < nv; ++v) {
    const Point3 q = physicalPoint(v, t[v]);
    report.maxDisplacement = std::max(report.maxDisplacement, norm(sub(q, points[v])));
    points[v] = q;
  }
  return report;
}

}  // namespace

SmoothingReport smoothOnSegments(std::vector<Point3>& points, const std::vector<Surfel>& surfels,
                                 const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                 const ImageGeometry& geometry, const SmoothingParameters& parameters) {
  return smoothImpl<false>(points, surfels, triangles, geometry, parameters);
}

SmoothingReport smoothComplexOnSegments(std::vector<Point3>& points, const std::vector<Surfel>& surfels,
                                        const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                        const ImageGeometry& geometry, const SmoothingParameters& parameters) {
  return smoothImpl<true>(points, surfels, triangles, geometry, parameters);
}

}  // namespace surftrack::refine
