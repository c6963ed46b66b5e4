// libFuzzer target: arbitrary bytes as a volume file of one format, "mha", "mhd", "nrrd",
// "nhdr", "nii", "nii.gz", "raw" or "tif", named by the program's name:
// fuzz_volume_header_<format> (one binary, one link to it per format, fuzz/CMakeLists.txt).
//
// Each input goes through
//  1. the format's header parser (io/VolumeHeader.h; io/TiffStack.h for tif) on the input
//     buffer itself, whole and cut in half: libFuzzer's buffer is exactly the input, so
//     AddressSanitizer reports any read past it;
//  2. the whole loader on a file holding the input (loadVolume, or loadRawVolume with a layout
//     taken from the input's first bytes), every voxel of the result read (a read past a
//     mapping is a SIGSEGV or SIGBUS: a crash);
//  3. when the loader accepts the input, readVolume (readRawVolume) on the same file: both must
//     give the same type, dimensions, geometry and voxels, or the target aborts.
// It must never crash, hang or report a sanitizer error; ReadError is the expected failure.
// Headers that name a data file (.mhd, .nhdr) find "data.raw" (64 KiB) next to the input, so
// that the seeds (fuzz/make_seed_corpus.cpp) reach the mapping.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <string_view>

#include "LoadVolume.h"
#include "ReadVolume.h"
#include "TiffStack.h"
#include "VolumeHeader.h"

namespace {

namespace fs = std::filesystem;
using namespace surftrack;

std::string gFormat;  // from the program's name, set once by LLVMFuzzerInitialize

std::string gInput;  // the file that holds each input

void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz_volume_header (%s): %s\n", gFormat.c_str(), what.c_str());
  std::abort();
}

/// Reads every voxel of a view (so that a bad mapping or offset faults here) and returns a sum.
double touchAll(const VolumeView& v) {
  double sum = 0;
  visitScalarType(v.type, [&](auto t) {
    using T = decltype(t);
    const auto* p = static_cast<const T*>(v.data);
    for (int z = 0; z < v.dims.nz; ++z)
      for (int y = 0; y < v.dims.ny; ++y)
        for (int x = 0; x < v.dims.nx; ++x) {
          const T value = p[x * v.strides[0] + y * v.strides[1] + z * v.strides[2]];
          sum += std::isfinite(double(value)) ? double(value) : 0.0;
        }
  });
  return sum;
}

/// The same type, dimensions and geometry as readVolume, and the same voxels unless ITK decoded
/// both (two decodes of one corrupt file may differ: ITK 5.2's MetaIO does not report corrupt
/// compressed data and leaves the voxels as they were allocated).
void requireSame(const io::LoadedVolume& loaded, const io::AnyVolume& read) {
  if (loaded.view.type != io::scalarTypeOf(read)) fail("loadVolume and readVolume disagree on the voxel type");
  if (loaded.view.dims != io::dimsOf(read)) fail("loadVolume and readVolume disagree on the dimensions");
  const ImageGeometry& a = loaded.view.geometry;
  const ImageGeometry& b = io::geometryOf(read);
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(a.spacing[i] - b.spacing[i]) <= 1e-9) || !(std::abs(a.origin[i] - b.origin[i]) <= 1e-9))
      fail("loadVolume and readVolume disagree on the geometry");
    for (int j = 0; j < 3; ++j)
      if (!(std::abs(a.direction[i][j] - b.direction[i][j]) <= 1e-9))
        fail("loadVolume and readVolume disagree on the direction");
  }
  const std::string_view byItk = "(decoded by ITK)";
  if (loaded.decodeReason.size() >= byItk.size() &&
      loaded.decodeReason.compare(loaded.decodeReason.size() - byItk.size(), byItk.size(), byItk) == 0)
    return;
  std::visit([&](const auto& image) {
    const std::size_t size = sizeOf(loaded.view.type);
    const auto* p = static_cast<const unsigned char*>(loaded.view.data);
    for (std::size_t i = 0; i < image.data().size(); ++i)
      if (std::memcmp(p + i * size, &image.data()[i], size) != 0) {
        double a = 0;
        visitScalarType(loaded.view.type, [&](auto t) {
          decltype(t) v;
          std::memcpy(&v, p + i * size, size);
          a = double(v);
        });
        fail("loadVolume and readVolume disagree on voxel " + std::to_string(i) + ": " + std::to_string(a) + " (" +
             std::to_string(a == 0 ? 0 : std::log10(std::abs(a))) + " decades) against " +
             std::to_string(double(image.data()[i])) + " (" + loaded.decodeReason + ")");
      }
  }, read);
}

