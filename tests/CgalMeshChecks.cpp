// CgalMeshChecks.h with CGAL (libcgal-dev, header-only; tests and tools only).
#include "CgalMeshChecks.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <iterator>
#include <utility>

namespace surftrack::checks {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;

Kernel::Point_3 cgalPoint(const Point& p) { return Kernel::Point_3(p[0], p[1], p[2]); }

CgalMesh cgalMesh(const Points& points, const Triangles& triangles) {
  CgalMesh m;
  std::vector<CgalMesh::Vertex_index> v;
  v.reserve(points.size());
  for (const auto& p : points) v.push_back(m.add_vertex(cgalPoint(p)));
  for (const auto& t : triangles) m.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return m;
}

std::vector<Kernel::Point_3> samplePoints(const Points& points, const Triangles& triangles) {
  std::vector<Kernel::Point_3> out;
  auto mix = [&](const std::array<std::uint32_t, 3>& t, double a, double b, double c) {
    const auto &p = points[t[0]], &q = points[t[1]], &r = points[t[2]];
    out.emplace_back(a * p[0] + b * q[0] + c * r[0], a * p[1] + b * q[1] + c * r[1], a * p[2] + b * q[2] + c * r[2]);
  };
  for (const auto& t : triangles) {
    mix(t, 1, 0, 0);
    mix(t, 0.5, 0.5, 0);
    mix(t, 0, 0.5, 0.5);
    mix(t, 0.5, 0, 0.5);
    mix(t, 1.0 / 3, 1.0 / 3, 1.0 / 3);
    mix(t, 4.0 / 6, 1.0 / 6, 1.0 / 6);
    mix(t, 1.0 / 6, 4.0 / 6, 1.0 / 6);
    mix(t, 1.0 / 6, 1.0 / 6, 4.0 / 6);
  }
  return out;
}

}  // namespace

std::size_t selfIntersections(const Points& points, const Triangles& triangles) {
  const CgalMesh m = cgalMesh(points, triangles);
  std::vector<std::pair<CgalMesh::Face_index, CgalMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(m, std::back_inserter(pairs));
  return pairs.size();
}

std::size_t soupIntersections(const Points& points, const Triangles& triangles) {
  using P = Kernel::Point_3;
  std::vector<CGAL::Bbox_3> boxes;
  for (const auto& t : triangles)
    boxes.push_back(cgalPoint(points[t[0]]).bbox() + cgalPoint(points[t[1]]).bbox() + cgalPoint(points[t[2]]).bbox());
  std::size_t count = 0;
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (std::size_t j = i + 1; j < triangles.size(); ++j) {
      if (!CGAL::do_overlap(boxes[i], boxes[j])) continue;
      const auto &a = triangles[i], &b = triangles[j];
      std::vector<std::uint32_t> shared;
      for (std::uint32_t v : a)
        if (std::find(b.begin(), b.end(), v) != b.end()) shared.push_back(v);
      auto other = [&](const std::array<std::uint32_t, 3>& t) {
        std::vector<P> out;
        for (std::uint32_t v : t)
          if (std::find(shared.begin(), shared.end(), v) == shared.end()) out.push_back(cgalPoint(points[v]));
        return out;
      };
      const Kernel::Triangle_3 ta(cgalPoint(points[a[0]]), cgalPoint(points[a[1]]), cgalPoint(points[a[2]]));
      const Kernel::Triangle_3 tb(cgalPoint(points[b[0]]), cgalPoint(points[b[1]]), cgalPoint(points[b[2]]));
      bool meet = false;
      if (shared.size() == 3) {
        meet = true;
      } else if (shared.size() == 2) {
        const P p = cgalPoint(points[shared[0]]), q = cgalPoint(points[shared[1]]);
        const P r = other(a)[0], s = other(b)[0];
        meet = CGAL::coplanar(p, q, r, s) && CGAL::coplanar_orientation(p, q, r, s) == CGAL::POSITIVE;
      } else if (shared.size() == 1) {
        const auto oa = other(a), ob = other(b);
        meet = CGAL::do_intersect(Kernel::Segment_3(oa[0], oa[1]), tb) ||
               CGAL::do_intersect(Kernel::Segment_3(ob[0], ob[1]), ta);
      } else {
        meet = CGAL::do_intersect(ta, tb);
      }
      count += meet;
    }
  return count;
}

double sampledDistance(const Points& pa, const Triangles& ta, const Points& pb, const Triangles& tb) {
  const CgalMesh b = cgalMesh(pb, tb);
  return CGAL::Polygon_mesh_processing::max_distance_to_triangle_mesh<CGAL::Sequential_tag>(samplePoints(pa, ta), b);
}

struct SideOfMesh::Impl {
  CgalMesh mesh;
  CGAL::Side_of_triangle_mesh<CgalMesh, Kernel> side;
  explicit Impl(CgalMesh m) : mesh(std::move(m)), side(mesh) {}
};

SideOfMesh::SideOfMesh(const Points& points, const Triangles& triangles)
    : impl_(std::make_unique<Impl>(cgalMesh(points, triangles))) {}

SideOfMesh::~SideOfMesh() = default;

Side SideOfMesh::operator()(const Point& p) const {
  switch (impl_->side(cgalPoint(p))) {
    case CGAL::ON_BOUNDED_SIDE: return Side::Inside;
    case CGAL::ON_UNBOUNDED_SIDE: return Side::Outside;
    default: return Side::Boundary;
  }
}

int orientation(const Point& p, const Point& q, const Point& r, const Point& s) {
  return int(CGAL::orientation(cgalPoint(p), cgalPoint(q), cgalPoint(r), cgalPoint(s)));
}

}  // namespace surftrack::checks
