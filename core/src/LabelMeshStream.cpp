// A label's mesh file written from its fragment files with bounded memory (LabelBlockFiles.h,
// writeLabelMeshStreamed; docs/theory.md, "A label larger than one merge", "Its mesh, streamed"):
// the bytes writeSurface writes for mergeLabelFragmentFiles' surface, without that surface.
//
// The merge in memory (LabelBlocks.cpp) numbers the vertices by increasing key over the union of
// the fragments' keys, and orders the triangles by owning cube, each fragment's in its own
// order. Both orders are merges of sorted streams, so they are computed as streams:
//   1. the vertices: a k-way merge of the fragments' keys (each increasing in its file), each
//      new key placed by the single pass' expression and written, and every fragment key's
//      global number written to a remap file beside the output;
//   2. the triangles: a k-way merge of the fragments' triangles by owning cube (each fragment's
//      in non-decreasing cube order, checked: the block scan's order, which is the single
//      pass's restricted to the block), each renumbered through the remap file, read by the
//      window of local numbers a chunk of triangles uses.
// A fragment's stream is read a chunk at a time, and only from the point where the merge reaches
// its block (the block's lowest key or cube bounds all of its own): memory is a chunk per
// fragment of the blocks that meet the plane being merged, never the label. Every byte read is
// checked against the file's checksums, keys and indices as readLabelFragment checks them.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <fcntl.h>
#include <filesystem>
#include <map>
#include <queue>
#include <random>
#include <unistd.h>

#include "BlockOwnership.h"
#include "BoundaryMapping.h"
#include "Cancellation.h"
#include "Errors.h"
#include "FragmentChecksum.h"
#include "LabelBlockFiles.h"
#include "MeshIO.h"
#include "PhysicalRange.h"

namespace surftrack {
namespace {

[[noreturn]] void bad(const std::string& path, const std::string& what) {
  throw InvalidInput("fragment file '" + path + "': " + what);
}

/// A file read or written at offsets (pread/pwrite); closed when dropped.
class Fd {
 public:
  Fd(const std::string& path, int flags) : path_(path), fd_(::open(path.c_str(), flags | O_CLOEXEC, 0666)) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }
  /// Reads `bytes` at `offset`; false when the file is shorter.
  bool read(std::uint64_t offset, void* data, std::size_t bytes) const {
    auto* p = static_cast<char*>(data);
    while (bytes > 0) {
      const ssize_t n = ::pread(fd_, p, bytes, off_t(offset));
      if (n <= 0) return false;
      p += n, bytes -= std::size_t(n), offset += std::uint64_t(n);
    }
    return true;
  }
  bool write(std::uint64_t offset, const void* data, std::size_t bytes) const {
    const auto* p = static_cast<const char*>(data);
    while (bytes > 0) {
      const ssize_t n = ::pwrite(fd_, p, bytes, off_t(offset));
      if (n <= 0) return false;
      p += n, bytes -= std::size_t(n), offset += std::uint64_t(n);
    }
    return true;
  }

 private:
  std::string path_;
  int fd_;
};

/// One fragment of the label: where its data lie, and the state of its two streams.
struct Fragment {
  const std::string* path;
  FragmentFileIndex::Entry entry;
  std::uint64_t keyBound = 0;   ///< no key of the fragment is below it (its block's lowest plane)
  std::uint64_t cubeBound = 0;  ///< no owning cube of its triangles is below it (its block's first cube)
  std::uint64_t remapAt = 0;    ///< its keys' global numbers in the remap file, from this entry on

  // The keys' stream (pass 1).
  std::vector<std::uint64_t> keys;
  std::size_t keysRead = 0, keyAt = 0;  ///< keys read from the file; position in `keys`
  std::uint64_t lastKey = 0;
  FragmentChecksum keySum;
  std::vector<std::uint32_t> numbers;  ///< global numbers waiting to be written to the remap file
  std::uint64_t numbersAt = 0;          ///< the local number of numbers[0]
  std::uint64_t keysChecksum = 0;       ///< of all its keys, once read (seeds the triangles')

  // The triangles' stream (pass 2).
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< renumbered, in the output's orientation
  std::vector<std::uint64_t> cubes;
  std::size_t trianglesRead = 0, triangleAt = 0;
  FragmentChecksum triangleSum;
  std::uint64_t lastCube = 0;
};

/// The lowest packed owning cube (BlockOwnership.h, owningCube) of a block's cubes.
std::uint64_t firstCube(Voxel lo) {
  return packedCube({lo.x == 0 ? -1 : lo.x, lo.y == 0 ? -1 : lo.y, lo.z == 0 ? -1 : lo.z});
}

/// The lowest key of a surfel of a block's cubes: a surfel's voxels lie in the cube, whose min
/// corner is at lo.z or above (-1 at the volume's low face), and keys order planes first.
std::uint64_t firstKey(Voxel lo) {
  const int z = lo.z == 0 ? -1 : lo.z;
  return std::uint64_t(z + Surfel::kCoordinateLimit) << 43;
}

class Streams {
 public:
  Streams(std::vector<Fragment>& fragments, std::size_t chunk, const std::atomic<bool>* cancel)
      : f_(fragments), chunk_(chunk), cancel_(cancel) {}