/// The TIFF metadata parser (io/TiffStack.h) on the input buffer itself, whole.
void parseTiffBuffer(std::string_view bytes) {
  try {
    const io::TiffStack stack = io::parseTiffStack(
        [&](std::uint64_t offset, std::size_t n) {
          return offset >= bytes.size() ? std::string() : std::string(bytes.substr(std::size_t(offset), n));
        },
        bytes.size(), "input.tif");
    if (stack.channels < 1 || stack.slices < 1 || stack.pages() > (std::int64_t(1) << 31))
      fail("the TIFF parser gives an impossible stack");
  } catch (const io::HeaderError&) {
  }
}

void parseBuffer(std::string_view bytes) {
  using Parse = std::optional<io::DataLayout> (*)(std::string_view, std::uint64_t);
  Parse parse = gFormat == "nii" ? io::parseNifti1Header
              : gFormat == "mha" || gFormat == "mhd" ? io::parseMetaImageHeader
                                                     : io::parseNrrdHeader;
  for (std::string_view head : {bytes, bytes.substr(0, bytes.size() / 2)}) {
    try {
      const auto layout = parse(head, bytes.size());
      if (!layout && head.size() == bytes.size()) fail("the parser asks for more bytes of a whole file");
      if (layout && layout->decodeReason.empty() && layout->dataFile.empty() &&
          (layout->offset > bytes.size() || bytes.size() - layout->offset < layout->dataBytes()))
        fail("the parser places the voxels outside the file");
    } catch (const io::HeaderError&) {
    }
  }
}

void writeInput(const uint8_t* data, size_t size) {
  std::ofstream out(gInput, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) fail("cannot write " + gInput);
}

void fuzzRaw(const uint8_t* data, size_t size) {
  // The layout from the first 5 bytes: type, byte order, header bytes, dimensions (1 to 16).
  if (size < 5) return;
  io::RawLayout layout;
  layout.type = ScalarType(data[0] % 10);
  layout.bigEndian = data[0] & 0x80;
  layout.headerBytes = data[1] % 32;
  layout.dims = {1 + data[2] % 16, 1 + data[3] % 16, 1 + data[4] % 16};
  writeInput(data + 5, size - 5);
  try {
    const io::LoadedVolume loaded = io::loadRawVolume(gInput, layout);
    touchAll(loaded.view);
    requireSame(loaded, io::readRawVolume(gInput, layout));
  } catch (const io::ReadError&) {
  }
}

void fuzzFile(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (gFormat == "tif")
    parseTiffBuffer(bytes);
  else if (gFormat != "nii.gz")  // (gzip'd bytes: the parser sees them inflated, through the loader)
    parseBuffer(bytes);
  writeInput(data, size);
  // A TIFF stack's channel: none, 0 or 1, by the input's length.
  io::ReadOptions options;
  if (gFormat == "tif" && size % 3 != 0) options.channel = int(size % 3) - 1;
  io::LoadedVolume loaded;
  try {
    loaded = io::loadVolume(gInput, options);
  } catch (const io::ReadError&) {
    return;
  }
  touchAll(loaded.view);
  io::AnyVolume read;
  try {
    read = io::readVolume(gInput, options);
  } catch (const io::ReadError& e) {
    fail(std::string("loadVolume accepts what readVolume rejects: ") + e.what());
  }
  requireSame(loaded, read);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const std::string name = *argc > 0 ? fs::path((*argv)[0]).filename().string() : "";
  const std::string prefix = "fuzz_volume_header_";
  gFormat = name.rfind(prefix, 0) == 0 ? name.substr(prefix.size()) : "";
  if (gFormat != "mha" && gFormat != "mhd" && gFormat != "nrrd" && gFormat != "nhdr" && gFormat != "nii" &&
      gFormat != "nii.gz" && gFormat != "raw" && gFormat != "tif")
    fail("run me as fuzz_volume_header_<format>, format mha, mhd, nrrd, nhdr, nii, nii.gz, raw or tif (not '" + name +
         "')");
  // One directory per process (libFuzzer's -jobs/-workers run several): under /dev/shm when
  // there is one, so that the inputs never reach a disk.
  const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
  std::string dir = (base / "surftrack-fuzz-XXXXXX").string();
  if (!::mkdtemp(dir.data())) fail("mkdtemp failed");
  gInput = (fs::path(dir) / ("input." + std::string(gFormat))).string();
  std::string data(65536, '\0');
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = char(i * 131 + (i >> 8));
  std::ofstream(fs::path(dir) / "data.raw", std::ios::binary).write(data.data(), std::streamsize(data.size()));
  std::atexit([] {
    std::error_code ec;
    fs::remove_all(fs::path(gInput).parent_path(), ec);
  });
  std::cerr.rdbuf(nullptr);  // ITK's MetaIO and NRRD readers complain on std::cerr: not a finding
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > (1 << 20)) return 0;
  if (gFormat == "raw")
    fuzzRaw(data, size);
  else
    fuzzFile(data, size);
  return 0;
}
