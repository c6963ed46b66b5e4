#include "MeshIO.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <system_error>

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/exporter/BaseExporter.hh>

#include "Cancellation.h"
#include "TemporaryFiles.h"

namespace surftrack {
namespace {

namespace fs = std::filesystem;

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return char(std::tolower(ch)); });
  return ext;
}

/// A fresh name next to `path`, with the same extension (OpenMesh picks the writer by it).
fs::path temporaryPathFor(const fs::path& path, const std::string& ext) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  std::string name = path.stem().string();
  name += ".tmp-" + std::to_string(rng()) + ext;
  return path.parent_path() / ("." + name);
}

/// Items (vertices or triangles) written between two checks of a cancel flag.
constexpr std::size_t kCancelCheck = std::size_t(1) << 16;

/// A triangle list seen as OpenMesh's writers see a mesh: what ExporterT gives for a
/// SurfaceMesh without normals, colours, texture coordinates or status (double points). The
/// writers ask it for every vertex and triangle in turn: every kCancelCheck of those asks, it
/// checks `cancel` (a raised flag throws Cancelled out of the writer, whose stream closes).
class TriangleListExporter final : public OpenMesh::IO::BaseExporter {
 public:
  using VH = OpenMesh::VertexHandle;
  using FH = OpenMesh::FaceHandle;
  using EH = OpenMesh::EdgeHandle;
  using HH = OpenMesh::HalfedgeHandle;
  using Status = OpenMesh::Attributes::StatusInfo;

  TriangleListExporter(const std::vector<std::array<double, 3>>& v,
                       const std::vector<std::array<std::uint32_t, 3>>& t, const std::atomic<bool>* cancel)
      : v_(v), t_(t), cancel_(cancel) {}