  /// Pass 1: the vertices (float x, y, z per vertex, little-endian) appended to `vertices`, the
  /// global numbers to `remap`; returns the vertex count.
  std::uint64_t vertices(const ImageGeometry& geometry, std::FILE* vertices, const Fd& remap) {
    using Head = std::pair<std::uint64_t, std::size_t>;  // (key or bound, fragment); loaded below
    std::priority_queue<Head, std::vector<Head>, std::greater<>> heap;
    std::vector<bool> loaded(f_.size(), false);
    for (std::size_t i = 0; i < f_.size(); ++i)
      if (f_[i].entry.keys > 0) heap.push({f_[i].keyBound, i});
    std::uint64_t count = 0, last = 0;
    std::vector<float> out;
    out.reserve(3 * chunk_);
    auto flush = [&] {
      if (!out.empty() && std::fwrite(out.data(), sizeof(float), out.size(), vertices) != out.size())
        throw std::runtime_error("cannot write a temporary file of vertices (disk full?)");
      out.clear();
    };
    std::size_t steps = 0;
    while (!heap.empty()) {
      auto [key, i] = heap.top();
      heap.pop();
      Fragment& f = f_[i];
      if (!loaded[i]) {  // the merge reached its block: its stream starts
        loaded[i] = true;
        readKeys(f);
        heap.push({f.keys[0], i});
        continue;
      }
      if (++steps % (1 << 20) == 0) throwIfCancelled(cancel_, "writing");
      if (count == 0 || key != last) {
        if (count == std::numeric_limits<std::uint32_t>::max())
          throw InvalidInput("label " + f.entry.label.text() + " has more than 2^32 - 1 surfels");
        const Surfel s = Surfel::fromKey(key);
        const std::array<double, 3> index = MidpointMapping{}(s);
        const std::array<double, 3> p = geometry.toPhysical(index);  // the single pass's expression
        if (!fitsFloat(p)) throw InvalidInput(outOfRangeText(geometry, index, p));
        out.insert(out.end(), {float(p[0]), float(p[1]), float(p[2])});
        if (out.size() >= 3 * chunk_) flush();
        last = key;
        ++count;
      }
      f.numbers.push_back(std::uint32_t(count - 1));
      if (f.numbers.size() >= chunk_) writeNumbers(f, remap);
      if (++f.keyAt == f.keys.size()) {
        if (f.keysRead < f.entry.keys) {
          readKeys(f);
        } else {  // its keys are done
          writeNumbers(f, remap);
          f.keysChecksum = f.keySum.finish();
          if (f.entry.triangles == 0 && FragmentChecksum(f.keysChecksum).finish() != f.entry.checksum)
            bad(*f.path, "corrupted (the data of label " + f.entry.label.text() + " do not match their checksum)");
          std::vector<std::uint64_t>().swap(f.keys);
          std::vector<std::uint32_t>().swap(f.numbers);
          continue;
        }
      }
      heap.push({f.keys[f.keyAt], i});
    }
    flush();
    return count;
  }

  /// Pass 2: the triangles (binary PLY faces: uchar 3, int32 x 3) appended to `out`, in the
  /// single pass' order, their second and third corners swapped when `mirrored`.
  void triangles(const Fd& remap, bool mirrored, std::FILE* out) {
    using Head = std::pair<std::uint64_t, std::size_t>;  // (cube or bound, fragment)
    std::priority_queue<Head, std::vector<Head>, std::greater<>> heap;
    std::vector<bool> loaded(f_.size(), false);
    for (std::size_t i = 0; i < f_.size(); ++i)
      if (f_[i].entry.triangles > 0) heap.push({f_[i].cubeBound, i});
    std::vector<unsigned char> buffer;
    buffer.reserve(13 * chunk_);
    auto flush = [&] {
      if (!buffer.empty() && std::fwrite(buffer.data(), 1, buffer.size(), out) != buffer.size())
        throw std::runtime_error("cannot write the mesh (disk full?)");
      buffer.clear();
    };
    std::size_t steps = 0;
    while (!heap.empty()) {
      const std::size_t i = heap.top().second;
      heap.pop();
      Fragment& f = f_[i];
      if (!loaded[i]) {
        loaded[i] = true;
        readTriangles(f, remap, mirrored);
        heap.push({f.cubes[0], i});
        continue;
      }
      if (++steps % (1 << 20) == 0) throwIfCancelled(cancel_, "writing");
      const auto& t = f.triangles[f.triangleAt];
      unsigned char face[13];
      face[0] = 3;
      const std::int32_t v[3] = {std::int32_t(t[0]), std::int32_t(t[1]), std::int32_t(t[2])};
      std::memcpy(face + 1, v, 12);
      buffer.insert(buffer.end(), face, face + 13);
      if (buffer.size() >= 13 * chunk_) flush();
      if (++f.triangleAt == f.triangles.size()) {
        if (f.trianglesRead < f.entry.triangles) {
          readTriangles(f, remap, mirrored);
        } else {
          if (f.triangleSum.finish() != f.entry.checksum)
            bad(*f.path, "corrupted (the data of label " + f.entry.label.text() + " do not match their checksum)");
          std::vector<std::array<std::uint32_t, 3>>().swap(f.triangles);
          std::vector<std::uint64_t>().swap(f.cubes);
          continue;
        }
      }
      heap.push({f.cubes[f.triangleAt], i});
    }
    flush();
  }

