// extractLoops (paper §5.2), the boundary mappings (§3.1), the OpenMesh conversion and mesh
// files, checked against references that do not use the converter: the boundaries come from
// scanBoundaries and from voxel components (VoxelComponents.h), the Euler characteristics from
// cell counts on the voxels, the orientation from exact-enough solid-angle winding numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <random>
#include <system_error>

#include <OpenMesh/Core/IO/MeshIO.hh>

#include "BoundaryMapping.h"
#include "Cancellation.h"
#include "CaseSubset.h"
#include "LoopExtraction.h"
#include "MeshChecks.h"
#include "PairTestName.h"
#include "MeshIO.h"
#include "Phantoms.h"
#include "ScanBoundaries.h"
#include "SurfaceMesh.h"
#include "TrackComponent.h"
#include "VoxelComponents.h"

using namespace surftrack;
namespace ref = surftrack::testing;
using Point = std::array<double, 3>;
using ref::isClosedManifoldOn;
using ref::signedVolume;
using ref::voxelEuler;
using ref::windingNumber;

namespace {

// ---------------------------------------------------------------------------------------------
// The whole check of one binary image under one pair.

struct Checks {
  bool winding = false;   // winding numbers at every voxel of O and Q (costly)
  bool openMesh = false;  // build the OpenMesh mesh and check it has no boundary
};

struct ImageStats {
  std::size_t boundaries = 0, triangles = 0, windingVoxels = 0;
};

ImageStats checkImage(const BinaryVolume& volume, AdjacencyPair pair, Checks checks,
                      const std::string& name) {
  SCOPED_TRACE(name + " pair " + toString(pair));
  ImageStats stats;
  const auto image = binaryView(volume);
  const BoundaryPartition partition = scanBoundaries(image, pair);
  const ref::VoxelComponents voxels(image, pair);
  const Dims& dims = volume.dims();
  const int outside = voxels.component(Voxel{-1, -1, -1});
  std::map<int, long> eulerSum;  // 1-component -> sum of chi of its boundaries' meshes

  for (const std::vector<Surfel>& boundary : partition.components()) {
    const std::vector<std::uint64_t> keys = ref::sortedKeys(boundary);
    const SurfaceGraph graph = trackComponent(image, boundary.front(), pair);
    const TriangleMesh mesh = extractLoops(image, graph);
    EXPECT_EQ(mesh.surfels, graph.surfels) << "vertex v must be graph vertex v";
    EXPECT_EQ(extractLoops(graph).triangles, mesh.triangles)
        << "the bricks the graph keeps must give the triangles the image gives";
    long euler = 0;
    const auto manifold = isClosedManifoldOn(mesh, keys, &euler);
    EXPECT_TRUE(manifold);
    if (!manifold) return stats;
    ++stats.boundaries;
    stats.triangles += mesh.triangles.size();

    const int O = voxels.component(boundary.front().inside());
    const int Q = voxels.component(boundary.front().outside());
    eulerSum[O] += euler;
    const std::vector<Point> positions = mapVertices(mesh, MidpointMapping{});
    const double volumeSign = signedVolume(mesh, positions);
    EXPECT_EQ(volumeSign > 0, Q == outside) << "signed volume " << volumeSign;
    EXPECT_NE(volumeSign, 0.0);

    if (checks.winding) {
      // O lies inside the closed surface iff Q is the unbounded component; the surface is
      // oriented from O to Q, so the side inside gets winding +1 (O) or -1 (a cavity Q).
      const bool outer = Q == outside;
      for (int z = -1; z <= dims.nz; ++z)
        for (int y = -1; y <= dims.ny; ++y)
          for (int x = -1; x <= dims.nx; ++x) {
            const Voxel v{x, y, z};
            const int c = voxels.component(v);
            const bool inO = voxels.value(v) && c == O, inQ = !voxels.value(v) && c == Q;
            if (!inO && !inQ) continue;
            const double expected = inO ? (outer ? 1 : 0) : (outer ? 0 : -1);
            const double w = windingNumber(mesh, positions, {double(x), double(y), double(z)});
            EXPECT_NEAR(w, expected, 1e-6) << "voxel " << v << (inO ? " of O" : " of Q");
            ++stats.windingVoxels;
          }
    }
    if (checks.openMesh) {
      SurfaceMesh om;
      EXPECT_NO_THROW(om = toSurfaceMesh(mesh, positions));
      EXPECT_EQ(om.n_vertices(), mesh.surfels.size());
      EXPECT_EQ(om.n_faces(), mesh.triangles.size());
      for (auto heh : om.halfedges()) EXPECT_FALSE(om.is_boundary(heh));
      for (auto vh : om.vertices()) EXPECT_TRUE(om.is_manifold(vh));
    }
  }

  // Euler: sum over the boundaries of each kappa-component O of chi = 2 chi(O).
  std::map<int, std::vector<Voxel>> components;
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x)
        if (volume.at(x, y, z)) components[voxels.component({x, y, z})].push_back({x, y, z});
  for (const auto& [O, members] : components)
    EXPECT_EQ(eulerSum[O], 2 * voxelEuler(members, voxels, O, pair)) << "component of " << members.front();
  return stats;
}

