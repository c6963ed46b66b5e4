// A block's label fragments as one flat binary file (LabelBlockFiles.h; docs/api.md, "Fragment
// files"), and a label's merge straight from such files. Flat arrays rather than a zip of numpy
// arrays: the merge reads a label's bytes with one seek and one read, no Python between
// (docs/performance.md, "Label maps by blocks on Dask"). Every length is checked against the
// file's size and every byte against a checksum before use, so a truncated or damaged file is
// a one-line error naming it, never a crash or a wrong mesh.
#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

#include "BlockOwnership.h"
#include "Errors.h"
#include "FragmentChecksum.h"
#include "LabelBlockFiles.h"

namespace surftrack {
namespace {

static_assert(std::endian::native == std::endian::little, "fragment files are written little-endian as in memory");

constexpr char kMagic[8] = {'S', 'T', 'F', 'R', 'A', 'G', '\r', '\n'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 80, kEntryBytes = 56;

/// The file's checksum (FragmentChecksum.h).
std::uint64_t checksum(const void* data, std::size_t bytes, std::uint64_t h = FragmentChecksum::kSeed) {
  return fragmentChecksum(data, bytes, h);
}

template <class T>
void put(std::vector<unsigned char>& out, T v) {
  const std::size_t at = out.size();
  out.resize(at + sizeof v);
  std::memcpy(out.data() + at, &v, sizeof v);
}

template <class T>
T take(const unsigned char*& p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  p += sizeof v;
  return v;
}

struct File {
  std::FILE* f = nullptr;
  ~File() {
    if (f) std::fclose(f);
  }
};

[[noreturn]] void bad(const std::string& path, const std::string& what) {
  throw InvalidInput("fragment file '" + path + "': " + what);
}

void readAt(const std::string& path, std::FILE* f, std::uint64_t offset, void* data, std::size_t bytes) {
  if (bytes == 0) return;
  if (fseeko(f, off_t(offset), SEEK_SET) != 0 || std::fread(data, 1, bytes, f) != bytes)
    bad(path, "truncated (cannot read " + std::to_string(bytes) + " bytes at " + std::to_string(offset) + ")");
}

/// The data bytes of an entry, overflow-checked: keys then triangles.
bool dataBytes(const FragmentFileIndex::Entry& e, std::uint64_t& bytes) {
  constexpr std::uint64_t kMax = std::uint64_t(1) << 60;
  if (e.keys > kMax / 8 || e.triangles > kMax / 12) return false;
  bytes = 8 * e.keys + 12 * e.triangles;
  return true;
}

}  // namespace

const FragmentFileIndex::Entry* FragmentFileIndex::find(LabelValue label) const {
  auto at = std::lower_bound(entries.begin(), entries.end(), label,
                             [](const Entry& e, const LabelValue& L) { return e.label < L; });
  return at != entries.end() && at->label == label ? &*at : nullptr;
}

void writeLabelFragmentFile(const std::string& path, Dims volume, Voxel lo, Voxel hi,
                            const std::vector<LabelFragment>& fragments) {
  for (std::size_t i = 1; i < fragments.size(); ++i)
    if (!(fragments[i - 1].label < fragments[i].label))
      throw InvalidInput("fragments to write are not by increasing label");
  std::vector<unsigned char> head;
  head.insert(head.end(), kMagic, kMagic + 8);
  put(head, kVersion);
  put(head, std::uint32_t(kEntryBytes));
  for (int a = 0; a < 3; ++a) put(head, std::int32_t(volume[a]));
  for (int a = 0; a < 3; ++a) put(head, std::int32_t(lo[a]));
  for (int a = 0; a < 3; ++a) put(head, std::int32_t(hi[a]));
  put(head, std::uint32_t(0));
  put(head, std::uint64_t(fragments.size()));
  std::uint64_t length = kHeaderBytes + kEntryBytes * fragments.size();
  for (const LabelFragment& f : fragments) length += 8 * f.keys.size() + 12 * f.triangles.size();
  put(head, length);
  const std::size_t checksumAt = head.size();
  put(head, std::uint64_t(0));  // the checksum of the header and index, filled in below
  std::uint64_t offset = kHeaderBytes + kEntryBytes * fragments.size();
  for (const LabelFragment& f : fragments) {
    put(head, std::uint64_t(f.label.negative()));
    put(head, f.label.magnitude());
    put(head, f.voxels);
    put(head, std::uint64_t(f.keys.size()));
    put(head, std::uint64_t(f.triangles.size()));
    put(head, offset);
    const std::uint64_t sum =
        checksum(f.triangles.data(), 12 * f.triangles.size(), checksum(f.keys.data(), 8 * f.keys.size()));
    put(head, sum);
    offset += 8 * f.keys.size() + 12 * f.triangles.size();
  }
  const std::uint64_t sum = checksum(head.data(), head.size());
  std::memcpy(head.data() + checksumAt, &sum, 8);

  // A temporary name no other writer of the same file takes, in the same directory (rename is
  // atomic within a file system).
  std::random_device entropy;
  const std::string temporary = path + ".tmp-" + std::to_string(entropy()) + std::to_string(entropy());
  {
    File out{std::fopen(temporary.c_str(), "wb")};
    if (!out.f) throw std::runtime_error("cannot write the fragment file '" + temporary + "'");
    bool ok = std::fwrite(head.data(), 1, head.size(), out.f) == head.size();
    for (const LabelFragment& f : fragments) {
      ok = ok && (f.keys.empty() || std::fwrite(f.keys.data(), 8, f.keys.size(), out.f) == f.keys.size());
      ok = ok && (f.triangles.empty() ||
                  std::fwrite(f.triangles.data(), 12, f.triangles.size(), out.f) == f.triangles.size());
    }
    ok = std::fflush(out.f) == 0 && ok;
    ok = std::fclose(out.f) == 0 && ok;
    out.f = nullptr;
    if (!ok) {
      std::remove(temporary.c_str());
      throw std::runtime_error("cannot write the fragment file '" + temporary + "' (disk full?)");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot rename '" + temporary + "' to '" + path + "': " + error.message());
  }
}

FragmentFileIndex readFragmentFileIndex(const std::string& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) bad(path, "cannot be read (" + error.message() + ")");
  File in{std::fopen(path.c_str(), "rb")};
  if (!in.f) bad(path, "cannot be opened");
  unsigned char header[kHeaderBytes];
  if (size < kHeaderBytes) bad(path, "truncated (" + std::to_string(size) + " bytes, shorter than a header)");
  readAt(path, in.f, 0, header, kHeaderBytes);
  if (std::memcmp(header, kMagic, 8) != 0) bad(path, "not a surftrack fragment file");
  const unsigned char* p = header + 8;
  const auto version = take<std::uint32_t>(p);
  if (version != kVersion)
    bad(path, "format version " + std::to_string(version) + ", this build reads version " + std::to_string(kVersion));
  if (take<std::uint32_t>(p) != kEntryBytes) bad(path, "corrupted (index entry size)");
  FragmentFileIndex index;
  int v[9];
  for (int& x : v) x = take<std::int32_t>(p);
  index.volume = Dims{v[0], v[1], v[2]};
  index.lo = Voxel{v[3], v[4], v[5]};
  index.hi = Voxel{v[6], v[7], v[8]};
  take<std::uint32_t>(p);
  const auto count = take<std::uint64_t>(p);
  const auto length = take<std::uint64_t>(p);
  const auto sum = take<std::uint64_t>(p);
  if (length != size)
    bad(path, (size < length ? "truncated (" : "corrupted (") + std::to_string(size) + " bytes, the header says " +
                  std::to_string(length) + ")");
  if (count > (size - kHeaderBytes) / kEntryBytes) bad(path, "corrupted (label count beyond the file)");
  std::vector<unsigned char> head(kHeaderBytes + kEntryBytes * count);
  std::memcpy(head.data(), header, kHeaderBytes);
  readAt(path, in.f, kHeaderBytes, head.data() + kHeaderBytes, kEntryBytes * count);
  std::memset(head.data() + kHeaderBytes - 8, 0, 8);
  if (checksum(head.data(), head.size()) != sum) bad(path, "corrupted (header or index checksum)");

  for (int a = 0; a < 3; ++a)
    if (index.volume[a] < 1 || index.lo[a] < 0 || index.lo[a] >= index.hi[a] || index.hi[a] > index.volume[a])
      bad(path, "corrupted (its block is not in its volume)");
  std::uint64_t offset = kHeaderBytes + kEntryBytes * count;
  p = head.data() + kHeaderBytes;
  index.entries.resize(count);
  for (auto& e : index.entries) {
    const auto negative = take<std::uint64_t>(p);
    const auto magnitude = take<std::uint64_t>(p);
    if (negative > 1 || (negative && (magnitude == 0 || magnitude > (std::uint64_t(1) << 63))))
      bad(path, "corrupted (a label out of range)");
    e.label = negative ? LabelValue(std::int64_t(0 - magnitude)) : LabelValue(magnitude);
    e.voxels = take<std::uint64_t>(p);
    e.keys = take<std::uint64_t>(p);
    e.triangles = take<std::uint64_t>(p);
    e.offset = take<std::uint64_t>(p);
    e.checksum = take<std::uint64_t>(p);
    std::uint64_t bytes = 0;
    if (e.offset != offset || !dataBytes(e, bytes) || bytes > size - offset)
      bad(path, "corrupted (an index entry beyond the file)");
    offset += bytes;
  }
  if (offset != size) bad(path, "corrupted (the index does not cover the file)");
  for (std::size_t i = 1; i < count; ++i)
    if (!(index.entries[i - 1].label < index.entries[i].label)) bad(path, "corrupted (labels not increasing)");
  return index;
}

LabelFragment readLabelFragment(const std::string& path, const FragmentFileIndex::Entry& entry) {
  std::uint64_t bytes = 0;
  if (!dataBytes(entry, bytes)) bad(path, "corrupted (an index entry beyond the file)");
  File in{std::fopen(path.c_str(), "rb")};
  if (!in.f) bad(path, "cannot be opened");
  LabelFragment f;
  f.label = entry.label;
  f.voxels = entry.voxels;
  f.keys.resize(entry.keys);
  f.triangles.resize(entry.triangles);
  readAt(path, in.f, entry.offset, f.keys.data(), 8 * f.keys.size());
  readAt(path, in.f, entry.offset + 8 * entry.keys, f.triangles.data(), 12 * f.triangles.size());
  if (checksum(f.triangles.data(), 12 * f.triangles.size(), checksum(f.keys.data(), 8 * f.keys.size())) !=
      entry.checksum)
    bad(path, "corrupted (the data of label " + entry.label.text() + " do not match their checksum)");
  // Checked as well, so that no file, however made, reaches the merge with indices beyond its keys.
  if (!validKeys(f.keys)) bad(path, "label " + entry.label.text() + " has keys out of range or not increasing");
  for (const auto& t : f.triangles)
    for (std::uint32_t v : t)
      if (v >= f.keys.size()) bad(path, "label " + entry.label.text() + " has a triangle beyond its vertices");
  return f;
}

LabelSurface mergeLabelFragmentFiles(LabelValue label, const std::vector<std::string>& paths,
                                     const ImageGeometry& geometry, const LabelOptions& options) {
  std::vector<LabelFragment> fragments;
  for (const std::string& path : paths) {
    const FragmentFileIndex index = readFragmentFileIndex(path);
    if (const auto* e = index.find(label)) fragments.push_back(readLabelFragment(path, *e));
  }
  if (fragments.empty()) throw InvalidInput("no fragment file holds label " + label.text());
  return mergeLabelFragments(fragments, geometry, options);
}

}  // namespace surftrack