 private:
  /// The next chunk of a fragment's keys, checked (surfel keys, strictly increasing).
  void readKeys(Fragment& f) {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(chunk_, f.entry.keys - f.keysRead));
    f.keys.resize(n);
    const Fd in(*f.path, O_RDONLY);
    if (!in.ok()) bad(*f.path, "cannot be opened");
    if (!in.read(f.entry.offset + 8 * f.keysRead, f.keys.data(), 8 * n))
      bad(*f.path, "truncated (the keys of label " + f.entry.label.text() + ")");
    f.keySum.add(f.keys.data(), 8 * n);
    for (std::size_t v = 0; v < n; ++v) {
      const std::uint64_t k = f.keys[v];
      if (k >> 63 || (k & 7) > 5 || (f.keysRead + v > 0 && k <= f.lastKey) || k < f.keyBound)
        bad(*f.path, "label " + f.entry.label.text() + " has keys out of range or not increasing");
      f.lastKey = k;
    }
    f.keysRead += n;
    f.keyAt = 0;
  }

  void writeNumbers(Fragment& f, const Fd& remap) {
    if (!remap.write(f.remapAt + 4 * f.numbersAt, f.numbers.data(), 4 * f.numbers.size()))
      throw std::runtime_error("cannot write a temporary file of vertex numbers (disk full?)");
    f.numbersAt += f.numbers.size();
    f.numbers.clear();
  }

  /// The next chunk of a fragment's triangles (an even count but the last, so that the
  /// checksum goes by whole 8-byte words), checked, their owning cubes computed from the keys
  /// of the window of local numbers they use, then renumbered through the remap file.
  void readTriangles(Fragment& f, const Fd& remap, bool mirrored) {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(chunk_ & ~std::size_t(1), f.entry.triangles - f.trianglesRead));
    f.triangles.resize(n);
    std::uint32_t lo = std::numeric_limits<std::uint32_t>::max(), hi = 0;
    {
      const Fd in(*f.path, O_RDONLY);
      if (!in.ok()) bad(*f.path, "cannot be opened");
      if (!in.read(f.entry.offset + 8 * f.entry.keys + 12 * f.trianglesRead, f.triangles.data(), 12 * n))
        bad(*f.path, "truncated (the triangles of label " + f.entry.label.text() + ")");
      if (f.trianglesRead == 0) f.triangleSum = FragmentChecksum(f.keysChecksum);
      f.triangleSum.add(f.triangles.data(), 12 * n);
      for (const auto& t : f.triangles)
        for (std::uint32_t v : t) {
          if (v >= f.entry.keys) bad(*f.path, "label " + f.entry.label.text() + " has a triangle beyond its vertices");
          lo = std::min(lo, v), hi = std::max(hi, v);
        }
      window_.resize(hi - lo + 1);
      if (!in.read(f.entry.offset + 8 * std::uint64_t(lo), window_.data(), 8 * window_.size()))
        bad(*f.path, "truncated (the keys of label " + f.entry.label.text() + ")");
    }
    numbers_.resize(window_.size());
    if (!remap.read(f.remapAt + 4 * std::uint64_t(lo), numbers_.data(), 4 * numbers_.size()))
      throw std::runtime_error("cannot read a temporary file of vertex numbers");
    f.cubes.resize(n);
    for (std::size_t t = 0; t < n; ++t) {
      auto& tri = f.triangles[t];
      f.cubes[t] = owningCube({window_[tri[0] - lo], window_[tri[1] - lo], window_[tri[2] - lo]});
      // The merge sorts by cube, stably: this fragment's own order must already be by cube.
      if ((f.trianglesRead + t > 0 && f.cubes[t] < f.lastCube) || f.cubes[t] < f.cubeBound)
        throw InvalidInput("fragment file '" + *f.path + "': the triangles of label " + f.entry.label.text() +
                           " are not in the scan's order of cubes");
      f.lastCube = f.cubes[t];
      tri = {numbers_[tri[0] - lo], numbers_[tri[1] - lo], numbers_[tri[2] - lo]};
      if (mirrored) std::swap(tri[1], tri[2]);  // as finishScannedLabel
    }
    f.trianglesRead += n;
    f.triangleAt = 0;
  }

  std::vector<Fragment>& f_;
  std::size_t chunk_;
  const std::atomic<bool>* cancel_;
  std::vector<std::uint64_t> window_;
  std::vector<std::uint32_t> numbers_;
};

