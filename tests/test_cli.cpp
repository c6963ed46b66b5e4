// End-to-end tests of the `surftrack` command-line tool: they run the executable on small
// volumes written with ITK (and on the mricron-data MRI volumes when installed), read the
// meshes back with OpenMesh, and check every bad input's exit status, one-line message, and
// that no output file is left behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <functional>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "Phantoms.h"
#include "cli/CliTestSupport.h"

namespace surftrack {
namespace {

using namespace clitest;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() /
            ("surftrack-cli-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(root_);
    work_ = root_ / "work";
    scratch_ = root_ / "scratch";
    fs::create_directories(work_);
    fs::create_directories(scratch_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(work_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(root_, ec);
  }

  std::string path(const std::string& name) const { return (work_ / name).string(); }
  RunResult run(const std::vector<std::string>& args) const { return runTool(args, scratch_); }

  /// Runs a command that must fail: exit status `code`, one line "surftrack: error: ..."
  /// containing `needle` on stderr, nothing on stdout, and the work directory unchanged
  /// (no output, no temporary file).
  void expectFailure(const std::vector<std::string>& args, int code, const std::string& needle) {
    const std::vector<std::string> before = listDirectory(work_);
    const RunResult r = run(args);
    std::string cmd;
    for (const auto& a : args) cmd += a + " ";
    SCOPED_TRACE("surftrack " + cmd);
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_EQ(r.err.rfind("surftrack: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(listDirectory(work_), before) << "a file was left behind";
  }

  static bool isRoot() { return ::geteuid() == 0; }

  fs::path root_, work_, scratch_;
};

// --- volumes ---------------------------------------------------------------------------------

ImageGeometry skewGeometry() {
  ImageGeometry g;
  g.spacing = {0.5, 2.0, 1.5};
  g.origin = {10.0, -20.0, 5.0};
  return g;
}

/// A box of value `in` over [lo, hi] (inclusive) in a volume of `out`.
template <class T>
DenseImage<T> boxVolume(Dims dims, Voxel lo, Voxel hi, T in, T out, ImageGeometry g = {}) {
  DenseImage<T> image(dims, out, g);
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) image.at(x, y, z) = in;
  return image;
}

/// Adds a ball of value `in`, radius r (voxels with |v - c|^2 <= r^2; lib/Phantoms.h).
template <class T>
void addBall(DenseImage<T>& image, Voxel c, int r, T in) {
  paintBall(image, Ball::ofRadius(c, r), in);
}

template <class T>
std::size_t surfelsAbove(const DenseImage<T>& image, double iso) {
  return countBoundarySurfels(image, [iso](T v) { return double(v) > iso; });
}

void expectNear3(const std::array<double, 3>& a, const std::array<double, 3>& b, double tol,
                 const std::string& what) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tol) << what << " axis " << i;
}

/// The checks on a good run: exit 0, JSON surfels, the mesh read back with OpenMesh is a
/// closed manifold with one vertex per surfel, the tool's triangle count, and the expected
/// physical bounding box.
void expectGoodMesh(const RunResult& r, const fs::path& mesh, std::size_t surfels,
                    const std::optional<std::pair<std::array<double, 3>, std::array<double, 3>>>& box) {
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(jsonNumber(r.out, "surfels"), double(surfels));
  EXPECT_EQ(jsonNumber(r.out, "vertices"), double(surfels));
  EXPECT_EQ(jsonBool(r.out, "closed"), std::optional<bool>(true));
  EXPECT_EQ(jsonBool(r.out, "manifold"), std::optional<bool>(true));
  const MeshCheck c = checkMeshFile(mesh);
  ASSERT_TRUE(c.read) << mesh;
  EXPECT_EQ(c.vertices, surfels) << mesh;
  EXPECT_EQ(double(c.faces), jsonNumber(r.out, "triangles")) << mesh;
  EXPECT_TRUE(c.closed) << mesh;
  EXPECT_TRUE(c.manifold) << mesh;
  if (box) {
    expectNear3(c.min, box->first, 1e-3, mesh.string() + " bbox min");
    expectNear3(c.max, box->second, 1e-3, mesh.string() + " bbox max");
  }
}

// --- reading: every input format, spacing != 1, non-zero origin ------------------------------

TEST_F(Cli, ReadsEveryInputFormatInPhysicalCoordinates) {
  const Dims dims{20, 18, 16};
  const Voxel lo{4, 5, 3}, hi{12, 11, 10};
  const ImageGeometry g = skewGeometry();
  const auto image = boxVolume<std::int16_t>(dims, lo, hi, 100, 0, g);
  const std::size_t surfels = surfelsAbove(image, 50);
  ASSERT_EQ(surfels, 2u * (9 * 7 + 7 * 8 + 9 * 8));
  const auto box = physicalBox(g, {lo.x - 0.5, lo.y - 0.5, lo.z - 0.5}, {hi.x + 0.5, hi.y + 0.5, hi.z + 0.5});
  for (const std::string ext : {".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd"}) {
    SCOPED_TRACE(ext);
    const std::string in = path("box" + ext), out = path("box" + ext + ".ply");
    io::writeVolume(io::AnyVolume(image), in);
    const RunResult r = run({"mesh", in, "-o", out, "--iso", "50", "--mapping", "midpoint", "--json"});
    expectGoodMesh(r, out, surfels, box);
    EXPECT_EQ(jsonString(r.out, "type"), "int16");
  }
  // A raw file: the layout and the geometry on the command line.
  const std::string raw = path("box.raw"), out = path("box.raw.ply");
  {
    std::ofstream f(raw, std::ios::binary);
    f.write(reinterpret_cast<const char*>(image.data().data()), std::streamsize(image.data().size() * 2));
  }
  const RunResult r = run({"mesh", raw, "-o", out, "--raw-dims", "20,18,16", "--raw-type", "int16", "--spacing",
                           "0.5,2,1.5", "--origin", "10,-20,5", "--iso", "50", "--mapping", "midpoint", "--json"});
  expectGoodMesh(r, out, surfels, box);
  // Big-endian raw with a header.
  const std::string rawBig = path("box-be.raw"), outBig = path("box-be.ply");
  {
    std::ofstream f(rawBig, std::ios::binary);
    f.write("HEADER", 6);
    for (std::int16_t v : image.data()) {
      const char bytes[2] = {char((std::uint16_t(v) >> 8) & 0xFF), char(std::uint16_t(v) & 0xFF)};
      f.write(bytes, 2);
    }
  }
  const RunResult rb = run({"mesh", rawBig, "-o", outBig, "--raw-dims=20,18,16", "--raw-type=int16", "--raw-endian",
                            "big", "--raw-header", "6", "--spacing", "0.5,2,1.5", "--origin", "10,-20,5", "--iso",
                            "50", "--mapping", "midpoint", "--json"});
  expectGoodMesh(rb, outBig, surfels, box);
}

TEST_F(Cli, ReadsADicomSeries) {
  // A directory of one 2D DICOM file per slice, as a scanner writes it: the spacing, origin
  // and direction come from the slices' headers.
  ImageGeometry g;
  g.spacing = {0.75, 0.8, 2.0};
  g.origin = {-30.0, 12.5, 40.0};
  g.direction = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
  const Voxel lo{3, 4, 2}, hi{10, 9, 6};
  const auto image = boxVolume<std::uint16_t>(Dims{14, 12, 9}, lo, hi, 1000, 0, g);
  fs::create_directories(work_ / "series");
  io::writeDicomSeries(io::AnyVolume(image), path("series"));
  const std::size_t surfels = surfelsAbove(image, 500);
  const auto box = physicalBox(g, {lo.x - 0.5, lo.y - 0.5, lo.z - 0.5}, {hi.x + 0.5, hi.y + 0.5, hi.z + 0.5});
  const RunResult r = run({"mesh", path("series"), "-o", path("ct.stl"), "--iso", "500", "--json"});
  expectGoodMesh(r, path("ct.stl"), surfels, box);
  EXPECT_EQ(jsonArray(r.out, "spacing"), "0.75,0.8,2");
  EXPECT_EQ(jsonArray(r.out, "dims"), "14,12,9");
}

TEST_F(Cli, AppliesTheDirectionMatrix) {
  ImageGeometry g = skewGeometry();
  g.direction = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};  // 90 degrees about z
  const Voxel lo{2, 3, 4}, hi{9, 5, 6};
  const auto image = boxVolume<std::uint8_t>(Dims{12, 10, 9}, lo, hi, 200, 10, g);
  const std::size_t surfels = surfelsAbove(image, 100);
  // The linear mapping puts each vertex at t = (100 - 200) / (10 - 200) from its inside voxel.
  const double t = 100.0 / 190.0;
  const auto box = physicalBox(g, {lo.x - t, lo.y - t, lo.z - t}, {hi.x + t, hi.y + t, hi.z + t});
  for (const std::string ext : {".nrrd", ".mha", ".nii.gz"}) {
    SCOPED_TRACE(ext);
    const std::string in = path("rot" + ext), out = path("rot" + ext + ".off");
    io::writeVolume(io::AnyVolume(image), in);
    expectGoodMesh(run({"mesh", in, "-o", out, "--iso", "100", "--json"}), out, surfels, box);
  }
}

// --- writing: every mesh format --------------------------------------------------------------

TEST_F(Cli, WritesEveryMeshFormat) {
  const ImageGeometry g = skewGeometry();
  DenseImage<std::uint8_t> image(Dims{16, 16, 16}, 0, g);
  addBall<std::uint8_t>(image, Voxel{8, 7, 8}, 5, 255);
  const std::string in = path("ball.nrrd");
  io::writeVolume(io::AnyVolume(image), in);
  const std::size_t surfels = surfelsAbove(image, 127.5);
  struct Case {
    std::string name;
    std::vector<std::string> extra;
    std::string header;  // how the file starts
  };
  const std::vector<Case> cases = {
      {"ball.ply", {}, "ply\nformat binary_little_endian"},
      {"ball-ascii.ply", {"--ascii"}, "ply\nformat ascii"},
      {"ball.obj", {}, ""},
      {"ball.off", {}, "OFF"},
      {"ball.stl", {}, ""},
      {"ball-ascii.stl", {"--ascii"}, "solid"},
      {"BALL.PLY", {}, "ply"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::vector<std::string> args = {"mesh", in, "-o", path(c.name), "--iso", "127.5", "--mapping", "midpoint", "--json"};
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const RunResult r = run(args);
    const auto box = physicalBox(g, {8 - 5.5, 7 - 5.5, 8 - 5.5}, {8 + 5.5, 7 + 5.5, 8 + 5.5});
    expectGoodMesh(r, path(c.name), surfels, box);
    EXPECT_EQ(readText(path(c.name)).rfind(c.header, 0), 0u);
  }
  // The same vertices with the linear mapping stay strictly inside the midpoint box's cells.
  const RunResult r = run({"mesh", in, "-o", path("linear.ply"), "--iso", "127.5", "--json"});
  expectGoodMesh(r, path("linear.ply"), surfels, std::nullopt);
  EXPECT_EQ(jsonString(r.out, "mapping"), "linear");
}

// --- the six voxel types ---------------------------------------------------------------------

template <class T>
void writeBall(const std::string& file) {
  DenseImage<T> image(Dims{14, 13, 12}, T(0));
  addBall<T>(image, Voxel{7, 6, 6}, 4, T(100));
  io::writeVolume(io::AnyVolume(image), file);
}

TEST_F(Cli, ReadsAllSixVoxelTypes) {
  writeBall<std::uint8_t>(path("uint8.nrrd"));
  writeBall<std::int16_t>(path("int16.nrrd"));
  writeBall<std::uint16_t>(path("uint16.nrrd"));
  writeBall<std::int32_t>(path("int32.mha"));
  writeBall<float>(path("float.nii"));
  writeBall<double>(path("double.nrrd"));
  DenseImage<std::uint8_t> ref(Dims{14, 13, 12}, 0);
  addBall<std::uint8_t>(ref, Voxel{7, 6, 6}, 4, 100);
  const std::size_t surfels = surfelsAbove(ref, 50);
  for (const std::string name : {"uint8.nrrd", "int16.nrrd", "uint16.nrrd", "int32.mha", "float.nii", "double.nrrd"}) {
    SCOPED_TRACE(name);
    const RunResult r = run({"mesh", path(name), "-o", path(name + ".ply"), "--iso", "50", "--json"});
    expectGoodMesh(r, path(name + ".ply"), surfels, std::nullopt);
    EXPECT_EQ(jsonString(r.out, "type"), name.substr(0, name.find('.')));
    EXPECT_EQ(jsonNumber(r.out, "genus"), 0.0);
  }
}

// --- seeds -----------------------------------------------------------------------------------

class CliSeeds : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    geometry_.spacing = {2, 1, 1};
    geometry_.origin = {-5, 3, 7};
    image_ = DenseImage<std::uint8_t>(Dims{36, 20, 20}, 0, geometry_);
    addBall<std::uint8_t>(image_, Voxel{10, 10, 10}, 6, 200);  // A: x in [4, 16]
    addBall<std::uint8_t>(image_, Voxel{26, 10, 10}, 4, 200);  // B: x in [22, 30]
    DenseImage<std::uint8_t> a(image_.dims(), 0), b(image_.dims(), 0);
    addBall<std::uint8_t>(a, Voxel{10, 10, 10}, 6, 200);
    addBall<std::uint8_t>(b, Voxel{26, 10, 10}, 4, 200);
    surfelsA_ = surfelsAbove(a, 100);
    surfelsB_ = surfelsAbove(b, 100);
    input_ = path("balls.nii.gz");
    io::writeVolume(io::AnyVolume(image_), input_);
  }
  RunResult mesh(std::vector<std::string> extra, const std::string& out = "out.ply") {
    std::vector<std::string> args = {"mesh", input_, "-o", path(out), "--iso", "100"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  }
  ImageGeometry geometry_;
  DenseImage<std::uint8_t> image_;
  std::size_t surfelsA_ = 0, surfelsB_ = 0;
  std::string input_;
};

TEST_F(CliSeeds, RayFromAVoxelInsideWalksPlusXToTheFirstSurfel) {
  RunResult r = mesh({"--seed-ray", "26,10,10", "--json"});
  expectGoodMesh(r, path("out.ply"), surfelsB_, std::nullopt);
  EXPECT_EQ(jsonString(r.out, "walk_direction"), "+x");
  EXPECT_EQ(jsonNumber(r.out, "walk_steps"), 4.0);
  EXPECT_EQ(jsonBool(r.out, "voxel_inside"), std::optional<bool>(true));
  // The summary names the surfel used.
  r = mesh({"--seed-ray", "26,10,10"}, "out2.ply");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("voxel (26,10,10) (inside), 4 voxels along +x to surfel c=(30,10,10) d=(31,10,10)"),
            std::string::npos)
      << r.out;
}