class LoopExtraction : public ::testing::TestWithParam<AdjacencyPair> {};

// ---------------------------------------------------------------------------------------------

TEST_P(LoopExtraction, EveryConfigurationOfA2x2x2And2x2x3Block) {
  ImageStats total;
  for (Dims dims : {Dims{2, 2, 2}, Dims{2, 2, 3}, Dims{3, 2, 2}, Dims{2, 3, 2}}) {
    const std::uint64_t count = std::uint64_t(1) << dims.count();
    for (std::uint64_t bits = 0; bits < count; ++bits) {
      if (!surftrack::testing::caseChecked(bits)) continue;
      const auto stats = checkImage(ref::volumeFromBits(dims, bits), GetParam(), {true, bits % 16 == 0},
                                    "block " + std::to_string(dims.nx) + "x" + std::to_string(dims.ny) +
                                        "x" + std::to_string(dims.nz) + " bits " + std::to_string(bits));
      total.boundaries += stats.boundaries;
      total.windingVoxels += stats.windingVoxels;
      if (HasFailure()) return;
    }
  }
  EXPECT_GT(total.boundaries, surftrack::testing::subsetMinimum(4096));
  EXPECT_GT(total.windingVoxels, surftrack::testing::subsetMinimum(100000));
}

TEST_P(LoopExtraction, ThousandRandomImages) {
  ImageStats total;
  for (int i = 0; i < 1000; ++i) {
    if (!surftrack::testing::caseChecked(std::uint64_t(i))) continue;
    const int side = 3 + i % 14;
    const double density = 0.1 + 0.8 * (i % 17) / 16.0;
    const Checks checks{side <= 6, i % 5 == 0};
    const auto stats = checkImage(ref::randomVolume({side, side, side}, density, 7000u + i), GetParam(),
                                  checks, "random image " + std::to_string(i));
    total.boundaries += stats.boundaries;
    total.triangles += stats.triangles;
    if (HasFailure()) return;
  }
  EXPECT_GT(total.boundaries, surftrack::testing::subsetMinimum(5000));
}

INSTANTIATE_TEST_SUITE_P(AllPairs, LoopExtraction, ::testing::ValuesIn(kAllAdjacencyPairs),
                         surftrack::testing::pairTestName);

// ---------------------------------------------------------------------------------------------

TEST(LoopExtractionErrors, GraphOfAnotherImageIsRejected) {
  BinaryVolume a({3, 3, 3});
  a.at(0, 0, 0) = a.at(1, 1, 1) = 1;  // a strict 26-configuration of 1-voxels
  const auto image = binaryView(a);
  SurfaceGraph graph = trackComponent(image, Surfel{{0, 0, 0}, 1}, AdjacencyPair::k26_6);
  EXPECT_NO_THROW(extractLoops(image, graph));
  // Tracked with 18-6, the two cubes are separate boundaries: the tube has no vertex links.
  SurfaceGraph split = trackComponent(image, Surfel{{0, 0, 0}, 1}, AdjacencyPair::k18_6);
  split.pair = AdjacencyPair::k26_6;
  EXPECT_THROW(extractLoops(image, split), std::logic_error);
  EXPECT_THROW(extractLoops(split), std::logic_error);
  // A graph that carries no bricks can only be checked against an image.
  SurfaceGraph bare = graph;
  bare.bricks = {};
  EXPECT_THROW(extractLoops(bare), std::invalid_argument);
  EXPECT_NO_THROW(extractLoops(image, bare));
  // A vertex moved to a brick the graph's bricks do not hold.
  SurfaceGraph moved = graph;
  moved.surfels[0].c.x += 64;
  EXPECT_THROW(extractLoops(moved), std::logic_error);
  // A voxel of the tracked surface removed.
  BinaryVolume b = a;
  b.at(1, 1, 1) = 0;
  EXPECT_THROW(extractLoops(binaryView(b), graph), std::logic_error);
  try {
    extractLoops(binaryView(b), graph);
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("does not match the image"), std::string::npos) << e.what();
  }
}

