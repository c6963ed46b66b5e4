// Per-component figures and vertex normals of a Surface: plain sums over its triangles.
#include <algorithm>
#include <cmath>
#include <numeric>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "Extract.h"
#include "MeshComponents.h"
#include "PlaceSurface.h"
#include "VertexNormals.h"

namespace surftrack {
namespace {

using Point = std::array<double, 3>;
using refine::cross;
using refine::dot;

}  // namespace

namespace {

// Twice the area: |(b - a) x (c - a)|. Divergence theorem: the signed volume of the tetrahedron
// (0, a, b, c), summed.
double squaredNormal(const std::vector<Point>& vertices, const std::array<std::uint32_t, 3>& t) {
  const Point n = refine::triangleNormal({vertices[t[0]], vertices[t[1]], vertices[t[2]]});
  return dot(n, n);
}

double tetrahedron(const std::vector<Point>& vertices, const std::array<std::uint32_t, 3>& t) {
  return dot(vertices[t[0]], cross(vertices[t[1]], vertices[t[2]])) / 6.0;
}

void addTriangle(const std::vector<Point>& vertices, const std::array<std::uint32_t, 3>& t, double& area,
                 double& volume) {
  area += 0.5 * std::sqrt(squaredNormal(vertices, t));
  volume += tetrahedron(vertices, t);
}

/// The counts that follow from the others on a closed surface: every edge borders two triangles.
void completeCounts(ComponentFigures& f) {
  f.edges = 3 * f.triangles / 2;
  f.euler = (long long)f.surfels - (long long)f.edges + (long long)f.triangles;
}

}  // namespace

ComponentFigures connectedMeshFigures(const std::vector<Point>& vertices,
                                      const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  ComponentFigures f;
  f.surfels = vertices.size();
  f.triangles = triangles.size();
  double area = 0, volume = 0;  // the sums in registers, in triangle order
  std::size_t i = 0;
#if defined(__SSE2__)
  for (; i + 2 <= triangles.size(); i += 2) {  // two square roots at once (correctly rounded both)
    double root[2];
    _mm_storeu_pd(root, _mm_sqrt_pd(_mm_set_pd(squaredNormal(vertices, triangles[i + 1]),
                                               squaredNormal(vertices, triangles[i]))));
    area += 0.5 * root[0];
    volume += tetrahedron(vertices, triangles[i]);
    area += 0.5 * root[1];
    volume += tetrahedron(vertices, triangles[i + 1]);
  }
#endif
  for (; i < triangles.size(); ++i) addTriangle(vertices, triangles[i], area, volume);
  f.area = area;
  f.volume = volume;
  completeCounts(f);
  return f;
}

std::vector<ComponentFigures> componentFigures(const std::vector<Point>& vertices,
                                               const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                               std::vector<std::uint32_t>* componentOf) {
  std::size_t count = 0;
  std::vector<std::uint32_t> label = triangleComponents(vertices.size(), triangles, count);
  if (count == 1) {  // one boundary, the most frequent case
    if (componentOf) *componentOf = std::move(label);
    return {connectedMeshFigures(vertices, triangles)};
  }
  std::vector<ComponentFigures> figures(count);
  for (std::uint32_t c : label) ++figures[c].surfels;
  for (const auto& t : triangles) {
    ComponentFigures& f = figures[label[t[0]]];
    ++f.triangles;
    addTriangle(vertices, t, f.area, f.volume);
  }
  for (ComponentFigures& f : figures) completeCounts(f);
  // By decreasing size; the labels follow.
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return figures[a].surfels > figures[b].surfels; });
  std::vector<ComponentFigures> sorted(count);
  std::vector<std::uint32_t> rankOf(count);
  for (std::size_t i = 0; i < count; ++i) {
    sorted[i] = figures[order[i]];
    rankOf[order[i]] = std::uint32_t(i);
  }
  if (componentOf) {
    for (std::uint32_t& c : label) c = rankOf[c];
    *componentOf = std::move(label);
  }
  return sorted;
}

std::vector<Point> vertexNormals(const Surface& surface) {
  std::vector<Point> normals;
  refine::sumTriangleNormals(surface.vertices, surface.triangles, normals);  // area-weighted
  for (Point& n : normals) {
    const double length = std::sqrt(dot(n, n));
    if (length > 0)
      for (double& x : n) x /= length;
  }
  return normals;
}

}  // namespace surftrack