TEST_F(CliSeeds, RayFromAVoxelOutsideWalksToTheFirstInsideVoxel) {
  const RunResult r = mesh({"--seed-ray", "18,10,10", "--json"});
  expectGoodMesh(r, path("out.ply"), surfelsB_, std::nullopt);
  EXPECT_EQ(jsonBool(r.out, "voxel_inside"), std::optional<bool>(false));
  EXPECT_EQ(jsonArray(r.out, "c"), "22,10,10") << r.out;
  EXPECT_EQ(jsonArray(r.out, "d"), "21,10,10") << r.out;
  // From (0,0,0), +x meets nothing, -x leaves the domain at once, +y ... : no ray reaches a
  // ball, but from (10,0,10) the +y ray (second try after +x, -x) reaches A.
  const RunResult r2 = mesh({"--seed-ray", "10,0,10", "--json"}, "out2.ply");
  expectGoodMesh(r2, path("out2.ply"), surfelsA_, std::nullopt);
  EXPECT_EQ(jsonString(r2.out, "walk_direction"), "+y");
}

TEST_F(CliSeeds, ASeedVoxelOrPointGoesToTheNearestSurfel) {
  // Voxel (19,10,10), between A (x <= 16) and B (x >= 22), is nearer A's surfel c=(16,10,10)
  // d=(17,10,10), whose midpoint x = 16.5 is 2.5 voxels = 5 mm away (spacing 2 along x), than
  // B's (21.5: 5 mm too, but B's y/z-neighbours are no nearer; ties go to the smaller key: A).
  RunResult r = mesh({"--seed", "19,10,10", "--json"});
  expectGoodMesh(r, path("out.ply"), surfelsA_, std::nullopt);
  EXPECT_EQ(jsonArray(r.out, "c"), "16,10,10") << r.out;
  EXPECT_EQ(jsonNumber(r.out, "distance"), 5.0) << r.out;
  // Nearer B: x = 20.
  r = mesh({"--seed", "20,10,10", "--json"}, "b.ply");
  expectGoodMesh(r, path("b.ply"), surfelsB_, std::nullopt);
  EXPECT_EQ(jsonNumber(r.out, "distance"), 3.0) << r.out;
  // The midpoint of a surfel of A, given as a physical point: that surfel, at distance 0
  // (the ray rule used to round it to the outside voxel and walk away from A).
  // Surfel c=(16,10,10) d=(17,10,10): midpoint x = 16.5 -> (-5 + 33, 13, 17) = (28, 13, 17).
  r = mesh({"--seed-point", "28,13,17", "--json"}, "p.ply");
  expectGoodMesh(r, path("p.ply"), surfelsA_, std::nullopt);
  EXPECT_EQ(jsonNumber(r.out, "distance"), 0.0) << r.out;
  EXPECT_EQ(jsonArray(r.out, "point"), "28,13,17") << r.out;
  r = mesh({"--seed", "19,10,10"}, "s.ply");
  EXPECT_NE(r.out.find("-> nearest surfel c=(16,10,10) d=(17,10,10), at 5"), std::string::npos) << r.out;
}

