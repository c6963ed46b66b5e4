// toSurfaceMesh, the direct half-edge construction (converter/SurfaceMesh.h), against
// toSurfaceMeshByAddFace, which builds the same mesh face by face with OpenMesh's add_face and
// its own topology checks: on every image the converter's tests use (every configuration of
// small blocks, the seeded random images of tests/test_loop_extraction.cpp, all four adjacency
// pairs), both give the same mesh; and triangles that are not a closed oriented manifold are
// rejected.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "BoundaryMapping.h"
#include "CaseSubset.h"
#include "LoopExtraction.h"
#include "PairTestName.h"
#include "ScanBoundaries.h"
#include "SurfaceMesh.h"
#include "TrackComponent.h"
#include "VoxelComponents.h"

using namespace surftrack;
namespace ref = surftrack::testing;
using Point = std::array<double, 3>;
using Triangle = std::array<std::uint32_t, 3>;

namespace {

using HH = SurfaceMesh::HalfedgeHandle;

std::pair<int, int> ends(const SurfaceMesh& m, HH h) {
  return {m.from_vertex_handle(h).idx(), m.to_vertex_handle(h).idx()};
}

/// The face's vertices, rotated so that the smallest comes first (orientation kept).
std::vector<int> faceVertices(const SurfaceMesh& m, SurfaceMesh::FaceHandle f) {
  std::vector<int> v;
  for (auto vh : m.fv_range(f)) v.push_back(vh.idx());
  std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
  return v;
}

/// A closed, consistent half-edge structure with no boundary, whose faces are `mesh`'s.
::testing::AssertionResult isClosedHalfedgeMesh(const SurfaceMesh& m, const TriangleMesh& mesh) {
  if (m.n_vertices() != mesh.surfels.size() || m.n_faces() != mesh.triangles.size())
    return ::testing::AssertionFailure() << "sizes " << m.n_vertices() << "/" << m.n_faces();
  if (m.n_halfedges() != 3 * m.n_faces())
    return ::testing::AssertionFailure() << m.n_halfedges() << " halfedges for " << m.n_faces()
                                         << " triangles";
  std::vector<int> valence(m.n_vertices(), 0);
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t) ++valence[v];
  for (auto h : m.halfedges()) {
    if (m.is_boundary(h)) return ::testing::AssertionFailure() << "boundary halfedge " << h.idx();
    const HH n = m.next_halfedge_handle(h);
    if (m.prev_halfedge_handle(n) != h)
      return ::testing::AssertionFailure() << "prev(next(" << h.idx() << ")) differs";
    if (m.from_vertex_handle(n) != m.to_vertex_handle(h))
      return ::testing::AssertionFailure() << "next of " << h.idx() << " does not continue it";
    if (m.next_halfedge_handle(m.next_halfedge_handle(n)) != h)
      return ::testing::AssertionFailure() << "face of " << h.idx() << " is not a triangle";
    if (m.face_handle(n) != m.face_handle(h))
      return ::testing::AssertionFailure() << "next of " << h.idx() << " in another face";
  }
  for (auto f : m.faces()) {
    const HH h = m.halfedge_handle(f);
    if (!h.is_valid() || m.face_handle(h) != f)
      return ::testing::AssertionFailure() << "face " << f.idx() << "'s halfedge";
    const Triangle& t = mesh.triangles[f.idx()];
    std::vector<int> expected{int(t[0]), int(t[1]), int(t[2])};
    std::rotate(expected.begin(), std::min_element(expected.begin(), expected.end()), expected.end());
    if (faceVertices(m, f) != expected)
      return ::testing::AssertionFailure() << "face " << f.idx() << " is not triangle " << f.idx();
  }
  for (auto v : m.vertices()) {
    if (!m.is_manifold(v)) return ::testing::AssertionFailure() << "vertex " << v.idx() << " not manifold";
    const HH h = m.halfedge_handle(v);
    if (!h.is_valid() || m.from_vertex_handle(h) != v)
      return ::testing::AssertionFailure() << "vertex " << v.idx() << "'s halfedge is not outgoing";
    if (int(m.valence(v)) != valence[v.idx()])
      return ::testing::AssertionFailure() << "vertex " << v.idx() << ": valence " << m.valence(v)
                                           << ", " << valence[v.idx()] << " triangles";
  }
  return ::testing::AssertionSuccess();
}