  OpenMesh::Vec3f point(VH h) const override {
    tick();
    const auto& p = v_[std::size_t(h.idx())];
    return {float(p[0]), float(p[1]), float(p[2])};
  }
  OpenMesh::Vec3d pointd(VH h) const override {
    tick();
    const auto& p = v_[std::size_t(h.idx())];
    return {p[0], p[1], p[2]};
  }
  bool is_point_double() const override { return true; }
  bool is_normal_double() const override { return false; }
  OpenMesh::Vec3f normal(VH) const override { return {0, 0, 0}; }
  OpenMesh::Vec3d normald(VH) const override { return {0, 0, 0}; }
  OpenMesh::Vec3uc color(VH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4uc colorA(VH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec3ui colori(VH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4ui colorAi(VH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec3f colorf(VH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4f colorAf(VH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec2f texcoord(VH) const override { return {0, 0}; }
  OpenMesh::Vec2f texcoord(HH) const override { return {0, 0}; }
  Status status(VH) const override { return {}; }

  unsigned int get_vhandles(FH f, std::vector<VH>& out) const override {
    tick();
    const auto& t = t_[std::size_t(f.idx())];
    out.assign({VH(int(t[0])), VH(int(t[1])), VH(int(t[2]))});
    return 3;
  }
  HH getHeh(FH, VH) const override { return HH(); }
  unsigned int get_face_texcoords(std::vector<OpenMesh::Vec2f>& out) const override {
    out.clear();
    return 0;
  }
  OpenMesh::Vec3f normal(FH) const override { return {0, 0, 0}; }
  OpenMesh::Vec3d normald(FH) const override { return {0, 0, 0}; }
  OpenMesh::Vec3uc color(FH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4uc colorA(FH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec3ui colori(FH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4ui colorAi(FH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec3f colorf(FH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4f colorAf(FH) const override { return {0, 0, 0, 0}; }
  Status status(FH) const override { return {}; }

  OpenMesh::Vec3uc color(EH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4uc colorA(EH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec3ui colori(EH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4ui colorAi(EH) const override { return {0, 0, 0, 0}; }
  OpenMesh::Vec3f colorf(EH) const override { return {0, 0, 0}; }
  OpenMesh::Vec4f colorAf(EH) const override { return {0, 0, 0, 0}; }
  Status status(EH) const override { return {}; }

  // Halfedge queries serve the OM format's writer only, which writeTriangles does not offer.
  int get_halfedge_id(VH) override { return -1; }
  int get_halfedge_id(FH) override { return -1; }
  int get_next_halfedge_id(HH) override { return -1; }
  int get_to_vertex_id(HH) override { return -1; }
  int get_face_id(HH) override { return -1; }
  Status status(HH) const override { return {}; }

  std::size_t n_vertices() const override { return v_.size(); }
  std::size_t n_faces() const override { return t_.size(); }
  std::size_t n_edges() const override { return 3 * t_.size() / 2; }  // closed: each edge twice
  bool is_triangle_mesh() const override { return true; }
  // The PLY writer looks for custom properties in the kernel: an empty one has none.
  const OpenMesh::BaseKernel* kernel() override { return &noProperties_; }

 private:
  void tick() const {
    if (asks_++ % kCancelCheck == 0) throwIfCancelled(cancel_, "writing");  // the first ask too
  }

  OpenMesh::BaseKernel noProperties_;
  const std::vector<std::array<double, 3>>& v_;
  const std::vector<std::array<std::uint32_t, 3>>& t_;
  const std::atomic<bool>* cancel_;
  mutable std::size_t asks_ = 0;
};

/// Binary PLY, the most common output, byte for byte as OpenMesh's PLY writer writes it for a
/// SurfaceMesh (the tests compare both), but from whole arrays: OpenMesh's writer goes value by
/// value through the exporter and the stream, about 50 MB/s on this project's machines
/// (docs/performance.md), a large part of a seeded extraction. Several meshes go one after the
/// other (their triangles' indices shifted); `labelled` adds the label to every vertex and face
/// as writeLabelledTriangles states (one int, or two 32-bit words). Binary, or text for
/// writeLabelledTriangles. False if a write fails (errno says why). `cancel` is checked before
/// each buffer.
bool writePly(const std::vector<LabelledMesh>& meshes, bool labelled, bool binary, const std::string& path,
              const std::atomic<bool>* cancel = nullptr) {
  static_assert(std::endian::native == std::endian::little, "binary_little_endian is written as is");
  std::size_t vertexCount = 0, faceCount = 0;
  bool narrow = true, negative = false;  // every label fits int32; some label is negative
  for (const LabelledMesh& m : meshes) {
    vertexCount += m.vertices->size(), faceCount += m.triangles->size();
    narrow = narrow && m.label.fits<std::int32_t>();
    negative = negative || m.label.negative();
  }
  // Closed on every way out, Cancelled included.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> owned(std::fopen(path.c_str(), "wb"), &std::fclose);
  std::FILE* const file = owned.get();
  if (!file) return false;
  const std::string label = !labelled ? ""
                            : narrow  ? "property int label\n"
                                      : std::string("property ") + (negative ? "int" : "uint") +
                                           " label_high\nproperty uint label_low\n";
  const std::string header = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") +
                             " 1.0\n" + (labelled ? "comment surftrack label surfaces: one closed surface per label\n" : "") +
                             "element vertex " + std::to_string(vertexCount) +
                             "\nproperty float x\nproperty float y\nproperty float z\n" + label + "element face " +
                             std::to_string(faceCount) + "\nproperty list uchar int vertex_indices\n" + label +
                             "end_header\n";
  bool ok = std::fwrite(header.data(), 1, header.size(), file) == header.size();
  const std::size_t extra = !labelled ? 0 : narrow ? 4 : 8;
  // A label's columns: its low 32 bits (int32 when narrow), then, when wide, the high word of
  // its two's complement (int64 for a negative label, uint64 else: exact either way).
  struct Columns {
    unsigned char bytes[8];
    char text[48];
  };
  auto columns = [&](const LabelValue& L) {
    Columns c{};
    const std::uint64_t bits = L.negative() ? std::uint64_t(L.as<std::int64_t>()) : L.magnitude();
    const auto low = std::uint32_t(bits), high = std::uint32_t(bits >> 32);
    if (narrow) {
      std::memcpy(c.bytes, &low, 4);
      std::snprintf(c.text, sizeof c.text, " %d", int(std::int32_t(low)));
    } else {
      std::memcpy(c.bytes, &high, 4);
      std::memcpy(c.bytes + 4, &low, 4);
      if (negative)
        std::snprintf(c.text, sizeof c.text, " %d %u", int(std::int32_t(high)), unsigned(low));
      else
        std::snprintf(c.text, sizeof c.text, " %u %u", unsigned(high), unsigned(low));
    }
    return c;
  };
  constexpr std::size_t kChunk = 1 << 16;  // items per buffer
  std::vector<unsigned char> buffer(kChunk * (13 + extra));
  std::string text;
  for (const LabelledMesh& m : meshes) {
    const auto& vertices = *m.vertices;
    const Columns L = columns(m.label);
    for (std::size_t begin = 0; ok && begin < vertices.size(); begin += kChunk) {
      throwIfCancelled(cancel, "writing");
      const std::size_t n = std::min(kChunk, vertices.size() - begin);
      unsigned char* out = buffer.data();
      text.clear();
      for (std::size_t v = begin; v < begin + n; ++v, out += 12 + extra) {
        const float p[3] = {float(vertices[v][0]), float(vertices[v][1]), float(vertices[v][2])};
        if (!binary) {
          char line[96];
          const int length = std::snprintf(line, sizeof line, "%.9g %.9g %.9g%s\n", p[0], p[1], p[2],
                                           labelled ? L.text : "");
          text.append(line, std::size_t(length));
          continue;
        }
        std::memcpy(out, p, 12);
        std::memcpy(out + 12, L.bytes, extra);
      }
      ok = binary ? std::fwrite(buffer.data(), 12 + extra, n, file) == n
                  : std::fwrite(text.data(), 1, text.size(), file) == text.size();
    }
  }
  std::size_t offset = 0;
  for (const LabelledMesh& m : meshes) {
    const auto& triangles = *m.triangles;
    const Columns L = columns(m.label);
    for (std::size_t begin = 0; ok && begin < triangles.size(); begin += kChunk) {
      throwIfCancelled(cancel, "writing");
      const std::size_t n = std::min(kChunk, triangles.size() - begin);
      unsigned char* out = buffer.data();
      text.clear();
      for (std::size_t f = begin; f < begin + n; ++f, out += 13 + extra) {
        const std::int32_t t[3] = {std::int32_t(triangles[f][0] + offset), std::int32_t(triangles[f][1] + offset),
                                   std::int32_t(triangles[f][2] + offset)};
        if (!binary) {
          char line[96];
          const int length = std::snprintf(line, sizeof line, "3 %d %d %d%s\n", t[0], t[1], t[2],
                                           labelled ? L.text : "");
          text.append(line, std::size_t(length));
          continue;
        }
        out[0] = 3;
        std::memcpy(out + 1, t, 12);
        std::memcpy(out + 13, L.bytes, extra);
      }
      ok = binary ? std::fwrite(buffer.data(), 13 + extra, n, file) == n
                  : std::fwrite(text.data(), 1, text.size(), file) == text.size();
    }
    offset += m.vertices->size();
  }
  if (!ok) return false;  // (errno from the failed write, before fclose may change it)
  return std::fclose(owned.release()) == 0;
}

bool writeBinaryPly(const std::vector<std::array<double, 3>>& vertices,
                    const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::string& path,
                    const std::atomic<bool>* cancel) {
  return writePly({LabelledMesh{&vertices, &triangles, 0}}, false, true, path, cancel);
}

/// The extension of `path` if it is one writeMesh knows, else std::invalid_argument.
std::string meshExtension(const std::string& path) {
  constexpr std::array<const char*, 4> kFormats = {".ply", ".obj", ".off", ".stl"};
  const std::string ext = lowerExtension(fs::path(path));
  if (std::find(kFormats.begin(), kFormats.end(), ext) == kFormats.end())
    throw std::invalid_argument("cannot write mesh '" + path + "': unknown extension '" + ext +
                                "' (expected .ply, .obj, .off or .stl)");
  return ext;
}

/// Why `path` cannot be written, from the errno of creating a file next to it: for the
/// directory's usual failures the words of the CLI (cli/OutputFile.cpp), else the system's.
FileWriteError cannotCreate(const std::string& path, int error) {
  const fs::path target(path);
  const std::string dir = target.has_parent_path() ? target.parent_path().string() : std::string(".");
  std::error_code ignored;
  std::string why;
  if (error == ENOENT && !fs::exists(fs::path(dir), ignored)) why = "directory '" + dir + "' does not exist";
  else if (error == ENOTDIR) why = "'" + dir + "' is not a directory";
  else if (error == EACCES || error == EPERM) why = "directory '" + dir + "' is not writable (permission denied)";
  else why = "cannot create a file in directory '" + dir + "': " + std::generic_category().message(error);
  return FileWriteError(error, "cannot write '" + path + "': " + why);
}

/// The exception for a path that is a directory: raised before anything is written.
void requireNotDirectory(const std::string& path) {
  std::error_code ignored;
  if (fs::is_directory(fs::path(path), ignored))
    throw FileWriteError(EISDIR, "cannot write '" + path + "': it is a directory");
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::function<bool(const std::string&)>& write) {
  requireNotDirectory(path);
  const fs::path target(path);
  const fs::path temporary = temporaryPathFor(target, lowerExtension(target));
  const LiveTemporary live(temporary.string());  // removed by a handler of SIGINT (TemporaryFiles.h)
  // The temporary file is created here, empty, so that a directory that cannot take it is told
  // with the system's reason: the writers below only say whether they succeeded.
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw cannotCreate(path, errno);
  ::close(fd);
  std::error_code ignored;
  bool written = false;
  errno = 0;
  try {
    written = write(temporary.string());
  } catch (...) {
    fs::remove(temporary, ignored);
    throw;
  }
  if (!written) {
    const int error = errno != 0 ? errno : EIO;  // a writer that failed without a system error: EIO
    fs::remove(temporary, ignored);
    throw FileWriteError(error, "cannot write '" + path + "': " + std::generic_category().message(error));
  }
  std::error_code error;
  fs::rename(temporary, target, error);
  if (error) {
    fs::remove(temporary, ignored);
    throw FileWriteError(error.value(), "cannot write '" + path + "': " + error.message());
  }
}

void writeTriangles(const std::vector<std::array<double, 3>>& vertices,
                    const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::string& path,
                    bool binary, const std::atomic<bool>* cancel) {
  requireNotDirectory(path);  // before the extension: "out/" is a directory, not a format
  const std::string ext = meshExtension(path);
  OpenMesh::IO::Options options = OpenMesh::IO::Options::Default;
  if (binary && (ext == ".ply" || ext == ".stl")) options += OpenMesh::IO::Options::Binary;
  TriangleListExporter exporter(vertices, triangles, cancel);
  writeFileAtomically(path, [&](const std::string& temporary) {
    return ext == ".ply" && binary ? writeBinaryPly(vertices, triangles, temporary, cancel)
                                   : OpenMesh::IO::IOManager().write(temporary, exporter, options, 12);
  });
}

void writeLabelledTriangles(const std::vector<LabelledMesh>& meshes, const std::string& path, bool binary) {
  requireNotDirectory(path);
  if (meshExtension(path) != ".ply")
    throw std::invalid_argument("cannot write '" + path + "': labelled meshes are written as .ply");
  std::size_t vertices = 0;
  for (const LabelledMesh& m : meshes) vertices += m.vertices->size();
  if (vertices > std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("cannot write '" + path + "': more than 2^31 - 1 vertices in one PLY");
  writeFileAtomically(path, [&](const std::string& temporary) { return writePly(meshes, true, binary, temporary); });
}

void writeMesh(const SurfaceMesh& mesh, const std::string& path, bool binary) {
  requireNotDirectory(path);
  const std::string ext = meshExtension(path);
  OpenMesh::IO::Options options = OpenMesh::IO::Options::Default;
  if (binary && (ext == ".ply" || ext == ".stl")) options += OpenMesh::IO::Options::Binary;
  writeFileAtomically(path, [&](const std::string& temporary) {
    return OpenMesh::IO::write_mesh(mesh, temporary, options, 12);
  });
}

}  // namespace surftrack