TEST_F(CliSeeds, ASpeckGivesAWarning) {
  DenseImage<std::uint8_t> image = image_;
  image.at(33, 2, 2) = 200;  // one voxel of noise
  io::writeVolume(io::AnyVolume(image), path("speck.nrrd"));
  RunResult r = run({"mesh", path("speck.nrrd"), "-o", path("s.ply"), "--iso", "100", "--seed", "33,2,2"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("surftrack: warning: the surface found is a speck: 6 surfels"), std::string::npos) << r.err;
  r = run({"mesh", path("speck.nrrd"), "-o", path("s.ply"), "--iso", "100", "--seed", "10,10,10"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

TEST_F(CliSeeds, SurfelLargestAndAll) {
  RunResult r = mesh({"--seed", "30,10,10,+x", "--json"});
  expectGoodMesh(r, path("out.ply"), surfelsB_, std::nullopt);
  r = mesh({"--largest", "--json"}, "largest.ply");
  expectGoodMesh(r, path("largest.ply"), surfelsA_, std::nullopt);
  EXPECT_EQ(jsonNumber(r.out, "boundaries"), 2.0);
  r = mesh({"--json"}, "default.ply");  // --largest is the default
  expectGoodMesh(r, path("default.ply"), surfelsA_, std::nullopt);
  r = mesh({"--all", "--json"}, "all.ply");
  expectGoodMesh(r, path("all.ply"), surfelsA_ + surfelsB_, std::nullopt);
  EXPECT_EQ(jsonNumber(r.out, "components"), 2.0);
  EXPECT_EQ(jsonNumber(r.out, "euler_characteristic"), 4.0);
}

TEST_F(CliSeeds, EveryAdjacencyPair) {
  for (const std::string pair : {"26-6", "18-6", "6-18", "6-26"}) {
    SCOPED_TRACE(pair);
    const RunResult r = mesh({"--adjacency", pair, "--seed", "26,10,10", "--json"}, "pair" + pair + ".obj");
    expectGoodMesh(r, path("pair" + pair + ".obj"), surfelsB_, std::nullopt);
    EXPECT_EQ(jsonString(r.out, "adjacency"), pair);
  }
}

// --- labels, topology ------------------------------------------------------------------------

TEST_F(Cli, LabelSurfelsEqualTheDirectCount) {
  // Label 2: a thick shell around a cavity of label 3 (two boundaries); label 1: a box.
  DenseImage<std::int16_t> image(Dims{24, 20, 20}, 0);
  addBall<std::int16_t>(image, Voxel{12, 10, 10}, 8, 2);
  addBall<std::int16_t>(image, Voxel{12, 10, 10}, 3, 3);
  for (int z = 1; z < 4; ++z)
    for (int y = 1; y < 5; ++y)
      for (int x = 1; x < 6; ++x) image.at(x, y, z) = 1;
  io::writeVolume(io::AnyVolume(image), path("labels.nrrd"));
  for (int label : {1, 2, 3}) {
    SCOPED_TRACE(label);
    const std::size_t direct = countBoundarySurfels(image, [label](std::int16_t v) { return v == label; });
    const std::string out = path("label" + std::to_string(label) + ".ply");
    const RunResult r = run({"mesh", path("labels.nrrd"), "-o", out, "--label", std::to_string(label), "--all", "--json"});
    expectGoodMesh(r, out, direct, std::nullopt);
    EXPECT_EQ(jsonNumber(r.out, "components"), label == 2 ? 2.0 : 1.0);
    EXPECT_EQ(jsonString(r.out, "mapping"), "midpoint");
  }
}

TEST_F(Cli, EulerCharacteristicAndGenus) {
  // A square ring: a box with a hole through it (genus 1), and a box with two holes (genus 2).
  DenseImage<std::uint8_t> image(Dims{30, 12, 8}, 0);
  for (int z = 2; z <= 5; ++z)
    for (int y = 2; y <= 9; ++y) {
      for (int x = 2; x <= 9; ++x)
        if (!(x >= 4 && x <= 7 && y >= 4 && y <= 7)) image.at(x, y, z) = 1;
      for (int x = 14; x <= 27; ++x)
        if (!(y >= 4 && y <= 7 && ((x >= 16 && x <= 19) || (x >= 22 && x <= 25)))) image.at(x, y, z) = 1;
    }
  io::writeVolume(io::AnyVolume(image), path("rings.mha"));
  RunResult r = run({"mesh", path("rings.mha"), "-o", path("ring.ply"), "--iso", "0.5", "--seed", "2,5,3", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(jsonNumber(r.out, "euler_characteristic"), 0.0);
  EXPECT_EQ(jsonNumber(r.out, "genus"), 1.0);
  r = run({"mesh", path("rings.mha"), "-o", path("ring2.ply"), "--iso", "0.5", "--seed", "20,5,3", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(jsonNumber(r.out, "euler_characteristic"), -2.0);
  EXPECT_EQ(jsonNumber(r.out, "genus"), 2.0);
  r = run({"mesh", path("rings.mha"), "-o", path("both.ply"), "--iso", "0.5", "--all"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Euler characteristic -2 in total; by genus: 1 x1 2 x1"), std::string::npos) << r.out;
}

TEST_F(Cli, SmoothingAndDecimationKeepTheTopology) {
  // The two rings of EulerCharacteristicAndGenus (genus 1 and 2), smoothed and decimated.
  DenseImage<std::uint8_t> image(Dims{30, 12, 8}, 0);
  for (int z = 2; z <= 5; ++z)
    for (int y = 2; y <= 9; ++y) {
      for (int x = 2; x <= 9; ++x)
        if (!(x >= 4 && x <= 7 && y >= 4 && y <= 7)) image.at(x, y, z) = 1;
      for (int x = 14; x <= 27; ++x)
        if (!(y >= 4 && y <= 7 && ((x >= 16 && x <= 19) || (x >= 22 && x <= 25)))) image.at(x, y, z) = 1;
    }
  io::writeVolume(io::AnyVolume(image), path("rings.mha"));
  RunResult plain = run({"mesh", path("rings.mha"), "-o", path("plain.ply"), "--iso", "0.5", "--all", "--json"});
  ASSERT_EQ(plain.code, 0) << plain.err;
  RunResult r = run({"mesh", path("rings.mha"), "--smooth", "-o", path("light.ply"), "--iso", "0.5", "--all",
                     "--max-error", "0.5", "--reduce", "0.6", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(jsonNumber(r.out, "euler_characteristic"), -2.0);
  EXPECT_EQ(jsonNumber(r.out, "components"), 2.0);
  EXPECT_EQ(jsonNumber(r.out, "iterations"), 20.0);  // --smooth without N
  EXPECT_GT(jsonNumber(r.out, "max_vertex_displacement"), 0.0);
  EXPECT_LT(jsonNumber(r.out, "triangles_after"), jsonNumber(r.out, "triangles_before"));
  EXPECT_EQ(jsonNumber(r.out, "triangles_before"), jsonNumber(plain.out, "triangles"));
  EXPECT_LT(jsonNumber(r.out, "triangles"), jsonNumber(plain.out, "triangles"));
  // (Walls two voxels thick lose their corners to smoothing: the change is reported, not bounded.)
  EXPECT_NEAR(jsonNumber(r.out, "volume_change"),
              jsonNumber(r.out, "volume") / jsonNumber(r.out, "extracted_volume") - 1, 1e-6);
  EXPECT_GT(jsonNumber(r.out, "extracted_volume"), 0.0);
  r = run({"mesh", path("rings.mha"), "-o", path("smooth.ply"), "--iso", "0.5", "--all", "--smooth", "5"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* line : {"smoothing   5 Taubin iterations", "volume ", "Euler characteristic -2 in total"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  for (const auto& bad : std::vector<std::vector<std::string>>{
           {"--reduce", "1.5"}, {"--reduce", "-0.1"}, {"--max-error", "0"}, {"--max-error", "x"}, {"--smooth", "0"}}) {
    std::vector<std::string> args{"mesh", path("rings.mha"), "-o", path("bad.ply"), "--iso", "0.5"};
    args.insert(args.end(), bad.begin(), bad.end());
    r = run(args);
    EXPECT_EQ(r.code, 2) << bad[0] << " " << bad[1];
    EXPECT_NE(r.err.find(bad[0]), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// --- output for people and scripts ----------------------------------------------------------

TEST_F(Cli, SummaryJsonAndQuiet) {
  DenseImage<std::uint8_t> image(Dims{16, 16, 16}, 0);
  addBall<std::uint8_t>(image, Voxel{8, 8, 8}, 5, 255);
  io::writeVolume(io::AnyVolume(image), path("ball.nrrd"));
  RunResult r = run({"mesh", path("ball.nrrd"), "-o", path("a.ply")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const char* line : {"image ", "values ", "surface ", "seed ", "mesh ", "topology ", "bbox ", "output ",
                           "timings ", "surfels", "genus 0", "closed 2-manifold", "Otsu"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  EXPECT_LE(std::count(r.out.begin(), r.out.end(), '\n'), 24);  // one screen

  r = run({"mesh", path("ball.nrrd"), "-o", path("b.ply"), "--quiet"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(fs::exists(path("b.ply")));

  r = run({"mesh", path("ball.nrrd"), "-o", path("c.ply"), "--json"});
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.out.front(), '{');
  for (const char* key : {"surfels", "vertices", "triangles", "components", "euler_characteristic", "genus"})
    EXPECT_FALSE(std::isnan(jsonNumber(r.out, key))) << key;
  for (const char* key : {"read", "track", "convert", "write", "total"})
    EXPECT_FALSE(std::isnan(jsonNumber(r.out, key))) << key;

  r = run({"info", path("ball.nrrd")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("16 x 16 x 16"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("uint8"), std::string::npos);
  r = run({"info", path("ball.nrrd"), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(jsonNumber(r.out, "max"), 255.0);
  EXPECT_EQ(jsonNumber(r.out, "otsu"), 127.5);

  r = run({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("usage: surftrack"), std::string::npos);
  r = run({"mesh", "--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--seed-point"), std::string::npos);
}

// A seeded extraction from an uncompressed file maps it and reads the voxels near the surface
// only; a compressed one is decoded. The bytes read are the engine's own count of the voxels it
// asked for (Surface::voxelsRead), checked here against the size of the image.
TEST_F(Cli, SeededExtractionFromAMappedFileReadsLittleOfIt) {
  DenseImage<std::uint16_t> image(Dims{160, 150, 140}, 0);
  addBall<std::uint16_t>(image, Voxel{80, 70, 60}, 9, 1000);
  const std::size_t surfels = surfelsAbove(image, 500);
  for (const std::string name : {"big.nii", "big.nrrd", "big.nii.gz"}) {
    SCOPED_TRACE(name);
    io::writeVolume(io::AnyVolume(image), path(name));
    const RunResult r = run({"mesh", path(name), "-o", path(name + ".ply"), "--iso", "500", "--seed", "80,70,60", "--json"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(jsonNumber(r.out, "surfels"), double(surfels));
    const double total = jsonNumber(r.out, "voxel_bytes"), read = jsonNumber(r.out, "voxel_bytes_read");
    EXPECT_EQ(total, double(image.dims().count() * 2));
    const bool compressed = name.size() > 3 && name.substr(name.size() - 3) == ".gz";
    if (compressed) {
      EXPECT_EQ(read, total);  // decoded whole
      EXPECT_NE(r.out.find("\"mapped\": false"), std::string::npos) << r.out;
    } else {
      EXPECT_GT(read, double(surfels));        // every surfel's two voxels were read
      EXPECT_LT(read, 0.05 * total) << r.out;  // and not much more
      EXPECT_NE(r.out.find("\"mapped\": true"), std::string::npos) << r.out;
      EXPECT_FALSE(std::isnan(jsonNumber(r.out, "voxel_bytes_resident")));
    }
  }
  const RunResult info = run({"info", path("big.nrrd")});
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.out.find("memory-mapped nrrd"), std::string::npos) << info.out;
}

TEST_F(Cli, DemoPhantom) {
  const std::string dir = path("demo");
  const RunResult r = run({"demo", "-o", dir, "--no-mricron", "--size", "48", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(jsonBool(r.out, "closed"), std::optional<bool>(true));
  const double surfels = jsonNumber(r.out, "surfels");
  const MeshCheck c = checkMeshFile(dir + "/phantom.ply");
  ASSERT_TRUE(c.read);
  EXPECT_TRUE(c.closed && c.manifold);
  EXPECT_EQ(double(c.vertices), surfels);
  // The printed equivalent command gives the same surface from the written phantom volume.
  ASSERT_TRUE(fs::exists(dir + "/phantom.nrrd"));
  const std::string command = jsonString(r.out, "command");
  ASSERT_NE(command.find("--seed "), std::string::npos) << command;
  std::string seed = command.substr(command.find("--seed ") + 7);
  seed = seed.substr(0, seed.find(' '));
  const RunResult again = run({"mesh", dir + "/phantom.nrrd", "-o", path("again.ply"), "--iso", "127.5", "--seed",
                               seed, "--json"});
  expectGoodMesh(again, path("again.ply"), std::size_t(surfels), std::nullopt);
  // Without mricron-data the demo says so and still succeeds.
  const RunResult without = run({"demo", "-o", path("demo2"), "--size", "24", "--mricron-dir", path("none")});
  ASSERT_EQ(without.code, 0) << without.err;
  EXPECT_NE(without.out.find("mricron-data is not installed"), std::string::npos) << without.out;
  EXPECT_NE(without.out.find("demo: 1 mesh written to"), std::string::npos) << without.out;
}

// --- bad input: a clear one-line error, a non-zero exit, no file left behind ----------------

TEST_F(Cli, MissingFile) {
  expectFailure({"mesh", path("nope.nii.gz"), "-o", path("out.ply")}, 1, "no such file");
  expectFailure({"info", path("nope.nrrd")}, 1, "no such file");
  expectFailure({"mesh", path("nope.raw"), "-o", path("out.ply"), "--raw-dims", "2,2,2", "--raw-type", "uint8"}, 1,
                "no such file");
}

TEST_F(Cli, UnreadableFile) {
  {
    std::ofstream(path("garbage.nrrd")) << "this is not an image\n";
    std::ofstream(path("garbage.nii.gz")) << "neither is this";
    std::ofstream(path("garbage.dat")) << "nor this";
    std::ofstream(path("empty.nii"));
  }
  expectFailure({"mesh", path("garbage.nrrd"), "-o", path("out.ply")}, 1, "garbage.nrrd");
  expectFailure({"mesh", path("garbage.nii.gz"), "-o", path("out.ply")}, 1, "cannot read");
  expectFailure({"mesh", path("garbage.dat"), "-o", path("out.ply")}, 1, "not a recognised image file");
  expectFailure({"mesh", path("empty.nii"), "-o", path("out.ply")}, 1, "empty");
  fs::create_directories(work_ / "nodicom");
  expectFailure({"mesh", path("nodicom"), "-o", path("out.ply")}, 1, "no DICOM series");
  if (!isRoot()) {  // root reads files whatever their permissions
    DenseImage<std::uint8_t> image(Dims{4, 4, 4}, 1);
    io::writeVolume(io::AnyVolume(image), path("locked.nrrd"));
    fs::permissions(path("locked.nrrd"), fs::perms::none);
    expectFailure({"mesh", path("locked.nrrd"), "-o", path("out.ply")}, 1, "cannot open");
  }
}

TEST_F(Cli, TruncatedFile) {
  DenseImage<std::int16_t> image(Dims{20, 20, 20}, 0);
  addBall<std::int16_t>(image, Voxel{10, 10, 10}, 6, 100);
  auto truncate = [](const fs::path& p) { fs::resize_file(p, fs::file_size(p) / 2); };
  for (const std::string ext : {".nii", ".nii.gz", ".nrrd", ".mha"}) {
    const std::string in = path("cut" + ext);
    io::writeVolume(io::AnyVolume(image), in);
    truncate(in);
    SCOPED_TRACE(ext);
    expectFailure({"mesh", in, "-o", path("out.ply"), "--iso", "50"}, 1, "cut" + ext);
  }
  // A detached header whose data file is cut short.
  io::writeVolume(io::AnyVolume(image), path("cut.mhd"));
  truncate(work_ / "cut.raw");
  expectFailure({"mesh", path("cut.mhd"), "-o", path("out.ply"), "--iso", "50"}, 1, "truncated");
  io::writeVolume(io::AnyVolume(image), path("cutn.nhdr"));
  for (const auto& e : fs::directory_iterator(work_))
    if (e.path().filename().string().rfind("cutn.", 0) == 0 && e.path().extension() != ".nhdr") truncate(e.path());
  expectFailure({"mesh", path("cutn.nhdr"), "-o", path("out.ply"), "--iso", "50"}, 1, "cutn.nhdr");
  // A raw file shorter than its stated size.
  { std::ofstream(path("short.raw"), std::ios::binary) << std::string(100, '\1'); }
  expectFailure({"mesh", path("short.raw"), "-o", path("out.ply"), "--raw-dims", "10,10,10", "--raw-type", "uint8"},
                1, "truncated");
}

// Every one of the ten scalar types reads and gives the surface of the same ball; a type
// outside them is refused.
TEST_F(Cli, EveryScalarTypeGivesTheSameSurface) {
  double surfels = -1;
  auto ball = [&](auto zero, const std::string& name) {
    using T = decltype(zero);
    DenseImage<T> image(Dims{12, 12, 12}, T(0));
    addBall<T>(image, Voxel{6, 6, 6}, 3, T(100));
    io::writeVolume(io::AnyVolume(image), path(name));
    const RunResult r = run({"mesh", path(name), "-o", path("out.ply"), "--iso", "50", "--json"});
    ASSERT_EQ(r.code, 0) << name << ": " << r.err;
    EXPECT_NE(r.out.find("\"type\": \"" + toString(scalarTypeOf<T>()) + "\""), std::string::npos) << r.out;
    if (surfels < 0) surfels = jsonNumber(r.out, "surfels");
    EXPECT_EQ(jsonNumber(r.out, "surfels"), surfels) << name;
  };
  ball(std::uint8_t{}, "u8.nrrd");
  ball(std::int8_t{}, "i8.nrrd");
  ball(std::uint16_t{}, "u16.nrrd");
  ball(std::int16_t{}, "i16.nrrd");
  ball(std::uint32_t{}, "u32.nrrd");
  ball(std::int32_t{}, "i32.nrrd");
  ball(std::uint64_t{}, "u64.nrrd");
  ball(std::int64_t{}, "i64.nrrd");
  ball(float{}, "f32.nrrd");
  ball(double{}, "f64.nrrd");
  EXPECT_GT(surfels, 0);
  { std::ofstream(path("x.raw"), std::ios::binary) << std::string(8, '\0'); }
  expectFailure({"mesh", path("x.raw"), "-o", path("out.ply"), "--raw-dims", "2,2,2", "--raw-type", "complex"}, 2,
                "unsupported voxel type");
}

class CliErrors : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    DenseImage<std::uint8_t> image(Dims{20, 20, 20}, 10);
    addBall<std::uint8_t>(image, Voxel{4, 4, 4}, 2, 200);
    input_ = path("small.nrrd");
    io::writeVolume(io::AnyVolume(image), input_);
  }
  std::string input_;
};

TEST_F(CliErrors, IsoValueOutsideTheDataRange) {
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "200"}, 1, "outside the data range [10, 200]");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "1e6"}, 1, "no voxel is above it");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "-3"}, 1, "every voxel would be inside");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "nan"}, 2, "not a number");
}

TEST_F(CliErrors, SeedOutsideTheDomain) {
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed", "20,0,0"}, 1,
                "seed voxel (20,0,0) lies outside the image domain [0,20)x[0,20)x[0,20)");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed", "-1,5,5"}, 1, "outside the image");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed-point", "1000,0,0"}, 1,
                "outside the image");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed", "25,1,1,+x"}, 1,
                "outside the image domain");
}

TEST_F(CliErrors, SeedNotOnAnyBoundary) {
  // The ball occupies [2, 6]^3: no axis ray from (12,12,12) meets it.
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed-ray", "12,12,12"}, 1,
                "seed voxel (12,12,12) is not on any boundary");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "250", "--seed", "12,12,12"}, 1,
                "no voxel is above it");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed", "12,12,12,+y"}, 1,
                "is not a boundary surfel");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed", "4,4,4,+x"}, 1,
                "is not a boundary surfel");
}

TEST_F(CliErrors, EmptySelection) {
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--label", "7"}, 1, "empty selection: label 7 does not occur");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--label", "7", "--all"}, 1, "empty selection");
  DenseImage<float> flat(Dims{5, 5, 5}, 3.5f);
  io::writeVolume(io::AnyVolume(flat), path("flat.nrrd"));
  expectFailure({"mesh", path("flat.nrrd"), "-o", path("out.ply")}, 1, "constant");
}

TEST_F(CliErrors, OutputCannotBeWritten) {
  expectFailure({"mesh", input_, "-o", path("missing/out.ply"), "--iso", "100"}, 1, "does not exist");
  fs::create_directories(work_ / "adir.ply");
  expectFailure({"mesh", input_, "-o", path("adir.ply"), "--iso", "100"}, 1, "is a directory");
  expectFailure({"mesh", input_, "-o", path("out.xyz"), "--iso", "100"}, 2, "unknown mesh format '.xyz'");
  expectFailure({"mesh", input_, "-o", path("noext"), "--iso", "100"}, 2, "unknown mesh format");
  // A failed run leaves an existing output untouched.
  { std::ofstream(path("keep.ply")) << "old content"; }
  expectFailure({"mesh", input_, "-o", path("keep.ply"), "--iso", "1000"}, 1, "outside the data range");
  EXPECT_EQ(readText(path("keep.ply")), "old content");
  if (!isRoot()) {
    fs::create_directories(work_ / "ro");
    fs::permissions(work_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    expectFailure({"mesh", input_, "-o", path("ro/out.ply"), "--iso", "100"}, 1, "not writable");
  }
  // The demo directory cannot be created under a file.
  expectFailure({"demo", "-o", path("keep.ply/sub"), "--no-mricron", "--size", "16"}, 1, "cannot create");
}

TEST_F(CliErrors, UsageErrors) {
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--frobnicate"}, 2, "unknown option '--frobnicate'");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "1", "--label", "2"}, 2, "not both");
  expectFailure({"mesh", input_}, 2, "missing the output mesh");
  expectFailure({"mesh", "-o", path("out.ply")}, 2, "missing the input volume");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--seed", "1,2"}, 2, "--seed");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--seed", "1,2,3", "--all"}, 2, "only one of");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--adjacency", "6-6"}, 2, "unsupported adjacency pair");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--mapping", "cubic"}, 2, "--mapping");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--label", "1", "--mapping", "linear"}, 2, "needs --iso");
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--raw-type", "uint8"}, 2, "need --raw-dims");
  expectFailure({"frobnicate"}, 2, "unknown command 'frobnicate'");
}

// --- outputs that are inputs, the output directory check, geometry, seed distance -------------

/// Writes the voxels of `image` as a headerless raw file (x fastest, then y, then z).
template <class T>
void writeRaw(const std::string& file, const DenseImage<T>& image) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(image.data().data()), std::streamsize(image.data().size() * sizeof(T)));
}

TEST_F(Cli, AnOutputThatIsTheInputIsRefused) {
  const DenseImage<std::uint8_t> image = boxVolume<std::uint8_t>(Dims{16, 16, 16}, Voxel{4, 4, 4}, Voxel{10, 10, 10}, 9, 0);
  const std::string in = path("rawin.ply");  // a raw volume under a mesh's name
  writeRaw(in, image);
  const std::string bytes = readText(in);
  auto raw = [](std::vector<std::string> args) {
    for (const char* a : {"--raw-dims", "16,16,16", "--raw-type", "uint8"}) args.push_back(a);
    return args;
  };
  // The same name, another spelling of it, a symbolic link and a hard link to it.
  fs::create_symlink(in, path("symlink.ply"));
  fs::create_hard_link(in, path("hardlink.ply"));
  for (const std::string& out : {in, (work_ / "." / "rawin.ply").string(), path("symlink.ply"), path("hardlink.ply")}) {
    expectFailure(raw({"mesh", in, "--label", "9", "-o", out}), 1, "is the input file");
    expectFailure(raw({"labels", in, "-o", out}), 1, "is the input file");
  }
  // labels: the table, a file of a pattern, the label names.
  fs::copy_file(in, path("vol.csv"));
  expectFailure(raw({"labels", path("vol.csv"), "-o", path("out/"), "--table", path("vol.csv")}), 1,
                "is the input file");
  fs::copy_file(in, path("9.ply"));
  expectFailure(raw({"labels", path("9.ply"), "-o", path("{label}.ply")}), 1, "is the input file");
  std::ofstream(path("names.csv")) << "9 box\n";
  expectFailure(raw({"labels", in, "-o", path("out/"), "--label-names", path("names.csv"), "--table", path("names.csv")}),
                1, "is the input file");
  for (const char* file : {"rawin.ply", "vol.csv", "9.ply"}) EXPECT_EQ(readText(path(file)), bytes) << file;
  EXPECT_EQ(readText(path("names.csv")), "9 box\n");
  // Another file of the same name is an ordinary output.
  fs::create_directories(work_ / "other");
  const RunResult r = run(raw({"mesh", in, "--label", "9", "-o", path("other/rawin.ply"), "--json"}));
  expectGoodMesh(r, path("other/rawin.ply"), countBoundarySurfels(image, [](std::uint8_t v) { return v == 9; }),
                 std::nullopt);
  EXPECT_EQ(readText(in), bytes);
}

TEST_F(Cli, AnOutputDirectoryIsCheckedWithoutAFileNameInIt) {
  DenseImage<std::uint16_t> image = boxVolume<std::uint16_t>(Dims{12, 12, 12}, Voxel{1, 1, 1}, Voxel{4, 4, 4}, 1, 0);
  for (int z = 6; z < 10; ++z)
    for (int y = 6; y < 10; ++y)
      for (int x = 6; x < 10; ++x) image.at(x, y, z) = 2;
  const std::string in = path("labels.nrrd");
  io::writeVolume(io::AnyVolume(image), in);
  // Anything named "probe" next to the output directory, or named as a pattern's file of label
  // 0, is no obstacle.
  fs::create_directories(work_ / "data" / "probe");
  const RunResult r = run({"labels", in, "-o", path("data/abc/"), "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listDirectory(path("data/abc")), (std::vector<std::string>{"label_1.ply", "label_2.ply", "labels.csv"}));
  EXPECT_EQ(listDirectory(path("data")), (std::vector<std::string>{"abc", "probe"}));
  fs::create_directories(work_ / "pattern" / "mesh-0.ply");
  const RunResult p = run({"labels", in, "-o", path("pattern/mesh-{label}.ply"), "--quiet"});
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(listDirectory(path("pattern")), (std::vector<std::string>{"mesh-0.ply", "mesh-1.ply", "mesh-2.ply"}));
  // The directory is still checked: missing, or not writable.
  expectFailure({"labels", in, "-o", path("missing/abc/")}, 1, "does not exist");
  expectFailure({"labels", in, "-o", path("missing/mesh-{label}.ply")}, 1, "does not exist");
  if (!isRoot()) {
    fs::create_directories(work_ / "ro");
    fs::permissions(work_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    expectFailure({"labels", in, "-o", path("ro/abc/")}, 1, "not writable");
    expectFailure({"labels", in, "-o", path("ro/mesh-{label}.ply")}, 1, "not writable");
  }
}

TEST_F(CliErrors, AGeometryBeyondTheFloatRangeIsRefused) {
  // 1e300: the vertices would be inf; 1e38: finite doubles, but beyond the floats of the file.
  for (const char* spacing : {"1e300,1e300,1e300", "1,1e38,1"}) {
    for (const char* rule : {"--largest", "--all"})
      expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", rule, "--spacing", spacing}, 1,
                    "put vertices beyond the float range");
    expectFailure({"mesh", input_, "-o", path("out.ply"), "--iso", "100", "--seed", "4,4,4", "--spacing", spacing}, 1,
                  "put vertices beyond the float range");
    expectFailure({"labels", input_, "-o", path("out/"), "--spacing", spacing}, 1, "put vertices beyond the float range");
  }
  expectFailure({"mesh", input_, "-o", path("out.ply"), "--label", "200", "--origin", "0,-1e39,0"}, 1,
                "put vertices beyond the float range");
  // Large but within the range: written, every vertex finite.
  const RunResult r = run({"mesh", input_, "-o", path("big.ply"), "--iso", "100", "--spacing", "1e36,1e36,1e36", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const MeshCheck c = checkMeshFile(path("big.ply"));
  ASSERT_TRUE(c.read);
  for (int a = 0; a < 3; ++a) EXPECT_TRUE(std::isfinite(c.min[a]) && std::isfinite(c.max[a]));
  EXPECT_GT(c.max[0], 1e36);
}

TEST_F(Cli, TheNearestSurfelSeedSearchIsBounded) {
  // A box at x in [0, 3] of a 600 voxels long raw file: the seed (599,4,4) is 595.5 voxels from
  // its face at x = 3.5.
  const DenseImage<std::uint8_t> image = boxVolume<std::uint8_t>(Dims{600, 8, 8}, Voxel{0, 2, 2}, Voxel{3, 5, 5}, 200, 0);
  const std::string in = path("long.raw");
  writeRaw(in, image);
  auto mesh = [&](const std::string& out, std::vector<std::string> extra) {
    std::vector<std::string> args = {"mesh", in, "--raw-dims", "600,8,8", "--raw-type", "uint8", "--iso", "100",
                                     "-o", path(out)};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  expectFailure(mesh("out.ply", {"--seed", "599,4,4"}), 1, "has no boundary surfel within 256 voxels");
  expectFailure(mesh("out.ply", {"--seed", "599,4,4"}), 1, "--max-seed-distance");
  expectFailure(mesh("out.ply", {"--seed-point", "599,4,4", "--max-seed-distance", "595"}), 1,
                "has no boundary surfel within 595 voxels");
  // Within the distance: the box, as --largest gives it.
  const RunResult r = run(mesh("seeded.ply", {"--seed", "599,4,4", "--max-seed-distance", "596", "--json"}));
  expectGoodMesh(r, path("seeded.ply"), surfelsAbove(image, 100), std::nullopt);
  EXPECT_EQ(jsonNumber(r.out, "distance"), 595.5);
  const RunResult largest = run(mesh("largest.ply", {"--largest", "--quiet"}));
  ASSERT_EQ(largest.code, 0) << largest.err;
  EXPECT_EQ(readText(path("seeded.ply")), readText(path("largest.ply")));
  expectFailure(mesh("out.ply", {"--seed", "599,4,4", "--max-seed-distance", "0"}), 2, "positive number of voxels");
  expectFailure(mesh("out.ply", {"--seed", "599,4,4", "--max-seed-distance", "far"}), 2, "positive number of voxels");
}

TEST_F(Cli, ASeedFarFromEveryObjectFailsHavingReadOnlyNearIt) {
  // A 128 MiB memory-mapped raw file (sparse), 256 x 256 x 2048, one box at z < 8; the seed at
  // z = 2000. The error comes from the voxels within 256 voxels of it — the planes z >= 1736,
  // a seventh of the file's pages (z is the slowest axis) — not from all of them.
  const std::string big = path("big.raw");
  const std::uintmax_t bytes = std::uintmax_t(256) * 256 * 2048;
  {
    std::ofstream out(big, std::ios::binary);
    const std::string row(10, char(200));
    for (int z = 0; z < 8; ++z)
      for (int y = 100; y < 110; ++y) {
        out.seekp(std::streamoff((std::uintmax_t(z) * 256 + y) * 256 + 100));
        out.write(row.data(), std::streamsize(row.size()));
      }
  }
  fs::resize_file(big, bytes);
  auto maxResident = [&](const std::vector<std::string>& args, RunResult& r) {
    struct rusage usage {};
    const pid_t pid = startTool(args, scratch_);
    r = finishTool(pid, scratch_, &usage);
    return std::uintmax_t(usage.ru_maxrss) * 1024;  // (kilobytes on Linux)
  };
  RunResult small, far;
  // The process's own footprint: the same command on a 1 MiB file.
  std::ofstream(path("small.raw"), std::ios::binary) << std::string(1 << 20, '\0');
  const std::uintmax_t baseline = maxResident(
      {"mesh", path("small.raw"), "--raw-dims", "1024,32,32", "--raw-type", "uint8", "--iso", "100", "--seed",
       "1000,16,16", "-o", path("out.ply")},
      small);
  EXPECT_EQ(small.code, 1) << small.err;
  const std::uintmax_t resident = maxResident(
      {"mesh", big, "--raw-dims", "256,256,2048", "--raw-type", "uint8", "--iso", "100", "--seed", "128,128,2000",
       "-o", path("out.ply")},
      far);
  EXPECT_EQ(far.code, 1) << far.err;
  EXPECT_NE(far.err.find("has no boundary surfel within 256 voxels"), std::string::npos) << far.err;
  EXPECT_LT(resident, baseline + bytes / 3) << "resident " << resident << " bytes, baseline " << baseline;
}

// --- surftrack info: quantiles against numpy ------------------------------------------------

/// numpy.quantile(values of the raw file, qs) by /usr/bin/python3, one value a line; empty if
/// python3 or numpy is missing.
std::vector<double> numpyQuantiles(const fs::path& raw, const std::string& dtype, const std::vector<double>& qs,
                                   const fs::path& scratch) {
  std::ostringstream script;
  script << "import numpy as np\n"
         << "a = np.fromfile('" << raw.string() << "', dtype='" << dtype << "')\n"
         << "for q in [";
  for (double q : qs) script << q << ",";
  script << "]: print(repr(float(np.quantile(a, q))))\n";
  const fs::path file = scratch / "quantiles.py";
  std::ofstream(file) << script.str();
  const std::string cmd = "/usr/bin/python3 " + shellQuote(file.string()) + " 2>/dev/null";
  std::vector<double> values;
  if (FILE* pipe = ::popen(cmd.c_str(), "r")) {
    char line[128];
    while (std::fgets(line, sizeof line, pipe)) values.push_back(std::strtod(line, nullptr));
    ::pclose(pipe);
  }
  return values;
}

TEST_F(Cli, InfoQuantilesAreNumpys) {
  if (std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 with numpy is needed (apt-get install python3-numpy)";
  const std::vector<double> qs = {0.01, 0.25, 0.5, 0.75, 0.99};
  std::mt19937_64 rng(20260118);
  // Each case: a raw file of random values of one type; numpy's dtype name.
  auto check = [&](const std::string& type, const std::string& dtype, auto image, double relative) {
    SCOPED_TRACE(type);
    const std::string file = path(type + ".raw");
    writeRaw(file, image);
    const std::vector<double> expected = numpyQuantiles(file, dtype, qs, scratch_);
    ASSERT_EQ(expected.size(), qs.size()) << "numpy failed";
    const Dims& d = image.dims();
    const RunResult r = run({"info", file, "--raw-dims",
                             std::to_string(d.nx) + "," + std::to_string(d.ny) + "," + std::to_string(d.nz),
                             "--raw-type", type, "--json"});
    ASSERT_EQ(r.code, 0) << r.err;
    const double range = jsonNumber(r.out, "max") - jsonNumber(r.out, "min");
    std::smatch m;
    std::string rest = r.out.substr(r.out.find("\"quantiles\""));
    for (std::size_t i = 0; i < qs.size(); ++i) {
      ASSERT_TRUE(std::regex_search(rest, m, std::regex("\"value\": (-?[0-9.eE+-]+)"))) << r.out;
      EXPECT_NEAR(std::stod(m[1]), expected[i], relative * range) << "q " << qs[i];
      rest = m.suffix();
    }
  };
  // The values 0..9, a tenth each: numpy gives 0, 2, 4.5, 7 and 9 (not 1, 3, 5, 8, 9).
  DenseImage<std::uint8_t> tenths(Dims{10, 10, 10}, 0);
  for (std::size_t i = 0; i < tenths.data().size(); ++i) tenths.data()[i] = std::uint8_t(i % 10);
  check("uint8", "u1", tenths, 1e-15);
  auto random = [&](auto zero, Dims d, auto draw) {
    DenseImage<decltype(zero)> image(d, zero);
    for (auto& v : image.data()) v = decltype(zero)(draw());
    return image;
  };
  std::uniform_int_distribution<int> i16(-30000, 30000);
  check("int16", "<i2", random(std::int16_t{}, Dims{13, 11, 7}, [&] { return i16(rng); }), 1e-15);
  check("uint32", "<u4", random(std::uint32_t{}, Dims{17, 9, 8}, [&] { return rng() >> 32; }), 1e-15);
  std::uniform_int_distribution<std::int64_t> i64(-(std::int64_t(1) << 50), std::int64_t(1) << 50);
  check("int64", "<i8", random(std::int64_t{}, Dims{9, 9, 9}, [&] { return i64(rng); }), 1e-15);
  std::normal_distribution<double> normal(0, 100);
  check("float", "<f4", random(float{}, Dims{15, 14, 6}, [&] { return normal(rng); }), 1e-6);
  check("double", "<f8", random(double{}, Dims{8, 8, 11}, [&] { return normal(rng) * 1e-3; }), 1e-15);
}

// --- the real MRI volumes of mricron-data ----------------------------------------------------

const fs::path kMricron = "/usr/share/mricron/templates";

TEST_F(Cli, MricronDemoSurfacesAreClosedManifolds) {
  if (!fs::exists(kMricron / "ch2better.nii.gz") || !fs::exists(kMricron / "aal.nii.gz"))
    GTEST_SKIP() << "mricron-data is not installed (" << kMricron << "): apt-get install mricron-data";
  const std::string dir = path("demo");
  const RunResult r = run({"demo", "-o", dir, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  // The results, one JSON object each, in the order phantom, cortex, atlas region.
  std::vector<std::string> results;
  for (std::size_t at = r.out.find("\"name\": "); at != std::string::npos;) {
    const std::size_t next = r.out.find("\"name\": ", at + 1);
    results.push_back(r.out.substr(at, next == std::string::npos ? std::string::npos : next - at));
    at = next;
  }
  ASSERT_EQ(results.size(), 3u) << r.out;
  const std::vector<std::string> meshes = {"phantom.ply", "cortex.ply", "aal-Precentral_L.ply"};
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(meshes[i]);
    const std::string& json = results[i];
    EXPECT_NE(json.find(meshes[i]), std::string::npos);
    const MeshCheck c = checkMeshFile(dir + "/" + meshes[i]);
    ASSERT_TRUE(c.read);
    EXPECT_TRUE(c.closed);
    EXPECT_TRUE(c.manifold);
    EXPECT_EQ(double(c.vertices), jsonNumber(json, "surfels"));
    EXPECT_EQ(double(c.faces), jsonNumber(json, "triangles"));
    EXPECT_EQ(jsonBool(json, "closed"), std::optional<bool>(true));
    EXPECT_EQ(jsonNumber(json, "components"), 1.0);
  }
  EXPECT_EQ(r.out.find("mricron-data is not installed"), std::string::npos);
  // The whole atlas, one closed mesh per region, named from aal.nii.txt.
  const std::vector<std::string> regions = listDirectory(dir + "/aal-regions");
  EXPECT_EQ(regions.size(), 117u);  // 116 regions and labels.csv
  EXPECT_EQ(jsonNumber(r.out, "regions"), 116.0);
  EXPECT_TRUE(fs::exists(dir + "/aal-regions/1_Precentral_L.ply"));
  EXPECT_TRUE(fs::exists(dir + "/aal-regions/116_Vermis_10.ply"));
  for (const std::string& file : {"1_Precentral_L.ply", "116_Vermis_10.ply"}) {
    const MeshCheck c = checkMeshFile(dir + "/aal-regions/" + file);
    EXPECT_TRUE(c.read && c.closed && c.manifold) << file;
  }
}

TEST_F(Cli, MricronLabelSurfelsEqualTheDirectCount) {
  const fs::path atlas = kMricron / "aal.nii.gz";
  if (!fs::exists(atlas)) GTEST_SKIP() << "mricron-data is not installed (" << atlas << "): apt-get install mricron-data";
  const io::AnyVolume volume = io::readVolume(atlas.string());
  ASSERT_EQ(io::scalarTypeOf(volume), io::ScalarType::UInt8);
  const auto& image = std::get<DenseImage<std::uint8_t>>(volume);
  for (int label : {1, 2, 37, 116}) {
    SCOPED_TRACE(label);
    const std::size_t direct = countBoundarySurfels(image, [label](std::uint8_t v) { return v == label; });
    ASSERT_GT(direct, 0u);
    const std::string out = path("aal" + std::to_string(label) + ".ply");
    const RunResult r = run({"mesh", atlas.string(), "-o", out, "--label", std::to_string(label), "--all", "--json"});
    expectGoodMesh(r, out, direct, std::nullopt);
  }
}


// --- surftrack labels ------------------------------------------------------------------------

/// Three touching balls of labels 1, 2 and 7 on background 0, a box of label 9 at the border.
DenseImage<std::uint16_t> labelBalls() {
  DenseImage<std::uint16_t> image(Dims{24, 20, 18}, 0);
  addBall(image, Voxel{7, 9, 8}, 5, std::uint16_t(1));
  addBall(image, Voxel{14, 9, 8}, 4, std::uint16_t(2));
  addBall(image, Voxel{11, 14, 10}, 3, std::uint16_t(7));
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 18; x < 24; ++x) image.at(x, y, z) = 9;
  return image;
}

TEST_F(Cli, LabelsWritesADirectoryOfClosedMeshesAndATable) {
  const DenseImage<std::uint16_t> image = labelBalls();
  const std::string in = path("labels.nrrd"), names = path("names.txt");
  io::writeVolume(io::AnyVolume(image), in);
  std::ofstream(names) << "# value name\n1 Left_thing\n2 Right 99\n7 Middle 1234\n";
  const std::string dir = path("out/"), table = path("table.json");
  const RunResult r = run({"labels", in, "--walls", "independent", "-o", dir, "--label-names", names, "--table", table, "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::map<int, std::string> files = {{1, "1_Left_thing.ply"}, {2, "2_Right.ply"},
                                            {7, "7_Middle.ply"}, {9, "9_label9.ply"}};
  std::vector<std::string> expected = {"labels.csv"};
  for (const auto& [label, file] : files) expected.push_back(file);
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(listDirectory(path("out")), expected);
  for (const auto& [label, file] : files) {
    SCOPED_TRACE(file);
    const std::size_t direct = countBoundarySurfels(image, [l = label](std::uint16_t v) { return v == l; });
    const MeshCheck c = checkMeshFile(path("out") + "/" + file);
    ASSERT_TRUE(c.read);
    EXPECT_TRUE(c.closed);
    EXPECT_TRUE(c.manifold);
    EXPECT_EQ(c.vertices, direct);
    EXPECT_NE(r.out.find("\"surfels\": " + std::to_string(direct)), std::string::npos) << r.out;
  }
  const std::string json = readText(table), csv = readText(path("out/labels.csv"));
  EXPECT_NE(json.find("\"name\": \"Right\""), std::string::npos) << json;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5) << csv;
  EXPECT_NE(csv.find("9,label9,120,120,"), std::string::npos) << csv;  // 6 x 5 x 4 voxels
}

TEST_F(Cli, LabelsWritesOnePlyWithALabelPerFaceAndPatterns) {
  const DenseImage<std::uint16_t> image = labelBalls();
  const std::string in = path("labels.nrrd");
  io::writeVolume(io::AnyVolume(image), in);
  const RunResult r = run({"labels", in, "--walls", "independent", "-o", path("all.ply"), "--labels", "1,7", "--ascii", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::size_t s1 = countBoundarySurfels(image, [](std::uint16_t v) { return v == 1; });
  const std::size_t s7 = countBoundarySurfels(image, [](std::uint16_t v) { return v == 7; });
  const std::string ply = readText(path("all.ply"));
  EXPECT_NE(ply.find("element vertex " + std::to_string(s1 + s7) + "\n"), std::string::npos);
  EXPECT_NE(ply.find("property int label\nend_header"), std::string::npos);
  // Every face line ends with its label: count the faces of each.
  std::istringstream lines(ply.substr(ply.find("end_header\n") + 11));
  std::string line;
  std::map<int, std::size_t> faces, vertices;
  while (std::getline(lines, line)) {
    std::istringstream f(line);
    std::vector<double> v;
    for (double x; f >> x;) v.push_back(x);
    if (v.size() == 4) ++vertices[int(v[3])];
    if (v.size() == 5) ++faces[int(v[4])];
  }
  EXPECT_EQ(vertices[1], s1);
  EXPECT_EQ(vertices[7], s7);
  EXPECT_EQ(faces[1], 2 * s1 - 4);  // one sphere each: F = 2V - 4
  EXPECT_EQ(faces[7], 2 * s7 - 4);

  const RunResult p = run({"labels", in, "--walls", "independent", "-o", path("mesh-{label}.obj"), "--labels", "2-7", "--quiet"});
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_TRUE(fs::exists(path("mesh-2.obj")));
  EXPECT_TRUE(fs::exists(path("mesh-7.obj")));
  EXPECT_FALSE(fs::exists(path("mesh-9.obj")));
}

TEST_F(Cli, LabelsPatternFailingMidwayLeavesNoFile) {
  const DenseImage<std::uint16_t> image = labelBalls();
  const std::string in = path("labels.nrrd");
  io::writeVolume(io::AnyVolume(image), in);
  fs::create_directories(path("pattern"));
  std::ofstream(path("pattern/mesh-1.ply")) << "old";  // an old output, to be kept as it is
  // Label 7's target is a directory: the labels before it are written, then the run fails.
  fs::create_directories(path("pattern/mesh-7.ply"));
  expectFailure({"labels", in, "--walls", "independent", "-o", path("pattern/mesh-{label}.ply")}, 1, "is a directory");
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(path("pattern"))) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"mesh-1.ply", "mesh-7.ply"})) << "no new file, no temporary";
  EXPECT_EQ(readText(path("pattern/mesh-1.ply")), "old");
  // Without the obstacle the same run replaces the old output and writes every label.
  fs::remove(path("pattern/mesh-7.ply"));
  const RunResult r = run({"labels", in, "-o", path("pattern/mesh-{label}.ply"), "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(readText(path("pattern/mesh-1.ply")), "old");
  EXPECT_TRUE(fs::exists(path("pattern/mesh-7.ply")));
}

TEST_F(Cli, LabelsBadInputIsOneLineAndLeavesNothing) {
  const DenseImage<std::uint16_t> image = labelBalls();
  const std::string in = path("labels.nrrd"), floats = path("floats.nrrd");
  io::writeVolume(io::AnyVolume(image), in);
  io::writeVolume(io::AnyVolume(DenseImage<float>(Dims{4, 4, 4}, 1.0f)), floats);
  fs::create_directories(path("full"));
  std::ofstream(path("full/x")) << "x";
  expectFailure({"labels", floats, "-o", path("out/")}, 1, "a label image needs integer voxels");
  expectFailure({"labels", in, "-o", path("out/"), "--labels", "42"}, 1, "label 42 does not occur");
  expectFailure({"labels", in, "-o", path("out/"), "--labels", "3-6"}, 1, "empty selection");
  expectFailure({"labels", in, "-o", path("out/"), "--label-names", path("missing.txt")}, 1,
                "cannot read label names");
  expectFailure({"labels", in, "-o", path("full/")}, 1, "not empty");
  expectFailure({"labels", in, "-o", path("all.obj")}, 2, "must be .ply");
  expectFailure({"labels", in, "-o", path("x-{name}.ply"), "--label-names", path("names.txt")}, 1,
                "cannot read label names");
  expectFailure({"labels", in, "-o", path("out/"), "--labels", "1,x"}, 2, "not an integer label");
  expectFailure({"labels", in, "-o", path("out/"), "--seed", "0,0,0"}, 1, "background");
  expectFailure({"labels", in, "-o", path("nowhere/{label}.ply")}, 1, "does not exist");
}

// --- interrupted runs --------------------------------------------------------------------------

/// Polls `dir` (every 0.2 ms, up to a minute) until `seen(name, path)` holds for one of its
/// entries, then sends `signal` to the tool `pid`. False if the tool ended before that.
template <class Seen>
bool interruptWhen(pid_t pid, const fs::path& dir, int signal, Seen seen) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      if (seen(it->path().filename().string(), it->path())) {
        ::kill(pid, signal);
        return true;
      }
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;  // (reaped: finishTool is not called)
    ::usleep(200);
  }
  ::kill(pid, SIGKILL);
  return false;
}

/// 8000 labels: a 60^3 volume of 3x3x3 blocks, each its own label; writing their meshes takes
/// long enough to be interrupted.
DenseImage<std::uint16_t> manyLabels() {
  DenseImage<std::uint16_t> image(Dims{60, 60, 60}, 0);
  for (int z = 0; z < 60; ++z)
    for (int y = 0; y < 60; ++y)
      for (int x = 0; x < 60; ++x) image.at(x, y, z) = std::uint16_t(1 + x / 3 + 20 * (y / 3) + 400 * (z / 3));
  return image;
}

TEST_F(Cli, AnInterruptedLabelsRunLeavesNoTemporary) {
  const std::string in = path("many.nrrd");
  io::writeVolume(io::AnyVolume(manyLabels()), in);
  auto isStaging = [](const std::string& name) { return name.rfind(".out.tmp-", 0) == 0; };
  // SIGINT while the meshes are written into the staging directory; SIGTERM as soon as it
  // exists (reading or extracting); SIGINT while a pattern's temporaries are written.
  struct Case {
    int signal;
    std::string output;
    std::function<bool(const std::string&, const fs::path&)> seen;
  };
  const std::vector<Case> cases = {
      {SIGINT, path("out/"), [&](const std::string& name, const fs::path& p) {
         std::error_code ec;
         return isStaging(name) && !fs::is_empty(p, ec) && !ec;
       }},
      {SIGTERM, path("out/"), [&](const std::string& name, const fs::path&) { return isStaging(name); }},
      {SIGINT, path("mesh-{label}.ply"), [](const std::string& name, const fs::path&) { return name.rfind(".mesh-", 0) == 0; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.output + ", signal " + std::to_string(c.signal));
    const pid_t pid = startTool({"labels", in, "-o", c.output, "--quiet"}, scratch_);
    ASSERT_GT(pid, 0);
    ASSERT_TRUE(interruptWhen(pid, work_, c.signal, c.seen)) << "the run ended before it could be interrupted";
    const RunResult r = finishTool(pid, scratch_);
    EXPECT_EQ(r.code, 128 + c.signal) << r.err;
    EXPECT_EQ(r.err, c.signal == SIGINT ? "surftrack: interrupted\n" : "surftrack: terminated\n");
    EXPECT_EQ(listDirectory(work_), std::vector<std::string>{"many.nrrd"}) << "no output, no temporary";
  }
}

TEST_F(Cli, AnInterruptedMeshWriteLeavesNoTemporary) {
  // Noise: about 800 000 surfels, written as a text PLY of some 50 MB.
  DenseImage<std::uint8_t> noise(Dims{80, 80, 80}, 0);
  std::mt19937 rng(7);
  for (auto& v : noise.data()) v = std::uint8_t(rng() & 1);
  const std::string in = path("noise.nrrd");
  io::writeVolume(io::AnyVolume(noise), in);
  fs::create_directories(work_ / "d");
  const pid_t pid = startTool({"mesh", in, "-o", path("d/c.ply"), "--iso", "0.5", "--all", "--ascii", "--quiet"}, scratch_);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(interruptWhen(pid, work_ / "d", SIGINT,
                            [](const std::string& name, const fs::path&) { return name.rfind(".c.tmp-", 0) == 0; }))
      << "the run ended before its write could be interrupted";
  const RunResult r = finishTool(pid, scratch_);
  EXPECT_EQ(r.code, 130) << r.err;
  EXPECT_EQ(listDirectory(work_ / "d"), std::vector<std::string>{}) << "no output, no temporary";
}

}  // namespace
}  // namespace surftrack