/// `direct` and `byAddFace` are the same mesh: vertices (points, surfels), faces (vertex
/// triples up to rotation) and, for every halfedge, opposite, next, prev and face, compared
/// through vertex pairs; then index for index, as toSurfaceMesh numbers edges as add_face.
::testing::AssertionResult sameMesh(const SurfaceMesh& direct, const SurfaceMesh& byAddFace) {
  const SurfaceMesh &a = direct, &b = byAddFace;
  if (a.n_vertices() != b.n_vertices() || a.n_edges() != b.n_edges() || a.n_faces() != b.n_faces())
    return ::testing::AssertionFailure() << "sizes " << a.n_vertices() << "/" << a.n_edges() << "/"
                                         << a.n_faces() << " vs " << b.n_vertices() << "/"
                                         << b.n_edges() << "/" << b.n_faces();
  for (auto v : a.vertices()) {
    const auto w = b.vertex_handle(v.idx());
    if (a.point(v) != b.point(w)) return ::testing::AssertionFailure() << "point of " << v.idx();
    if (!(surfelOf(a, v) == surfelOf(b, w))) return ::testing::AssertionFailure() << "surfel of " << v.idx();
  }
  for (auto f : a.faces())
    if (faceVertices(a, f) != faceVertices(b, b.face_handle(f.idx())))
      return ::testing::AssertionFailure() << "face " << f.idx();
  for (auto h : a.halfedges()) {
    const auto [from, to] = ends(a, h);
    const HH g = b.find_halfedge(b.vertex_handle(from), b.vertex_handle(to));
    if (!g.is_valid())
      return ::testing::AssertionFailure() << "halfedge " << from << "->" << to << " missing";
    if (ends(a, a.opposite_halfedge_handle(h)) != ends(b, b.opposite_halfedge_handle(g)) ||
        ends(a, a.next_halfedge_handle(h)) != ends(b, b.next_halfedge_handle(g)) ||
        ends(a, a.prev_halfedge_handle(h)) != ends(b, b.prev_halfedge_handle(g)) ||
        a.face_handle(h).idx() != b.face_handle(g).idx())
      return ::testing::AssertionFailure() << "halfedge " << from << "->" << to << " linked differently";
  }
  for (auto h : a.halfedges()) {
    const HH g = b.halfedge_handle(h.idx());
    if (a.to_vertex_handle(h).idx() != b.to_vertex_handle(g).idx() ||
        a.next_halfedge_handle(h).idx() != b.next_halfedge_handle(g).idx() ||
        a.face_handle(h).idx() != b.face_handle(g).idx())
      return ::testing::AssertionFailure() << "halfedge " << h.idx() << " numbered differently";
  }
  for (auto f : a.faces())
    if (a.halfedge_handle(f).idx() != b.halfedge_handle(b.face_handle(f.idx())).idx())
      return ::testing::AssertionFailure() << "face " << f.idx() << "'s halfedge differs";
  return ::testing::AssertionSuccess();
}

/// Both constructions on one indexed mesh, compared.
void checkBoth(const TriangleMesh& mesh, const std::vector<Point>& positions) {
  SurfaceMesh direct, byAddFace;
  ASSERT_NO_THROW(requireClosedOrientedManifold(mesh.surfels.size(), mesh.triangles));
  ASSERT_NO_THROW(direct = toSurfaceMesh(mesh, positions));
  ASSERT_NO_THROW(byAddFace = toSurfaceMeshByAddFace(mesh, positions));
  EXPECT_TRUE(isClosedHalfedgeMesh(direct, mesh));
  EXPECT_TRUE(isClosedHalfedgeMesh(byAddFace, mesh));
  EXPECT_TRUE(sameMesh(direct, byAddFace));
}