/// A temporary file beside `near`, removed when dropped.
struct Scratch {
  std::string path;
  explicit Scratch(const std::string& near, const std::string& what) {
    std::random_device entropy;
    path = near + "." + what + ".tmp-" + std::to_string(entropy()) + std::to_string(entropy());
  }
  ~Scratch() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};

}  // namespace

LabelMeshCounts writeLabelMeshStreamed(LabelValue label, const std::vector<std::string>& paths,
                                       const ImageGeometry& geometry, const std::string& path, std::uint64_t budget,
                                       const std::atomic<bool>* cancel) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& ch : extension) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (extension != ".ply") throw InvalidInput("a streamed mesh is written as binary .ply: '" + path + "'");
  std::vector<Fragment> fragments;
  std::map<std::array<int, 3>, const std::string*> blocks;
  std::map<int, std::size_t> perPlane;  // fragments whose blocks start at each z
  std::uint64_t remapBytes = 0;
  for (const std::string& p : paths) {
    const FragmentFileIndex index = readFragmentFileIndex(p);
    const auto* e = index.find(label);
    if (!e) continue;
    if (!blocks.emplace(std::array<int, 3>{index.lo.x, index.lo.y, index.lo.z}, &p).second)
      throw InvalidInput("fragment files '" + *blocks[{index.lo.x, index.lo.y, index.lo.z}] + "' and '" + p +
                         "' are of the same block");
    Fragment f;
    f.path = &p;
    f.entry = *e;
    f.keyBound = firstKey(index.lo);
    f.cubeBound = firstCube(index.lo);
    f.remapAt = remapBytes;
    remapBytes += 4 * e->keys;
    fragments.push_back(std::move(f));
    ++perPlane[index.lo.z];
  }
  if (fragments.empty()) throw InvalidInput("no fragment file holds label " + label.text());
  // A chunk per fragment of a plane of blocks (three streams of at most 12 bytes an item) within
  // the budget, but not so small that reading is all seeks.
  std::size_t plane = 1;
  for (const auto& [z, n] : perPlane) plane = std::max(plane, n);
  const std::size_t chunk = std::clamp<std::uint64_t>(budget / (32 * plane), 16, 1 << 16);

  LabelMeshCounts counts;
  for (const Fragment& f : fragments) counts.triangles += f.entry.triangles;
  const Scratch vertexFile(path, "vertices"), remapFile(path, "numbers");
  const Fd remap(remapFile.path, O_RDWR | O_CREAT | O_TRUNC);
  if (!remap.ok()) throw std::runtime_error("cannot create a temporary file beside '" + path + "'");
  Streams streams(fragments, chunk, cancel);
  {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> vertices(std::fopen(vertexFile.path.c_str(), "wb"), &std::fclose);
    if (!vertices) throw std::runtime_error("cannot create a temporary file beside '" + path + "'");
    counts.vertices = streams.vertices(geometry, vertices.get(), remap);
    if (std::fclose(vertices.release()) != 0) throw std::runtime_error("cannot write a temporary file (disk full?)");
  }
  // The header writePly writes, then the vertices, then the triangles (MeshIO.cpp).
  writeFileAtomically(path, [&](const std::string& temporary) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(temporary.c_str(), "wb"), &std::fclose);
    if (!out) return false;
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                               std::to_string(counts.vertices) +
                               "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                               std::to_string(counts.triangles) + "\nproperty list uchar int vertex_indices\nend_header\n";
    if (std::fwrite(header.data(), 1, header.size(), out.get()) != header.size()) return false;
    {
      std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(vertexFile.path.c_str(), "rb"), &std::fclose);
      if (!in) return false;
      std::vector<char> buffer(1 << 20);
      for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), in.get())) > 0;)
        if (std::fwrite(buffer.data(), 1, n, out.get()) != n) return false;
    }
    streams.triangles(remap, geometry.handedness() < 0, out.get());
    return std::fclose(out.release()) == 0;
  });
  return counts;
}

}  // namespace surftrack
