// Helpers of the end-to-end tests of the `surftrack` executable (tests/test_cli.cpp): run it,
// make small volumes, read meshes back with OpenMesh, pick fields out of its JSON.
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "Image.h"
#include "ReadVolume.h"

namespace surftrack::clitest {

namespace fs = std::filesystem;

struct RunResult {
  int code = -1;
  std::string out, err;
};

inline std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

/// Runs `surftrack ARGS...` with stdout and stderr captured in files of `scratch` (a
/// directory outside the one the test inspects for left-over files).
inline RunResult runTool(const std::vector<std::string>& args, const fs::path& scratch) {
  std::string cmd = shellQuote(SURFTRACK_EXE);
  for (const auto& a : args) {
    cmd += ' ';
    cmd += shellQuote(a);
  }
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  cmd += " > " + shellQuote(out.string()) + " 2> " + shellQuote(err.string()) + " < /dev/null";
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.out = readText(out);
  r.err = readText(err);
  return r;
}

/// Starts `surftrack ARGS...` without waiting (posix_spawn, no shell: the pid is the tool's own,
/// for kill()), its stdout and stderr going to files of `scratch`; finishTool waits for it.
inline pid_t startTool(const std::vector<std::string>& args, const fs::path& scratch) {
  std::vector<std::string> all = {SURFTRACK_EXE};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, (scratch / "stdout.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, (scratch / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  if (posix_spawn(&pid, SURFTRACK_EXE, &actions, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

/// Waits for a tool started by startTool: its status as the shell gives it (128 + the signal
/// that ended it, if one did) and its output; its resource usage through `usage` (wait4).
inline RunResult finishTool(pid_t pid, const fs::path& scratch, struct rusage* usage = nullptr) {
  int status = 0;
  RunResult r;
  struct rusage ignored;
  if (wait4(pid, &status, 0, usage ? usage : &ignored) == pid)
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.out = readText(scratch / "stdout.txt");
  r.err = readText(scratch / "stderr.txt");
  return r;
}

/// The number after "key": in a JSON text (first occurrence), or NaN.
inline double jsonNumber(const std::string& json, const std::string& key) {
  std::smatch m;
  const std::regex re("\"" + key + "\": (-?[0-9.eE+-]+)");
  if (!std::regex_search(json, m, re)) return std::numeric_limits<double>::quiet_NaN();
  return std::stod(m[1]);
}
inline std::optional<bool> jsonBool(const std::string& json, const std::string& key) {
  std::smatch m;
  const std::regex re("\"" + key + "\": (true|false)");
  if (!std::regex_search(json, m, re)) return std::nullopt;
  return m[1] == "true";
}
inline std::string jsonString(const std::string& json, const std::string& key) {
  std::smatch m;
  const std::regex re("\"" + key + "\": \"([^\"]*)\"");
  return std::regex_search(json, m, re) ? std::string(m[1]) : std::string();
}

/// The elements of the array after "key": (first occurrence), whitespace removed: "1,2,3".
inline std::string jsonArray(const std::string& json, const std::string& key) {
  std::smatch m;
  const std::regex re("\"" + key + "\": \\[([^\\]]*)\\]");
  if (!std::regex_search(json, m, re)) return "<none>";
  std::string out;
  for (char ch : std::string(m[1]))
    if (!std::isspace(static_cast<unsigned char>(ch))) out += ch;
  return out;
}

using ReadMesh = OpenMesh::TriMesh_ArrayKernelT<>;

struct MeshCheck {
  bool read = false;
  std::size_t vertices = 0, faces = 0;
  bool closed = false, manifold = false;
  std::array<double, 3> min{}, max{};
};

/// Reads a mesh file with OpenMesh and checks it: every edge has two faces, every vertex one
/// fan of faces (OpenMesh also drops, on reading, any face that would make an edge or vertex
/// complex: compare `faces` with the count the tool reported).
inline MeshCheck checkMeshFile(const fs::path& path) {
  MeshCheck c;
  ReadMesh mesh;
  OpenMesh::IO::Options options;
  if (!OpenMesh::IO::read_mesh(mesh, path.string(), options)) return c;
  c.read = true;
  c.vertices = mesh.n_vertices();
  c.faces = mesh.n_faces();
  c.closed = c.faces > 0;
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h)) {
      c.closed = false;
      break;
    }
  c.manifold = true;
  for (auto v : mesh.vertices())
    if (!mesh.is_manifold(v) || mesh.is_isolated(v)) c.manifold = false;
  const double inf = std::numeric_limits<double>::infinity();
  c.min = {inf, inf, inf};
  c.max = {-inf, -inf, -inf};
  for (auto v : mesh.vertices())
    for (int a = 0; a < 3; ++a) {
      c.min[a] = std::min(c.min[a], double(mesh.point(v)[a]));
      c.max[a] = std::max(c.max[a], double(mesh.point(v)[a]));
    }
  return c;
}

/// The number of boundary surfels (c, d): c a 1-voxel, d a 6-neighbour 0-voxel (voxels outside
/// the domain are 0), counted directly.
template <class T, class Inside>
std::size_t countBoundarySurfels(const DenseImage<T>& image, Inside inside) {
  const Dims& d = image.dims();
  auto at = [&](int x, int y, int z) { return d.contains(x, y, z) && inside(image.at(x, y, z)); };
  std::size_t n = 0;
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x) {
        if (!inside(image.at(x, y, z))) continue;
        n += !at(x + 1, y, z) + !at(x - 1, y, z) + !at(x, y + 1, z) + !at(x, y - 1, z) +
             !at(x, y, z + 1) + !at(x, y, z - 1);
      }
  return n;
}

/// The physical bounding box of the index-space box [lo, hi] under a geometry.
inline std::pair<std::array<double, 3>, std::array<double, 3>> physicalBox(
    const ImageGeometry& g, std::array<double, 3> lo, std::array<double, 3> hi) {
  const double inf = std::numeric_limits<double>::infinity();
  std::array<double, 3> mn{inf, inf, inf}, mx{-inf, -inf, -inf};
  for (int corner = 0; corner < 8; ++corner) {
    std::array<double, 3> p{};
    for (int a = 0; a < 3; ++a) p[a] = (corner >> a) & 1 ? hi[a] : lo[a];
    const auto q = g.toPhysical(p);
    for (int a = 0; a < 3; ++a) {
      mn[a] = std::min(mn[a], q[a]);
      mx[a] = std::max(mx[a], q[a]);
    }
  }
  return {mn, mx};
}

/// The files of a directory, by name, sorted.
inline std::vector<std::string> listDirectory(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace surftrack::clitest