/// Every boundary of the image under `pair`, each on its own, then all in one mesh (several
/// closed components). Returns the number of boundaries.
std::size_t checkImage(const BinaryVolume& volume, AdjacencyPair pair, const std::string& name) {
  SCOPED_TRACE(name + " pair " + toString(pair));
  const auto image = binaryView(volume);
  TriangleMesh all;
  std::vector<Point> allPositions;
  std::size_t boundaries = 0;
  for (const std::vector<Surfel>& boundary : scanBoundaries(image, pair).components()) {
    const SurfaceGraph graph = trackComponent(image, boundary.front(), pair);
    const TriangleMesh mesh = extractLoops(image, graph);
    const std::vector<Point> positions = mapVertices(mesh, MidpointMapping{});
    checkBoth(mesh, positions);
    if (::testing::Test::HasFailure()) return boundaries;
    ++boundaries;
    const auto offset = std::uint32_t(all.surfels.size());
    all.surfels.insert(all.surfels.end(), mesh.surfels.begin(), mesh.surfels.end());
    allPositions.insert(allPositions.end(), positions.begin(), positions.end());
    for (Triangle t : mesh.triangles) all.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  checkBoth(all, allPositions);
  return boundaries;
}

class SurfaceMeshConstruction : public ::testing::TestWithParam<AdjacencyPair> {};

TEST_P(SurfaceMeshConstruction, EveryConfigurationOfA2x2x2And2x2x3Block) {
  std::size_t boundaries = 0;
  for (Dims dims : {Dims{2, 2, 2}, Dims{2, 2, 3}, Dims{3, 2, 2}, Dims{2, 3, 2}}) {
    const std::uint64_t count = std::uint64_t(1) << dims.count();
    for (std::uint64_t bits = 0; bits < count; ++bits) {
      if (!surftrack::testing::caseChecked(bits)) continue;
      boundaries += checkImage(ref::volumeFromBits(dims, bits), GetParam(),
                               "block " + std::to_string(dims.nx) + "x" + std::to_string(dims.ny) +
                                   "x" + std::to_string(dims.nz) + " bits " + std::to_string(bits));
      if (HasFailure()) return;
    }
  }
  EXPECT_GT(boundaries, surftrack::testing::subsetMinimum(4096));
}

TEST_P(SurfaceMeshConstruction, ThousandRandomImages) {
  // The images of LoopExtraction.ThousandRandomImages (same sides, densities and seeds).
  std::size_t boundaries = 0;
  for (int i = 0; i < 1000; ++i) {
    if (!surftrack::testing::caseChecked(std::uint64_t(i))) continue;
    const int side = 3 + i % 14;
    const double density = 0.1 + 0.8 * (i % 17) / 16.0;
    boundaries += checkImage(ref::randomVolume({side, side, side}, density, 7000u + i), GetParam(),
                             "random image " + std::to_string(i));
    if (HasFailure()) return;
  }
  EXPECT_GT(boundaries, surftrack::testing::subsetMinimum(5000));
}

TEST_P(SurfaceMeshConstruction, LargerRandomImages) {
  for (int i = 0; i < 6; ++i)
    if (surftrack::testing::caseChecked(std::uint64_t(i)))
      checkImage(ref::randomVolume({40, 36, 32}, 0.2 + 0.12 * i, 9100u + i), GetParam(),
               "random 40x36x32 image " + std::to_string(i));
}

INSTANTIATE_TEST_SUITE_P(AllPairs, SurfaceMeshConstruction, ::testing::ValuesIn(kAllAdjacencyPairs),
                         surftrack::testing::pairTestName);

// ---------------------------------------------------------------------------------------------
// Triangles that are not a closed oriented manifold.

TriangleMesh withVertices(std::size_t n, std::vector<Triangle> triangles) {
  TriangleMesh m;
  for (std::size_t i = 0; i < n; ++i) m.surfels.push_back(Surfel{{int(i), 0, 0}, 0});
  m.triangles = std::move(triangles);
  return m;
}

std::vector<Point> positionsOf(const TriangleMesh& m) {
  std::vector<Point> p;
  for (std::size_t i = 0; i < m.surfels.size(); ++i) p.push_back({double(i), double(i * i % 7), double(i % 3)});
  return p;
}

/// A consistently oriented tetrahedron on vertices a, b, c, d.
std::vector<Triangle> tetrahedron(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  return {{a, c, b}, {a, b, d}, {a, d, c}, {b, c, d}};
}

std::vector<Triangle> operator+(std::vector<Triangle> x, const std::vector<Triangle>& y) {
  x.insert(x.end(), y.begin(), y.end());
  return x;
}

/// toSurfaceMesh (and requireClosedOrientedManifold) throw std::logic_error saying the
/// triangles are not a manifold.
::testing::AssertionResult rejected(const TriangleMesh& m) {
  try {
    requireClosedOrientedManifold(m.surfels.size(), m.triangles);
    return ::testing::AssertionFailure() << "accepted by requireClosedOrientedManifold";
  } catch (const std::logic_error&) {
  }
  try {
    toSurfaceMesh(m, positionsOf(m));
  } catch (const std::logic_error& e) {
    if (std::string(e.what()).find("not a closed oriented manifold") == std::string::npos)
      return ::testing::AssertionFailure() << "unexpected message: " << e.what();
    return ::testing::AssertionSuccess() << e.what();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "not a std::logic_error: " << e.what();
  }
  return ::testing::AssertionFailure() << "accepted";
}

TEST(SurfaceMeshErrors, SmallClosedMeshesAreAccepted) {
  checkBoth(withVertices(0, {}), {});
  checkBoth(withVertices(4, tetrahedron(0, 1, 2, 3)), positionsOf(withVertices(4, {})));
  // Two tetrahedra apart, and a "pillow": two triangles on the same three vertices.
  const TriangleMesh two = withVertices(8, tetrahedron(0, 1, 2, 3) + tetrahedron(7, 5, 6, 4));
  checkBoth(two, positionsOf(two));
  const TriangleMesh pillow = withVertices(3, {{0, 1, 2}, {0, 2, 1}});
  checkBoth(pillow, positionsOf(pillow));
}

TEST(SurfaceMeshErrors, MalformedTetrahedraAreRejected) {
  const std::vector<Triangle> tet = tetrahedron(0, 1, 2, 3);
  for (std::size_t f = 0; f < tet.size(); ++f) {
    SCOPED_TRACE("triangle " + std::to_string(f));
    std::vector<Triangle> removed = tet, flipped = tet, duplicated = tet;
    removed.erase(removed.begin() + f);
    std::swap(flipped[f][1], flipped[f][2]);
    duplicated.push_back(tet[f]);
    EXPECT_TRUE(rejected(withVertices(4, removed)));
    EXPECT_TRUE(rejected(withVertices(4, flipped)));
    EXPECT_TRUE(rejected(withVertices(4, duplicated)));
  }
  // Two tetrahedra sharing a vertex: every edge is fine, vertex 0 has two fans.
  const TriangleMesh vertex = withVertices(7, tet + tetrahedron(0, 4, 5, 6));
  EXPECT_TRUE(rejected(vertex));
  EXPECT_THROW(toSurfaceMeshByAddFace(vertex, positionsOf(vertex)), std::logic_error);
  // Two tetrahedra sharing an edge: edge (0, 1) is in four triangles.
  EXPECT_TRUE(rejected(withVertices(6, tet + tetrahedron(0, 1, 4, 5))));
  // An isolated vertex (add_face accepts it: a vertex without halfedge).
  const TriangleMesh isolated = withVertices(5, tet);
  EXPECT_TRUE(rejected(isolated));
  EXPECT_NO_THROW(toSurfaceMeshByAddFace(isolated, positionsOf(isolated)));
  // A degenerate triangle, alone or closed by its reverse.
  EXPECT_TRUE(rejected(withVertices(4, tet + std::vector<Triangle>{{0, 0, 1}, {1, 0, 0}})));
  EXPECT_TRUE(rejected(withVertices(3, {{0, 1, 1}})));
  EXPECT_THROW(toSurfaceMeshByAddFace(withVertices(3, {{0, 1, 1}}), positionsOf(withVertices(3, {}))),
               std::logic_error);
  // Not manifold errors but bad arguments.
  const TriangleMesh bad = withVertices(4, tet + std::vector<Triangle>{{0, 1, 9}});
  EXPECT_THROW(toSurfaceMesh(bad, positionsOf(bad)), std::invalid_argument);
  EXPECT_THROW(toSurfaceMesh(withVertices(4, tet), positionsOf(withVertices(3, {}))), std::invalid_argument);
  EXPECT_THROW(toSurfaceMeshByAddFace(bad, positionsOf(bad)), std::invalid_argument);
}

TEST(SurfaceMeshErrors, MalformedBoundaryMeshesAreRejected) {
  // Real boundaries: a triangle removed, flipped or duplicated, at several places; two copies
  // of a boundary glued at one vertex.
  std::size_t cases = 0;
  for (int i = 0; i < 12; ++i) {
    const auto volume = ref::randomVolume({6, 6, 6}, 0.3 + 0.04 * i, 8100u + i);
    const auto image = binaryView(volume);
    const AdjacencyPair pair = kAllAdjacencyPairs[i % 4];
    for (const std::vector<Surfel>& boundary : scanBoundaries(image, pair).components()) {
      const TriangleMesh mesh = extractLoops(image, trackComponent(image, boundary.front(), pair));
      SCOPED_TRACE("image " + std::to_string(i) + " boundary of " + std::to_string(mesh.surfels.size()) + " surfels");
      for (std::size_t f = 0; f < mesh.triangles.size(); f += 1 + mesh.triangles.size() / 5) {
        TriangleMesh removed = mesh, flipped = mesh, duplicated = mesh;
        removed.triangles.erase(removed.triangles.begin() + f);
        std::swap(flipped.triangles[f][0], flipped.triangles[f][1]);
        duplicated.triangles.insert(duplicated.triangles.begin() + (f * 7) % mesh.triangles.size(),
                                    mesh.triangles[f]);
        EXPECT_TRUE(rejected(removed));
        EXPECT_TRUE(rejected(flipped));
        EXPECT_TRUE(rejected(duplicated));
        cases += 3;
      }
      // The same boundary twice, the copy's vertex 0 replaced by the original's vertex 0.
      TriangleMesh glued = mesh;
      const auto n = std::uint32_t(mesh.surfels.size());
      glued.surfels.insert(glued.surfels.end(), mesh.surfels.begin() + 1, mesh.surfels.end());
      for (Triangle t : mesh.triangles) {
        for (auto& v : t) v = v == 0 ? 0 : v + n - 1;
        glued.triangles.push_back(t);
      }
      EXPECT_TRUE(rejected(glued));
      TriangleMesh isolated = mesh;
      isolated.surfels.push_back(Surfel{{100, 100, 100}, 0});
      EXPECT_TRUE(rejected(isolated));
      cases += 2;
    }
  }
  EXPECT_GT(cases, 100u);
}

}  // namespace