TEST(LoopExtractionCost, ReadsVoxelsInProportionToTheSurfaceOnly) {
  // A ball in a 2^18-sided domain: anything O(volume) would never finish.
  std::size_t reads = 0;
  const int c = 1 << 17;
  const Ball inBall = Ball::ofRadius({c, c, c}, 30);
  const ImplicitImage ball({1 << 18, 1 << 18, 1 << 18}, [&](int x, int y, int z) {
    ++reads;
    return inBall(x, y, z);
  });
  const SurfaceGraph graph = trackComponent(ball, Surfel{{c + 30, c, c}, 0}, AdjacencyPair::k26_6);
  reads = 0;
  const TriangleMesh mesh = extractLoops(ball, graph);
  EXPECT_LE(reads, 4 * 8 * graph.surfelCount());
  EXPECT_TRUE(isClosedManifoldOn(mesh, ref::sortedKeys(graph.surfels)));
  // From the bricks the graph keeps, the image is not read at all.
  reads = 0;
  EXPECT_EQ(extractLoops(graph).triangles, mesh.triangles);
  EXPECT_EQ(reads, 0u);
}

// ---------------------------------------------------------------------------------------------
// Gray images and the iso-value mapping.

TEST(IsoValueMapping, ValuesEqualToTheIsoValueNeverMergeVertices) {
  const double s = 100;
  std::size_t clamped = 0;
  ImageGeometry geometry;
  geometry.spacing = {0.5, 2.0, 1.25};
  geometry.origin = {10, -3, 7};
  geometry.direction = {{{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}};
  for (int i = 0; i < 60; ++i) {
    const int side = 4 + i % 7;
    DenseImage<std::uint8_t> gray({side, side + 1, side});
    std::mt19937 rng(500 + i);
    std::uniform_int_distribution<int> level(0, 4);
    for (auto& f : gray.data()) f = std::uint8_t(80 + 10 * level(rng));  // 80 .. 120, 100 = s
    const ThresholdImage<std::uint8_t> image(gray, s);
    const IsoValueMapping mapping(image);
    for (AdjacencyPair pair : kAllAdjacencyPairs) {
      SCOPED_TRACE("gray image " + std::to_string(i) + " pair " + toString(pair));
      std::vector<Point> all;
      for (const auto& boundary : scanBoundaries(image, pair).components()) {
        const SurfaceGraph graph = trackComponent(image, boundary.front(), pair);
        const TriangleMesh mesh = extractLoops(image, graph);
        ASSERT_TRUE(isClosedManifoldOn(mesh, ref::sortedKeys(boundary)));
        for (const Surfel& t : mesh.surfels) {
          const Point p = mapping(t);
          const Voxel c = t.inside(), d = t.outside();
          const int a = axisOf(t.n);
          const double along = (p[a] - c[a]) * signOf(t.n);  // in ]0, 1[ strictly
          EXPECT_GT(along, 0.0);
          EXPECT_LT(along, 1.0);
          for (int k = 0; k < 3; ++k)
            if (k != a) {
              EXPECT_EQ(p[k], double(c[k]));
            }
          if (gray.dims().contains(d) && gray.at(d) == s) {
            ++clamped;
            EXPECT_NEAR(along, 1 - IsoValueMapping<std::uint8_t>::kDefaultEpsilon, 1e-12);
          }
          all.push_back(p);
        }
        // Same connectivity as the midpoint mesh, vertices moved only; physical placement.
        const SurfaceMesh om = toMesh(graph, image, mapping, geometry);
        const SurfaceMesh mid = toMesh(graph, image, MidpointMapping{});
        ASSERT_EQ(om.n_faces(), mesh.triangles.size());
        ASSERT_EQ(om.n_vertices(), mesh.surfels.size());
        for (auto heh : om.halfedges()) EXPECT_FALSE(om.is_boundary(heh));
        for (auto fh : om.faces()) {
          std::vector<int> f, g;
          for (auto vh : om.fv_range(fh)) f.push_back(vh.idx());
          for (auto vh : mid.fv_range(mid.face_handle(fh.idx()))) g.push_back(vh.idx());
          EXPECT_EQ(f, g);
        }
        for (auto vh : om.vertices()) {
          EXPECT_EQ(surfelOf(om, vh), mesh.surfels[vh.idx()]);
          const Point q = geometry.toPhysical(mapping(mesh.surfels[vh.idx()]));
          const auto& r = om.point(vh);
          EXPECT_EQ((std::array<double, 3>{r[0], r[1], r[2]}), q);
        }
      }
      std::sort(all.begin(), all.end());
      EXPECT_EQ(std::adjacent_find(all.begin(), all.end()), all.end()) << "two vertices coincide";
    }
  }
  EXPECT_GT(clamped, 1000u) << "the test must exercise f(d) = s";
}

TEST(IsoValueMapping, InterpolatesLinearlyAndFallsBackToTheMidpointOutsideTheDomain) {
  DenseImage<float> gray({2, 1, 1});
  gray.at(0, 0, 0) = 10;
  gray.at(1, 0, 0) = 0;
  const IsoValueMapping<float> mapping(gray, 7.5);
  EXPECT_DOUBLE_EQ(mapping.parameter(Surfel{{0, 0, 0}, 0}), 0.25);
  EXPECT_DOUBLE_EQ(mapping(Surfel{{0, 0, 0}, 0})[0], 0.25);
  EXPECT_DOUBLE_EQ(mapping.parameter(Surfel{{0, 0, 0}, 1}), 0.5);  // d = (-1, 0, 0) is outside
  EXPECT_THROW(IsoValueMapping<float>(gray, 7.5, 0.0), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Mesh files.

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("surftrack_test_loop_extraction_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir_);
    BinaryVolume volume({3, 3, 3});
    for (auto& f : volume.data()) f = 1;
    volume.at(1, 1, 1) = 0;  // a cavity: two boundaries; use the outer one
    volume.at(0, 0, 0) = 0;
    const auto image = binaryView(volume);
    mesh_ = toMesh(trackComponent(image, Surfel{{2, 2, 2}, 0}, AdjacencyPair::k26_6), image,
                   MidpointMapping{});
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::size_t filesInDir() const {
    return std::distance(std::filesystem::directory_iterator(dir_), std::filesystem::directory_iterator{});
  }

  std::filesystem::path dir_;
  SurfaceMesh mesh_;
};

TEST_F(MeshFiles, RoundTripThroughOpenMesh) {
  ASSERT_GT(mesh_.n_faces(), 0u);
  struct Case {
    std::string name;
    bool binary;
  };
  const std::vector<Case> cases = {{"a.ply", true}, {"b.ply", false}, {"c.obj", true},
                                   {"d.off", true}, {"e.stl", true},  {"f.stl", false},
                                   {"G.PLY", true}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = (dir_ / c.name).string();
    writeMesh(mesh_, path, c.binary);
    SurfaceMesh back;
    OpenMesh::IO::Options options;
    if (c.binary) options += OpenMesh::IO::Options::Binary;
    ASSERT_TRUE(OpenMesh::IO::read_mesh(back, path, options));
    EXPECT_EQ(back.n_faces(), mesh_.n_faces());
    if (c.name.find(".stl") == std::string::npos) {
      EXPECT_EQ(back.n_vertices(), mesh_.n_vertices());
    }
  }
  EXPECT_EQ(filesInDir(), cases.size()) << "no temporary file may remain";
}

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// writeTriangles (an exporter over the triangle list) writes the bytes writeMesh writes for the
// half-edge mesh of the same triangles, in every format, on the boundaries of random images.
TEST_F(MeshFiles, TriangleListFilesEqualHalfedgeMeshFiles) {
  for (int i = 0; i < 8; ++i) {
    const auto volume = ref::randomVolume({7 + i, 6 + i, 5 + i}, 0.3 + 0.05 * i, 6100u + i);
    const auto image = binaryView(volume);
    const AdjacencyPair pair = kAllAdjacencyPairs[i % 4];
    const auto boundaries = scanBoundaries(image, pair).components();
    ASSERT_FALSE(boundaries.empty());
    const TriangleMesh mesh = extractLoops(image, trackComponent(image, boundaries.front().front(), pair));
    std::vector<Point> positions = mapVertices(mesh, MidpointMapping{});
    for (auto& p : positions) p = {p[0] * 0.7 + 0.1, p[1] * 1.3, p[2] - 5};  // digits beyond halves
    const SurfaceMesh om = toSurfaceMesh(mesh, positions);
    for (const std::string name : {"a.ply", "b.ply", "c.obj", "d.off", "e.stl", "f.stl"}) {
      SCOPED_TRACE("image " + std::to_string(i) + " " + name);
      const bool binary = name != "b.ply" && name != "f.stl";
      const std::string viaMesh = (dir_ / ("m" + name)).string(), viaList = (dir_ / ("t" + name)).string();
      writeMesh(om, viaMesh, binary);
      writeTriangles(positions, mesh.triangles, viaList, binary);
      const std::string a = fileBytes(viaMesh), b = fileBytes(viaList);
      EXPECT_GT(a.size(), 100u);
      EXPECT_TRUE(a == b) << a.size() << " vs " << b.size() << " bytes";
    }
  }
  EXPECT_EQ(filesInDir(), 12u) << "no temporary file may remain";
  EXPECT_THROW(writeTriangles({}, {}, (dir_ / "mesh.xyz").string()), std::invalid_argument);
  EXPECT_THROW(writeTriangles({}, {}, (dir_ / "no" / "dir" / "mesh.ply").string()), std::runtime_error);
  EXPECT_EQ(filesInDir(), 12u);
}

// A path that cannot be written says why, with the system's errno (FileWriteError, a
// std::system_error, converter/MeshIO.h): a missing directory, a file where a directory should
// be, a path that is a directory (refused before anything is written, whatever its extension).
TEST_F(MeshFiles, AnUnwritablePathSaysWhyWithItsErrno) {
  const std::vector<std::array<double, 3>> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  auto expectError = [&](const std::filesystem::path& path, int code, const std::string& why) {
    SCOPED_TRACE(path.string());
    try {
      writeTriangles(points, triangles, path.string());
      ADD_FAILURE() << "no error";
    } catch (const std::system_error& e) {
      EXPECT_EQ(e.code(), std::error_code(code, std::generic_category())) << e.what();
      EXPECT_EQ(std::string(e.what()), "cannot write '" + path.string() + "': " + why);
    }
  };
  expectError(dir_ / "no" / "dir" / "mesh.ply", ENOENT, "directory '" + (dir_ / "no" / "dir").string() + "' does not exist");
  std::ofstream(dir_ / "file") << "x";
  expectError(dir_ / "file" / "mesh.obj", ENOTDIR, "'" + (dir_ / "file").string() + "' is not a directory");
  for (const std::string name : {"out.ply", "out.stl", "out"}) {
    std::filesystem::create_directory(dir_ / name);
    expectError(dir_ / name, EISDIR, "it is a directory");
  }
  EXPECT_EQ(filesInDir(), 4u) << "the file and the three directories only";
}

// A raised cancel flag stops writeTriangles in every format (the binary PLY writer between its
// buffers, OpenMesh's writers through the exporter) with Cancelled, and the temporary file is
// removed; a flag that stays down changes nothing.
TEST_F(MeshFiles, ACancelledWriteLeavesNoFile) {
  const std::vector<std::array<double, 3>> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const std::vector<std::pair<std::string, bool>> cases = {{"a.ply", true}, {"b.ply", false}, {"c.obj", true},
                                                           {"d.off", true}, {"e.stl", true},  {"f.stl", false}};
  std::atomic<bool> cancel{true};
  for (const auto& [name, binary] : cases) {
    SCOPED_TRACE(name);
    EXPECT_THROW(writeTriangles(points, triangles, (dir_ / name).string(), binary, &cancel), Cancelled);
    EXPECT_EQ(filesInDir(), 0u) << "no file, no temporary file";
  }
  cancel = false;
  for (const auto& [name, binary] : cases) writeTriangles(points, triangles, (dir_ / name).string(), binary, &cancel);
  EXPECT_EQ(filesInDir(), cases.size());
}

TEST_F(MeshFiles, UnknownExtensionAndUnwritablePathThrowAndLeaveNoFile) {
  EXPECT_THROW(writeMesh(mesh_, (dir_ / "mesh.xyz").string()), std::invalid_argument);
  EXPECT_THROW(writeMesh(mesh_, (dir_ / "mesh").string()), std::invalid_argument);
  const std::string missing = (dir_ / "no" / "such" / "dir" / "mesh.ply").string();
  try {
    writeMesh(mesh_, missing);
    ADD_FAILURE() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  // A directory in the way of the final rename: the temporary file must be removed.
  std::filesystem::create_directory(dir_ / "taken.ply");
  std::filesystem::create_directory(dir_ / "taken.ply" / "x");
  EXPECT_THROW(writeMesh(mesh_, (dir_ / "taken.ply").string()), std::runtime_error);
  EXPECT_EQ(filesInDir(), 1u) << "only the directory 'taken.ply' may remain";
}

}  // namespace
