// io/LoadVolume.h: every format and voxel type written by ITK (and, for big-endian data, byte
// skips and header sizes, by hand) loads with the same dimensions, type, geometry and voxels as
// readVolume; exactly the uncompressed little-endian files with aligned voxels are mapped;
// truncated files and corrupt headers are ReadErrors naming the file; a freshly mapped 64 MiB
// file is not read until its voxels are touched.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <zlib.h>

#include "LoadVolume.h"
#include "ReadVolume.h"
#include "VolumeHeader.h"

namespace fs = std::filesystem;
using namespace surftrack;
using io::LoadedVolume;

namespace {

/// A fresh directory under the system's temporary directory, removed at the end.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "surftrack-load-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::uint64_t mix(std::uint64_t x) {  // splitmix64
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// Voxel values that use every byte of the type (so that a byte-order or offset error shows),
/// exact in float for the floating types.
template <class T>
T valueAt(int x, int y, int z) {
  const std::uint64_t h = mix((std::uint64_t(z) * 1000003u + std::uint64_t(y)) * 1000003u + std::uint64_t(x));
  if constexpr (std::is_floating_point_v<T>) {
    return T((double(h % 2000001) - 1000000.0) / 8.0);
  } else {
    T v;
    std::memcpy(&v, &h, sizeof(T));
    return v;
  }
}

/// A rotated, anisotropic, displaced frame (orthonormal, as NIfTI and DICOM need).
ImageGeometry testGeometry() {
  ImageGeometry g;
  g.spacing = {0.7, 1.3, 2.1};
  g.origin = {-12.5, 40.25, 7.0};
  const double a = 0.5, c = std::cos(a), s = std::sin(a);  // rotation about z, then about x
  const double b = 0.3, cb = std::cos(b), sb = std::sin(b);
  const double rz[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
  const double rx[3][3] = {{1, 0, 0}, {0, cb, -sb}, {0, sb, cb}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      g.direction[i][j] = 0;
      for (int k = 0; k < 3; ++k) g.direction[i][j] += rx[i][k] * rz[k][j];
    }
  return g;
}

template <class T>
DenseImage<T> makeVolume(Dims dims, const ImageGeometry& geometry = testGeometry()) {
  DenseImage<T> image(dims, T{}, geometry);
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x) image.at(x, y, z) = valueAt<T>(x, y, z);
  return image;
}

const unsigned char* voxelAt(const VolumeView& v, int x, int y, int z) {
  return static_cast<const unsigned char*>(v.data) +
         (x * v.strides[0] + y * v.strides[1] + z * v.strides[2]) * std::ptrdiff_t(sizeOf(v.type));
}

/// The loaded volume has the dimensions, type, geometry (1e-9) and every voxel of readVolume's.
void expectSame(const LoadedVolume& loaded, const io::AnyVolume& read, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_NE(loaded.view.data, nullptr);
  EXPECT_EQ(loaded.owner.get(), loaded.view.data);
  ASSERT_EQ(loaded.view.type, io::scalarTypeOf(read));
  ASSERT_EQ(loaded.view.dims, io::dimsOf(read));
  const ImageGeometry& a = loaded.view.geometry;
  const ImageGeometry& b = io::geometryOf(read);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.spacing[i], b.spacing[i], 1e-9);
    EXPECT_NEAR(a.origin[i], b.origin[i], 1e-9);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(a.direction[i][j], b.direction[i][j], 1e-9);
  }
  const Dims d = loaded.view.dims;
  const std::size_t size = sizeOf(loaded.view.type);
  EXPECT_EQ(loaded.dataBytes, d.count() * size);
  EXPECT_EQ(loaded.view.strides[0], 1);
  EXPECT_EQ(loaded.view.strides[1], d.nx);
  EXPECT_EQ(loaded.view.strides[2], std::ptrdiff_t(d.nx) * d.ny);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(loaded.view.data) % size, 0u) << "misaligned voxels";
  std::visit([&](const auto& image) {
    std::size_t mismatches = 0;
    for (int z = 0; z < d.nz; ++z)
      for (int y = 0; y < d.ny; ++y)
        for (int x = 0; x < d.nx; ++x)
          mismatches += std::memcmp(voxelAt(loaded.view, x, y, z), &image.at(x, y, z), size) != 0;
    EXPECT_EQ(mismatches, 0u);
  }, read);
}

/// The loaded voxels are those of `image` (the volume that was written).
template <class T>
void expectVoxels(const LoadedVolume& loaded, const DenseImage<T>& image) {
  ASSERT_EQ(loaded.view.type, scalarTypeOf<T>());
  ASSERT_EQ(loaded.view.dims, image.dims());
  std::size_t mismatches = 0;
  const Dims d = image.dims();
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x)
        mismatches += std::memcmp(voxelAt(loaded.view, x, y, z), &image.at(x, y, z), sizeof(T)) != 0;
  EXPECT_EQ(mismatches, 0u);
}

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

template <class T>
std::string bytesOf(const DenseImage<T>& image, bool bigEndian = false) {
  std::string out(reinterpret_cast<const char*>(image.data().data()), image.data().size() * sizeof(T));
  if (bigEndian)
    for (std::size_t i = 0; i < out.size(); i += sizeof(T)) std::reverse(out.begin() + i, out.begin() + i + sizeof(T));
  return out;
}

/// Where an attached header of ITK's ends, found without the loader's parsers: after NRRD's empty
/// line, after MetaImage's "ElementDataFile = LOCAL" line.
std::size_t attachedOffset(const std::string& path) {
  const std::string bytes = contents(path);
  if (bytes.rfind("NRRD", 0) == 0) return bytes.find("\n\n") + 2;
  const std::string line = "ElementDataFile = LOCAL\n";
  return bytes.find(line) + line.size();
}

/// Calls f and expects a one-line ReadError whose message contains every one of `parts`.
void expectReadError(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no ReadError; expected one mentioning " << *parts.begin();
  } catch (const io::ReadError& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message << "\n  lacks: " << part;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

void truncateTo(const std::string& path, std::uintmax_t size) { fs::resize_file(path, size); }

template <class T>
constexpr const char* nrrdType() {
  switch (scalarTypeOf<T>()) {
    case ScalarType::UInt8: return "uint8";
    case ScalarType::Int8: return "int8";
    case ScalarType::UInt16: return "uint16";
    case ScalarType::Int16: return "int16";
    case ScalarType::UInt32: return "uint32";
    case ScalarType::Int32: return "int32";
    case ScalarType::UInt64: return "uint64";
    case ScalarType::Int64: return "int64";
    case ScalarType::Float32: return "float";
    case ScalarType::Float64: return "double";
  }
  return "";
}

template <class T>
constexpr const char* metaType() {
  switch (scalarTypeOf<T>()) {
    case ScalarType::UInt8: return "MET_UCHAR";
    case ScalarType::Int8: return "MET_CHAR";
    case ScalarType::UInt16: return "MET_USHORT";
    case ScalarType::Int16: return "MET_SHORT";
    case ScalarType::UInt32: return "MET_UINT";
    case ScalarType::Int32: return "MET_INT";
    case ScalarType::UInt64: return "MET_ULONG_LONG";
    case ScalarType::Int64: return "MET_LONG_LONG";
    case ScalarType::Float32: return "MET_FLOAT";
    case ScalarType::Float64: return "MET_DOUBLE";
  }
  return "";
}

std::string nrrdHeader(const std::string& type, Dims d, const std::string& extra) {
  return "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: " + std::to_string(d.nx) + " " +
         std::to_string(d.ny) + " " + std::to_string(d.nz) +
         "\nspace: left-posterior-superior\nspace directions: (0.5,0,0) (0,0.75,0) (0,0,2)\n"
         "space origin: (1,2,3)\n" + extra;
}

std::string metaHeader(const std::string& type, Dims d, const std::string& extra, const std::string& dataFile) {
  return "ObjectType = Image\nNDims = 3\nDimSize = " + std::to_string(d.nx) + " " + std::to_string(d.ny) + " " +
         std::to_string(d.nz) + "\nElementSpacing = 0.5 0.75 2\nOffset = 1 2 3\n" + extra +
         "ElementType = " + type + "\nElementDataFile = " + dataFile + "\n";
}

const Dims kDims{7, 5, 3};

// ---------------------------------------------------------------------------------------------
// Every format, every type.

template <class T>
class LoadEveryType : public ::testing::Test {};
using AllTypes = ::testing::Types<std::uint8_t, std::int8_t, std::uint16_t, std::int16_t, std::uint32_t,
                                  std::int32_t, std::uint64_t, std::int64_t, float, double>;
TYPED_TEST_SUITE(LoadEveryType, AllTypes);

TYPED_TEST(LoadEveryType, UncompressedFilesAreMappedAndEqualToReadVolume) {
  using T = TypeParam;
  TempDir dir;
  const DenseImage<T> image = makeVolume<T>(kDims);
  for (const std::string ext : {"nrrd", "nhdr", "mha", "mhd", "nii"}) {
    const std::string path = dir / ("v-" + ext + "." + ext);
    io::writeVolume(io::AnyVolume(image), path);
    const LoadedVolume loaded = io::loadVolume(path);
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
    EXPECT_EQ(loaded.format, ext);
    // Attached headers of odd length leave multi-byte voxels unaligned: those are read.
    const bool attached = ext == "nrrd" || ext == "mha";
    const bool aligned = !attached || attachedOffset(path) % sizeof(T) == 0;
    EXPECT_EQ(loaded.mapped, aligned) << path << ": " << loaded.decodeReason;
    if (loaded.mapped) {
      EXPECT_TRUE(loaded.decodeReason.empty()) << loaded.decodeReason;
    } else {
      EXPECT_NE(loaded.decodeReason.find("not aligned"), std::string::npos) << loaded.decodeReason;
    }
  }
}

TYPED_TEST(LoadEveryType, AttachedHeadersPaddedToAlignmentAreMapped) {
  using T = TypeParam;
  TempDir dir;
  const DenseImage<T> image = makeVolume<T>(kDims);
  for (const std::string ext : {"nrrd", "mha"}) {
    const std::string path = dir / ("p." + ext);
    io::writeVolume(io::AnyVolume(image), path);
    // Pad the header (a NRRD comment, a MetaImage Comment field after ObjectType) so that the
    // voxels start at a multiple of 8 bytes.
    std::string bytes = contents(path);
    const std::size_t offset = attachedOffset(path);
    const std::size_t firstLine = bytes.find('\n') + 1;
    std::string pad = ext == "nrrd" ? "# pad\n" : "Comment = pad\n";
    while ((offset + pad.size()) % 8 != 0) pad.insert(pad.end() - 1, 'd');
    bytes.insert(firstLine, pad);
    writeFile(path, bytes);
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_TRUE(loaded.mapped) << path << ": " << loaded.decodeReason;
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
}

TYPED_TEST(LoadEveryType, CompressedFilesAreDecodedOnce) {
  using T = TypeParam;
  TempDir dir;
  const DenseImage<T> image = makeVolume<T>(kDims);
  for (const std::string name : {"c.nrrd", "c.mha", "c.nii.gz"}) {
    const std::string path = dir / name;
    io::writeVolume(io::AnyVolume(image), path, /*compress=*/true);
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_FALSE(loaded.mapped) << path;
    EXPECT_FALSE(loaded.decodeReason.empty());
    EXPECT_EQ(loaded.format, name.substr(2));
    EXPECT_EQ(loaded.residentBytes(), loaded.dataBytes);
    // A .nii.gz is inflated by the loader, its voxels 64-byte aligned; the others by ITK.
    const bool gzippedNifti = name == "c.nii.gz";
    EXPECT_NE(loaded.decodeReason.find(gzippedNifti ? "inflated into memory" : "ITK"), std::string::npos) << loaded.decodeReason;
    if (gzippedNifti) {
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(loaded.view.data) % 64, 0u);
    }
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
}

TYPED_TEST(LoadEveryType, BigEndianFilesAreDecodedOneByteFilesMapped) {
  using T = TypeParam;
  TempDir dir;
  const DenseImage<T> image = makeVolume<T>(kDims);
  const bool multiByte = sizeof(T) > 1;
  const std::string nrrd = dir / "be.nrrd";
  writeFile(nrrd, nrrdHeader(nrrdType<T>(), kDims, "endian: big\nencoding: raw\n") + "\n" + bytesOf(image, true));
  const std::string mha = dir / "be.mha";
  writeFile(mha, metaHeader(metaType<T>(), kDims, "ElementByteOrderMSB = True\n", "LOCAL") + bytesOf(image, true));
  for (const std::string& path : {nrrd, mha}) {
    const LoadedVolume loaded = io::loadVolume(path);
    if (multiByte) {
      EXPECT_FALSE(loaded.mapped) << path;
      EXPECT_NE(loaded.decodeReason.find("big-endian"), std::string::npos) << loaded.decodeReason;
    } else {
      EXPECT_TRUE(loaded.mapped) << path << ": " << loaded.decodeReason;
    }
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
}

TYPED_TEST(LoadEveryType, RawFiles) {
  using T = TypeParam;
  TempDir dir;
  const DenseImage<T> image = makeVolume<T>(kDims);
  for (const bool bigEndian : {false, true})
    for (const std::size_t header : {std::size_t(0), std::size_t(16), std::size_t(3)}) {
      const std::string path = dir / ("r" + std::to_string(header) + (bigEndian ? "be" : "le") + ".raw");
      writeFile(path, std::string(header, 'h') + bytesOf(image, bigEndian));
      io::RawLayout layout;
      layout.dims = kDims;
      layout.type = scalarTypeOf<T>();
      layout.bigEndian = bigEndian;
      layout.headerBytes = header;
      layout.geometry = testGeometry();
      const LoadedVolume loaded = io::loadRawVolume(path, layout);
      const bool swap = bigEndian && sizeof(T) > 1;
      EXPECT_EQ(loaded.mapped, !swap && header % sizeof(T) == 0) << path << ": " << loaded.decodeReason;
      EXPECT_EQ(loaded.format, "raw");
      expectSame(loaded, io::readRawVolume(path, layout), path);
      expectVoxels(loaded, image);
    }
}

// ---------------------------------------------------------------------------------------------
// Offsets: NRRD byte skip, MetaImage HeaderSize, 2D images.

TEST(LoadVolume, ByteSkipAndHeaderSizeAreHonoured) {
  TempDir dir;
  using T = std::int16_t;
  const DenseImage<T> image = makeVolume<T>(kDims);
  const std::string data = bytesOf(image);
  struct Case {
    std::string header, headerText, dataFile, dataBytes;
    bool mapped;
  };
  const std::vector<Case> cases = {
      // NRRD, detached, 16 bytes skipped: mapped.
      {"skip.nhdr", nrrdHeader("int16", kDims, "endian: little\nencoding: raw\nbyte skip: 16\ndata file: skip.raw\n"),
       "skip.raw", std::string(16, 's') + data, true},
      // NRRD, detached, the last bytes of the file: mapped (offset 10 + 0: aligned to 2).
      {"end.nhdr", nrrdHeader("int16", kDims, "endian: little\nencoding: raw\nbyte skip: -1\ndata file: end.raw\n"),
       "end.raw", std::string(10, 'e') + data, true},
      // MetaImage, detached, HeaderSize 16: mapped.
      {"hs.mhd", metaHeader("MET_SHORT", kDims, "HeaderSize = 16\n", "hs.raw"), "hs.raw", std::string(16, 'h') + data, true},
      // MetaImage, detached, HeaderSize -1 (the last bytes), 11 bytes before them: read (misaligned).
      {"hsend.mhd", metaHeader("MET_SHORT", kDims, "HeaderSize = -1\n", "hsend.raw"), "hsend.raw",
       std::string(11, 'h') + data, false},
  };
  for (const Case& c : cases) {
    writeFile(dir / c.header, c.headerText);
    writeFile(dir / c.dataFile, c.dataBytes);
    const std::string path = dir / c.header;
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_EQ(loaded.mapped, c.mapped) << path << ": " << loaded.decodeReason;
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
  // NRRD, attached, byte skip 6 after the header; then "byte skip: -1" (the end of the file).
  for (const std::string skip : {"6", "-1"}) {
    const std::string path = dir / ("attached" + skip + ".nrrd");
    writeFile(path, nrrdHeader("int16", kDims, "endian: little\nencoding: raw\nbyte skip: " + skip + "\n") + "\n" +
                        std::string(6, 'x') + data);
    const LoadedVolume loaded = io::loadVolume(path);
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
  // MetaImage, attached, HeaderSize -1.
  const std::string mha = dir / "end.mha";
  writeFile(mha, metaHeader("MET_SHORT", kDims, "HeaderSize = -1\n", "LOCAL") + std::string(5, 'x') + data);
  expectSame(io::loadVolume(mha), io::readVolume(mha), mha);
  expectVoxels(io::loadVolume(mha), image);
}

TEST(LoadVolume, TwoDimensionalImagesAreOneSlice) {
  TempDir dir;
  const DenseImage<std::uint16_t> image = makeVolume<std::uint16_t>(Dims{9, 4, 1});
  const std::string nrrd = dir / "flat.nhdr";
  writeFile(nrrd, "NRRD0004\ntype: uint16\ndimension: 2\nsizes: 9 4\nendian: little\nencoding: raw\n"
                  "spacings: 0.5 0.25\ndata file: flat.raw\n");
  writeFile(dir / "flat.raw", bytesOf(image));
  const std::string mhd = dir / "flat.mhd";
  writeFile(mhd, "ObjectType = Image\nNDims = 2\nDimSize = 9 4\nElementSpacing = 0.5 0.25\n"
                 "ElementType = MET_USHORT\nElementDataFile = flat.raw\n");
  for (const std::string& path : {nrrd, mhd}) {
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_TRUE(loaded.mapped) << loaded.decodeReason;
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
}

// ---------------------------------------------------------------------------------------------
// Formats ITK decodes.

TEST(LoadVolume, DicomSeriesAndVtkAreDecodedByItk) {
  TempDir dir;
  const DenseImage<std::uint16_t> image = makeVolume<std::uint16_t>(Dims{6, 5, 4});
  const fs::path series = dir.path() / "series";
  fs::create_directory(series);
  io::writeDicomSeries(io::AnyVolume(image), series.string());
  const LoadedVolume dicom = io::loadVolume(series.string());
  EXPECT_FALSE(dicom.mapped);
  EXPECT_EQ(dicom.format, "dicom");
  expectSame(dicom, io::readVolume(series.string()), "dicom");

  const std::string vtk = dir / "v.vtk";
  io::writeVolume(io::AnyVolume(image), vtk);
  const LoadedVolume loaded = io::loadVolume(vtk);
  EXPECT_FALSE(loaded.mapped);
  EXPECT_EQ(loaded.format, "vtk");
  expectSame(loaded, io::readVolume(vtk), vtk);
  expectVoxels(loaded, image);
}

TEST(LoadVolume, ScaledNiftiIsDecodedByItk) {
  TempDir dir;
  const std::string path = dir / "scaled.nii";
  io::writeVolume(io::AnyVolume(makeVolume<std::int16_t>(kDims)), path);
  std::string bytes = contents(path);
  const float slope = 0.5f, inter = 3.0f;
  std::memcpy(&bytes[112], &slope, 4);
  std::memcpy(&bytes[116], &inter, 4);
  writeFile(path, bytes);
  const LoadedVolume loaded = io::loadVolume(path);
  EXPECT_FALSE(loaded.mapped);
  EXPECT_NE(loaded.decodeReason.find("scaled"), std::string::npos) << loaded.decodeReason;
  expectSame(loaded, io::readVolume(path), path);
}

/// scl_slope = 0 with an scl_inter: the NIfTI-1 header calls it unscaled, but ITK 5.2 reads the
/// slope as 1 and adds the intercept (as it does for a NaN slope). Float voxels keep their type
/// then, so a mapping of the stored values would differ from readVolume (found by fuzz/): the
/// loader decodes them as ITK does, stored value + intercept.
TEST(LoadVolume, NiftiSlopeZeroWithAnInterceptIsReadAsItkReadsIt) {
  TempDir dir;
  const DenseImage<float> image = makeVolume<float>(kDims);
  for (const float slope : {0.0f, std::nanf("")}) {
    const std::string path = dir / "slope0.nii";
    io::writeVolume(io::AnyVolume(image), path);
    std::string bytes = contents(path);
    const float inter = 0.5f;
    std::memcpy(&bytes[112], &slope, 4);
    std::memcpy(&bytes[116], &inter, 4);
    writeFile(path, bytes);
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_FALSE(loaded.mapped) << slope;
    expectSame(loaded, io::readVolume(path), path);
    ASSERT_EQ(loaded.view.type, ScalarType::Float32);
    const auto* v = static_cast<const float*>(loaded.view.data);
    for (std::size_t i = 0; i < image.data().size(); ++i) ASSERT_EQ(v[i], image.data()[i] + inter) << i;
  }
}

TEST(LoadVolume, NiftiFloatsWithNanAreDecodedAsReadVolumeReadsThem) {
  TempDir dir;
  for (const bool isDouble : {false, true}) {
    const std::string path = dir / (isDouble ? "nan64.nii" : "nan32.nii");
    if (isDouble) {
      DenseImage<double> image = makeVolume<double>(kDims);
      image.at(1, 2, 0) = std::nan("");
      image.at(3, 1, 2) = -INFINITY;
      io::writeVolume(io::AnyVolume(image), path);
    } else {
      DenseImage<float> image = makeVolume<float>(kDims);
      image.at(1, 2, 0) = std::nanf("");
      io::writeVolume(io::AnyVolume(image), path);
    }
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_FALSE(loaded.mapped) << path;
    EXPECT_NE(loaded.decodeReason.find("NaN"), std::string::npos) << loaded.decodeReason;
    expectSame(loaded, io::readVolume(path), path);  // niftilib reads NaN and infinity as 0
    double v;
    visitScalarType(loaded.view.type, [&](auto t) {
      using T = decltype(t);
      T value;
      std::memcpy(&value, voxelAt(loaded.view, 1, 2, 0), sizeof(T));
      v = double(value);
    });
    EXPECT_EQ(v, 0.0);
  }
  // NRRD keeps NaN as stored, mapped or read.
  DenseImage<float> image = makeVolume<float>(kDims);
  image.at(1, 2, 0) = std::nanf("");
  const std::string nrrd = dir / "nan.nhdr";
  io::writeVolume(io::AnyVolume(image), nrrd);
  const LoadedVolume loaded = io::loadVolume(nrrd);
  EXPECT_TRUE(loaded.mapped);
  expectSame(loaded, io::readVolume(nrrd), nrrd);
}

TEST(LoadVolume, NumberedAndListedDataFilesAreDecodedByItk) {
  TempDir dir;
  using T = std::uint16_t;
  const DenseImage<T> image = makeVolume<T>(kDims);
  const std::string all = bytesOf(image);
  const std::size_t slice = all.size() / std::size_t(kDims.nz);
  for (int z = 0; z < kDims.nz; ++z) writeFile(dir / ("slice" + std::to_string(z + 1) + ".raw"), all.substr(z * slice, slice));
  const std::string mhd = dir / "numbered.mhd";
  writeFile(mhd, metaHeader("MET_USHORT", kDims, "", "slice%d.raw 1 3 1"));
  const std::string nhdr = dir / "numbered.nhdr";
  writeFile(nhdr, nrrdHeader("uint16", kDims, "endian: little\nencoding: raw\ndata file: slice%d.raw 1 3 1 2\n"));
  const std::string list = dir / "list.nhdr";
  writeFile(list, nrrdHeader("uint16", kDims, "endian: little\nencoding: raw\ndata file: LIST\n") +
                      "slice1.raw\nslice2.raw\nslice3.raw\n");
  const std::string metaList = dir / "list.mhd";
  writeFile(metaList, metaHeader("MET_USHORT", kDims, "", "LIST") + "slice1.raw\nslice2.raw\nslice3.raw\n");
  // A MetaImage list whose last name ends the file without its newline: MetaIO skips that name
  // and leaves its slice unread, so both readers refuse the list.
  const std::string unended = dir / "unended.mhd";
  writeFile(unended, metaHeader("MET_USHORT", kDims, "", "LIST") + "slice1.raw\nslice2.raw\nslice3.raw");
  expectReadError([&] { io::loadVolume(unended); }, {unended, "lists 2 data files", "without its newline"});
  expectReadError([&] { io::readVolume(unended); }, {unended, "lists 2 data files", "without its newline"});
  // A NRRD list of one file holding all three dimensions, with "\r\n" line ends.
  writeFile(dir / "all.raw", all);
  const std::string wholeList = dir / "list3.nhdr";
  writeFile(wholeList, nrrdHeader("uint16", kDims, "endian: little\nencoding: raw\ndata file: LIST 3\r\n") + "all.raw\r\n");
  for (const std::string& path : {mhd, nhdr, list, metaList, wholeList}) {
    SCOPED_TRACE(path);
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_FALSE(loaded.mapped) << path;
    EXPECT_NE(loaded.decodeReason.find("files"), std::string::npos) << loaded.decodeReason;
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
  // A '%' that is not teem's "%<digits>d" is part of one file's name: mapped.
  writeFile(dir / "100%.raw", all);
  const std::string percent = dir / "percent.nhdr";
  writeFile(percent, nrrdHeader("uint16", kDims, "endian: little\nencoding: raw\ndata file: 100%.raw\n"));
  const LoadedVolume loaded = io::loadVolume(percent);
  EXPECT_TRUE(loaded.mapped) << loaded.decodeReason;
  expectVoxels(loaded, image);
}

TEST(LoadVolume, FilePatternsThatWouldCrashTheirReadersAreReadErrors) {
  // MetaIO and teem pass these patterns to sprintf with one int, and MetaIO divides by the step.
  TempDir dir;
  const std::string ok = nrrdHeader("uint16", kDims, "endian: little\nencoding: raw\n");
  const std::pair<std::string, std::string> cases[] = {
      {"conversion.mhd", metaHeader("MET_USHORT", kDims, "", "slice%s%d.raw 1 3 1")},
      {"two.mhd", metaHeader("MET_USHORT", kDims, "", "slice%d%d.raw 1 3 1")},
      {"step0.mhd", metaHeader("MET_USHORT", kDims, "", "slice%d.raw 1 3 0")},
      {"step0implicit.mhd", metaHeader("MET_USHORT", kDims, "", "slice%d.raw 1 2")},  // (2 - 1) / 3 slices
      {"backwards.mhd", metaHeader("MET_USHORT", kDims, "", "slice%d.raw 3 1 1")},
      {"long.mhd", metaHeader("MET_USHORT", kDims, "", "slice%d" + std::string(90, 'x') + ".raw 1 3 1")},  // MetaIO's 80-byte words
      {"longjoined.mhd", metaHeader("MET_USHORT", kDims, "", "a b c d e f g h i j k l m n o p q r s t u v w x y z "
                                                             "a b c d e f g h i j k l m n o p q r s t u v %d 1 3 1")},
      {"conversion.nhdr", ok + "data file: slice%03d%s.raw 1 3 1\n"},
      {"step0.nhdr", ok + "data file: slice%d.raw 1 3 0\n"},
      {"width.nhdr", ok + "data file: slice%15d.raw 1 3 1\n"},  // teem's buffer: 10 characters
      {"numbers.nhdr", ok + "data file: slice%d.raw 1 three 1\n"},
  };
  for (const auto& [name, header] : cases) {
    const std::string path = dir / name;
    writeFile(path, header);
    SCOPED_TRACE(name);
    expectReadError([&] { io::loadVolume(path); }, {path});
  }
}

TEST(LoadVolume, CorruptCompressedMetaImageIsAReadError) {
  // ITK 5.2's MetaIO reports no error for a corrupt zlib stream (and may loop forever on one):
  // the loader inflates it first.
  TempDir dir;
  const DenseImage<std::int16_t> image = makeVolume<std::int16_t>(Dims{16, 16, 8});
  const std::string path = dir / "z.mha";
  io::writeVolume(io::AnyVolume(image), path, /*compress=*/true);
  const std::string good = contents(path);
  const std::size_t start = attachedOffset(path);
  std::string corrupt = good;
  for (std::size_t i = start + 4; i < start + 40 && i < corrupt.size(); ++i) corrupt[i] = char(0xff);
  writeFile(path, corrupt);
  expectReadError([&] { io::loadVolume(path); }, {path, "corrupt compressed data"});
  // A stream cut short (the file too, so that CompressedDataSize would run past its end).
  writeFile(path, good.substr(0, start + (good.size() - start) / 2));
  expectReadError([&] { io::loadVolume(path); }, {path});
  // The detached form, .mhd + .zraw.
  const std::string mhd = dir / "z.mhd";
  io::writeVolume(io::AnyVolume(image), mhd, /*compress=*/true);
  expectSame(io::loadVolume(mhd), io::readVolume(mhd), mhd);
  const std::string zraw = dir / "z.zraw";
  std::string bytes = contents(zraw);
  for (std::size_t i = 4; i < 40 && i < bytes.size(); ++i) bytes[i] = char(0xff);
  writeFile(zraw, bytes);
  expectReadError([&] { io::loadVolume(mhd); }, {mhd, "corrupt compressed data"});
}

/// `bytes` as gzip members (zlib, windowBits 31), one per part of `parts` sizes (the last takes
/// the rest).
std::string gzipped(const std::string& bytes, std::vector<std::size_t> parts = {}) {
  std::string out;
  std::size_t at = 0;
  parts.push_back(bytes.size());
  for (std::size_t part : parts) {
    const std::size_t n = std::min(part, bytes.size() - at);
    z_stream z{};
    EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 31, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string member(deflateBound(&z, uLong(n)) + 32, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + at));
    z.avail_in = uInt(n);
    z.next_out = reinterpret_cast<Bytef*>(member.data());
    z.avail_out = uInt(member.size());
    EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    member.resize(member.size() - z.avail_out);
    deflateEnd(&z);
    out += member;
    at += n;
    if (at == bytes.size()) break;
  }
  return out;
}

// A .nii.gz: its header inflated and checked by the NIfTI-1 parser, then the whole file inflated
// by libdeflate, member by member; what ITK's reader (gzread) accepts is read the same, compared
// with readVolume.
TEST(LoadVolume, GzippedNiftiMembersAndTrailingBytesReadAsItkReadsThem) {
  TempDir dir;
  const DenseImage<std::int16_t> image = makeVolume<std::int16_t>(Dims{16, 16, 8});
  const std::string plain = dir / "plain.nii";
  io::writeVolume(io::AnyVolume(image), plain);
  const std::string nii = contents(plain);
  struct Variant {
    std::string name, bytes, reason;
  };
  const std::vector<Variant> variants = {
      {"one.nii.gz", gzipped(nii), "inflated"},
      // bgzip and pigz --independent write several members; the first ends inside the header.
      {"members.nii.gz", gzipped(nii, {200, 1000, 1}), "inflated"},
      {"trailing.nii.gz", gzipped(nii) + "not a gzip member", "inflated"},
      // bgzip's end: an empty member after the last.
      {"emptylast.nii.gz", gzipped(nii) + gzipped(""), "inflated"},
      // More bytes than the header announces: ITK reads what it needs.
      {"longer.nii.gz", gzipped(nii + std::string(100, 'x')), "inflated"},
  };
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.name);
    const std::string path = dir / v.name;
    writeFile(path, v.bytes);
    const LoadedVolume loaded = io::loadVolume(path);
    EXPECT_NE(loaded.decodeReason.find(v.reason), std::string::npos) << loaded.decodeReason;
    EXPECT_EQ(loaded.format, "nii.gz");
    expectSame(loaded, io::readVolume(path), path);
    expectVoxels(loaded, image);
  }
  // What the parser leaves to ITK stays ITK's: scaled voxels.
  std::string scaled = nii;
  const float slope = 0.5f, inter = 3.0f;
  std::memcpy(&scaled[112], &slope, 4);
  std::memcpy(&scaled[116], &inter, 4);
  const std::string path = dir / "scaled.nii.gz";
  writeFile(path, gzipped(scaled));
  const LoadedVolume loaded = io::loadVolume(path);
  EXPECT_NE(loaded.decodeReason.find("scaled"), std::string::npos) << loaded.decodeReason;
  expectSame(loaded, io::readVolume(path), path);
}

TEST(LoadVolume, DamagedGzippedNiftiIsAReadError) {
  TempDir dir;
  const DenseImage<std::int16_t> image = makeVolume<std::int16_t>(Dims{16, 16, 8});
  const std::string plain = dir / "plain.nii";
  io::writeVolume(io::AnyVolume(image), plain);
  const std::string nii = contents(plain), gz = gzipped(nii);
  std::string flipped = gz;
  for (std::size_t i = gz.size() / 2; i < gz.size() / 2 + 16; ++i) flipped[i] = char(~flipped[i]);
  std::string nanSform = nii;
  const float nan = std::nanf("");
  std::memcpy(&nanSform[312], &nan, 4);
  // 1000 x 1000 x 1000 int16 voxels announced by a header and 64 KiB of zeros, 100 bytes once
  // deflated: refused before 2 GB are allocated.
  std::string bomb = nii.substr(0, 352) + std::string(1 << 16, '\0');
  const std::int16_t thousand = 1000;
  for (int d = 1; d <= 3; ++d) std::memcpy(&bomb[40 + 2 * d], &thousand, 2);
  struct Case {
    std::string name, bytes, expected;
  };
  const std::vector<Case> cases = {
      {"cut1.nii.gz", gz.substr(0, gz.size() - 1), "truncated"},
      {"cuthalf.nii.gz", gz.substr(0, gz.size() / 2), "truncated"},
      {"cutheader.nii.gz", gz.substr(0, 20), "truncated"},
      {"short.nii.gz", gzipped(nii.substr(0, nii.size() - 10)), "truncated"},
      {"flipped.nii.gz", flipped, "corrupt compressed data"},
      // A damaged member after those that hold the voxels: readVolume reads to the end too.
      {"damagedlast.nii.gz", gz + gzipped(std::string(5000, 'x')).substr(0, 30), "corrupt compressed data"},
      {"plain.nii.gz", nii, "not gzip-compressed"},
      {"garbage.nii.gz", std::string("\x1f\x8bneither is this"), "corrupt compressed data"},
      {"nansform.nii.gz", gzipped(nanSform), "sform"},  // ITK's reader would abort the process
      {"bomb.nii.gz", gzipped(bomb), "encoded data can hold"},
      {"empty.nii.gz", "", "empty"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir / c.name;
    writeFile(path, c.bytes);
    expectReadError([&] { io::loadVolume(path); }, {path, c.expected});
  }
}

/// The bytes a gzip stream inflates to (zlib).
std::string gunzipped(const std::string& bytes) {
  z_stream z{};
  EXPECT_EQ(inflateInit2(&z, 16 + MAX_WBITS), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = uInt(bytes.size());
  std::string out;
  char buffer[4096];
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof buffer;
    status = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - z.avail_out);
  }
  EXPECT_EQ(status, Z_STREAM_END);
  inflateEnd(&z);
  return out;
}

/// A .nii.gz beside a .nii of the same base name: niftilib looks for the voxels by base name,
/// .nii first, and ITK read the header of the one and the voxels of the other. Both readers give
/// the .nii.gz's own voxels, also when ITK decodes them (scaled voxels).
TEST(LoadVolume, GzippedNiftiBesideAnUncompressedOneReadsItsOwnVoxels) {
  TempDir dir;
  const DenseImage<std::int16_t> image = makeVolume<std::int16_t>(kDims);
  DenseImage<std::int16_t> other = image;
  for (auto& v : other.data()) v = std::int16_t(v ^ 0x5a5a);
  io::writeVolume(io::AnyVolume(other), dir / "scan.nii");
  for (const bool scaled : {false, true}) {
    SCOPED_TRACE(scaled ? "scaled" : "plain");
    const std::string path = dir / "scan.nii.gz";
    io::writeVolume(io::AnyVolume(image), path);
    if (scaled) {  // scl_slope 2, inflated, patched, gzipped again
      std::string bytes = gunzipped(contents(path));
      const float slope = 2;
      std::memcpy(&bytes[112], &slope, 4);
      writeFile(path, gzipped(bytes));
    }
    const io::AnyVolume read = io::readVolume(path);
    const LoadedVolume loaded = io::loadVolume(path);
    expectSame(loaded, read, path);
    std::visit([&](const auto& v) {
      for (std::size_t i = 0; i < image.data().size(); ++i)
        ASSERT_EQ(double(v.data()[i]), double(image.data()[i]) * (scaled ? 2 : 1)) << i;
    }, read);
  }
}

TEST(LoadVolume, MetaImageValuesAfterExtraSeparators) {
  // MetaIO skips '=', ':' and blanks before a value: "ElementDataFile = = LOCAL" is LOCAL.
  TempDir dir;
  const DenseImage<std::int16_t> image = makeVolume<std::int16_t>(kDims);
  const std::string path = dir / "separators.mha";
  writeFile(path, "ObjectType = Image\nNDims := 3\nDimSize = 7 5 3\nElementType = MET_SHORT\n"
                  "ElementDataFile = = LOCAL\n" + bytesOf(image));
  expectSame(io::loadVolume(path), io::readVolume(path), path);
  expectVoxels(io::loadVolume(path), image);
}

// ---------------------------------------------------------------------------------------------
// Lifetime.

TEST(LoadVolume, TheOwnerKeepsTheMappingAliveAfterTheFileIsDeleted) {
  TempDir dir;
  const DenseImage<float> image = makeVolume<float>(kDims);
  const std::string path = dir / "gone.nii";
  io::writeVolume(io::AnyVolume(image), path);
  LoadedVolume copy;
  {
    const LoadedVolume loaded = io::loadVolume(path);
    ASSERT_TRUE(loaded.mapped);
    copy = loaded;
  }
  fs::remove(path);
  expectVoxels(copy, image);
}

// ---------------------------------------------------------------------------------------------
// Truncated files and corrupt headers.

TEST(LoadVolume, TruncatedFilesAreReadErrors) {
  TempDir dir;
  const DenseImage<std::uint16_t> image = makeVolume<std::uint16_t>(Dims{16, 16, 8});
  const std::uintmax_t dataBytes = image.dims().count() * 2;
  for (const std::string ext : {"nrrd", "mha", "nii", "nhdr", "mhd"}) {
    const bool detached = ext == "nhdr" || ext == "mhd";
    for (const std::string cut : {"one byte", "half", "header only", "inside the header"}) {
      const std::string path = dir / ("t-" + ext + "." + ext);
      io::writeVolume(io::AnyVolume(image), path);
      const std::string victim = detached ? dir / ("t-" + ext + ".raw") : path;
      const std::uintmax_t size = fs::file_size(victim);
      const std::uintmax_t header = size - dataBytes;
      const std::uintmax_t to = cut == "one byte" ? size - 1 : cut == "half" ? size / 2 : cut == "header only" ? header
                              : detached ? 0 : header / 2;
      if (detached && cut == "inside the header") {
        truncateTo(path, fs::file_size(path) / 2);  // the header itself, cut in the middle
      } else {
        truncateTo(victim, to);
      }
      SCOPED_TRACE(path + ", cut: " + cut);
      // A header cut in the middle reads as malformed or truncated; a short data file as truncated.
      if (cut == "inside the header")
        expectReadError([&] { io::loadVolume(path); }, {path});
      else
        expectReadError([&] { io::loadVolume(path); }, {path, "truncated"});
      EXPECT_THROW(io::readVolume(path), io::ReadError);
    }
  }
  // Raw files: cut by one byte and by half.
  io::RawLayout layout;
  layout.dims = Dims{16, 16, 8};
  layout.type = ScalarType::UInt16;
  for (const std::uintmax_t to : {dataBytes - 1, dataBytes / 2, std::uintmax_t(0)}) {
    const std::string path = dir / "t.raw";
    writeFile(path, bytesOf(image));
    truncateTo(path, to);
    expectReadError([&] { io::loadRawVolume(path, layout); }, {path});
    if (to > 0) expectReadError([&] { io::loadRawVolume(path, layout); }, {"truncated"});
  }
}

TEST(LoadVolume, CorruptHeadersAreReadErrors) {
  TempDir dir;
  const std::string data(7 * 5 * 3 * 2, '\1');
  writeFile(dir / "ok.raw", data);
  const std::string okNrrd = nrrdHeader("int16", kDims, "endian: little\nencoding: raw\n");
  struct Case {
    std::string name, bytes, expected;
  };
  std::vector<Case> cases = {
      {"magic.nrrd", "NRRX0004\ntype: int16\n\n", "not a NRRD file"},
      {"version.nrrd", "NRRD0009\ntype: int16\n\n", "not a NRRD file"},
      {"unknown.nrrd", okNrrd + "colour: blue\n\n" + data, "not a NRRD field"},
      {"nocolon.nrrd", okNrrd + "just words\n\n" + data, "neither"},
      {"sizes.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 x 3\nendian: little\nencoding: raw\n\n" + data,
       "positive size"},
      {"count.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 5\nendian: little\nencoding: raw\n\n" + data,
       "needs 3 values"},
      {"order.nrrd", "NRRD0004\ntype: int16\nsizes: 7 5 3\ndimension: 3\nendian: little\nencoding: raw\n\n" + data,
       "before 'dimension'"},
      {"notype.nrrd", "NRRD0004\ndimension: 3\nsizes: 7 5 3\nendian: little\nencoding: raw\n\n" + data, "no 'type'"},
      {"badtype.nrrd", "NRRD0004\ntype: complex\ndimension: 3\nsizes: 7 5 3\nencoding: raw\n\n" + data, "no NRRD type"},
      {"noendian.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 5 3\nencoding: raw\n\n" + data, "endian"},
      {"endian.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 5 3\nendian: middle\nencoding: raw\n\n" + data,
       "neither little nor big"},
      {"twice.nrrd", okNrrd + "encoding: raw\n\n" + data, "repeats"},
      {"skip.nrrd", okNrrd + "byte skip: -5\n\n" + data, "byte skip"},
      {"huge.nrrd", "NRRD0004\ntype: double\ndimension: 3\nsizes: 2147483647 2147483647 2147483647\n"
                    "endian: little\nencoding: raw\n\n", "2^62"},
      {"big.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 700 500 300\nendian: little\nencoding: raw\n\n" + data,
       "truncated"},
      {"direction.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 5 3\nendian: little\nencoding: raw\n"
                         "space: RAS\nspace directions: (1,0) (0,1,0) (0,0,1)\n\n" + data, "3 components"},
      {"nospace.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 5 3\nendian: little\nencoding: raw\n"
                       "space directions: (1,0,0) (0,1,0) (0,0,1)\n\n" + data, "before 'space'"},
      {"missing.nhdr", okNrrd + "data file: nowhere.raw\n", "no such file"},
      {"device.nhdr", okNrrd + "data file: /dev/null\n", "not a regular file"},
      {"dir.nhdr", okNrrd + "data file: .\n", "directory"},
      {"shortdata.nhdr", okNrrd + "data file: short.raw\n", "truncated"},
      {"noend.nrrd", okNrrd, "truncated"},
      {"first.mha", "NDims = 3\nObjectType = Image\n", "ObjectType = Image"},
      {"object.mha", "ObjectType = Tube\nNDims = 3\n", "not a MetaImage image"},
      {"ndims.mha", "ObjectType = Image\nNDims = 0\n", "1 to 10"},
      {"dimsize.mha", "ObjectType = Image\nDimSize = 7 5 3\nNDims = 3\n", "before NDims"},
      {"dimcount.mha", "ObjectType = Image\nNDims = 3\nDimSize = 7 5\n", "needs 3 sizes"},
      {"etype.mha", "ObjectType = Image\nNDims = 3\nDimSize = 7 5 3\nElementType = MET_FOO\n", "element type"},
      {"spacing.mha", "ObjectType = Image\nNDims = 3\nElementSpacing = 1 a 1\n", "number"},
      {"headersize.mha", "ObjectType = Image\nNDims = 3\nHeaderSize = -7\n", "HeaderSize"},
      {"notype.mha", "ObjectType = Image\nNDims = 3\nDimSize = 7 5 3\nElementDataFile = LOCAL\n" + data, "ElementType"},
      {"noend.mha", "ObjectType = Image\nNDims = 3\nDimSize = 7 5 3\nElementType = MET_SHORT\n", "truncated"},
      {"short.mha", metaHeader("MET_SHORT", kDims, "", "LOCAL") + data.substr(1), "truncated"},
      {"missing.mhd", metaHeader("MET_SHORT", kDims, "", "nowhere.raw"), "no such file"},
      {"nodatafile.mha", "ObjectType = Image\nNDims = 3\nDimSize = 7 5 3\nElementType = MET_SHORT\nElementDataFile =\n",
       "names no data file"},
      // What crashed ITK's MetaIO (fuzz/): a key longer than its 255-byte field names, and a
      // list of files with a blank, missing or short entry.
      {"longkey.mha", "ObjectType = Image\nNDims = 3\n" + std::string(300, 'K') + " = 1\n", "more than 254 characters"},
      {"blanklist.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ok.raw\n\nok.raw\n", "lists 1 data files"},
      {"shortlist.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ok.raw\nok.raw\n", "lists 2 data files"},
      {"missinglist.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ok.raw\nnowhere.raw\nok.raw\n", "no such file"},
      {"dirlist.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ok.raw\n.\nok.raw\n", "directory"},
      {"shortfile.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ok.raw\ntiny.raw\nok.raw\n", "truncated"},
      // A list cut short after a name without its newline: the parser read past its buffer
      // (std::out_of_range, found by fuzz/).
      // (MetaIO skips the unterminated name, so the list has one name fewer.)
      {"cutlist.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ok.raw\nok.raw", "lists 1 data files"},
      {"cutlist1.mhd", metaHeader("MET_SHORT", kDims, "", "LIST") + "ab", "lists 0 data files"},
      // Three spaces in a row, which MetaIO counts as two words and then reads a word it never
      // wrote (a crash under fuzz/).
      {"spaces.mhd", metaHeader("MET_SHORT", kDims, "", "slice%d.raw   1 3 1"), "three or more spaces"},
      {"spacedlist.mhd", metaHeader("MET_SHORT", kDims, "", "LIST   2") + "ok.raw\nok.raw\nok.raw\n", "three or more spaces"},
      // NRRD lists of data files as teem reads them: the count of blocks, names without a
      // control byte (a NUL made teem's messages read past their buffer, under fuzz/).
      {"nullist.nhdr", okNrrd + "data file: LIST\nok.raw\n" + std::string("o\0k.raw\n", 8) + "ok.raw\n", "control character"},
      {"shortlist.nhdr", okNrrd + "data file: LIST\nok.raw\nok.raw\n", "lists 2 data files, and the image needs 3"},
      {"blanklist.nhdr", okNrrd + "data file: LIST\nok.raw\n\nok.raw\nok.raw\n", "lists 1 data files"},
      {"listdim.nhdr", okNrrd + "data file: LIST 4\nok.raw\n", "data file dimension"},
      {"missinglist.nhdr", okNrrd + "data file: LIST\nok.raw\nnowhere.raw\nok.raw\n", "no such file"},
      {"tinylist.nhdr", okNrrd + "data file: LIST\nok.raw\ntiny.raw\nok.raw\n", "truncated"},
      // ITK's matrix code aborts on the infinity 1e200 * 1e200 makes.
      {"huge.mha", "ObjectType = Image\nNDims = 3\nDimSize = 7 5 3\nElementSpacing = 1e200 1e200 1e200\n"
                   "TransformMatrix = 1e200 0 0 0 1e200 0 0 0 1e200\nElementType = MET_SHORT\nElementDataFile = LOCAL\n" + data,
       "1e15"},
      {"hugedirection.nrrd", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 7 5 3\nendian: little\nencoding: raw\n"
                             "space: LPS\nspace directions: (1e300,0,0) (0,1,0) (0,0,1)\n\n" + data, "1e15"},
      // Bytes that C readers would see otherwise (a NUL ends their string).
      {"control.nrrd", "NRRD0004\ntype: int16\x01\ndimension: 3\n\n", "control character"},
      {"nul.mha", std::string("ObjectType = Image\nNDims = 3\0\n", 31), "control character"},
      // More voxels than the encoded bytes can hold: an error before ITK allocates them.
      {"bomb.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1000 1000 1000\nencoding: gzip\n\nxxxx",
       "encoded data can hold"},
      {"bomb.mha", metaHeader("MET_UCHAR", Dims{1000, 1000, 1000}, "CompressedData = True\n", "LOCAL") + "xxxx",
       "encoded data can hold"},
      {"text.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 100 100 100\nencoding: ascii\n\n1 2 3\n",
       "encoded data can hold"},
      {"compressedsize.mha", metaHeader("MET_UCHAR", kDims, "CompressedData = True\nCompressedDataSize = 100000\n", "LOCAL") + "xxxx",
       "truncated"},
      {"bomb.nhdr", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1000 1000 1000\nencoding: gzip\ndata file: ok.raw\n",
       "encoded data can hold"},
      {"fifo.nhdr", okNrrd + "data file: fifo.raw\n", "not a regular file"},
      {"fifogz.nhdr", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 7 5 3\nencoding: gzip\ndata file: fifo.raw\n",
       "not a regular file"},
      {"garbage.nii", std::string(400, 'g'), "not a NIfTI-1 file"},
      {"short.nii", std::string(100, '\0'), "truncated"},
      {"empty.nrrd", "", "empty"},
  };
  writeFile(dir / "short.raw", data.substr(3));
  writeFile(dir / "tiny.raw", data.substr(0, 10));  // less than a slice
  ASSERT_EQ(::mkfifo((dir / "fifo.raw").c_str(), 0600), 0);  // opening it must not wait for a writer
  // NIfTI-1 headers with one field broken.
  {
    const std::string good = dir / "good.nii";
    io::writeVolume(io::AnyVolume(makeVolume<std::int16_t>(kDims)), good);
    const std::string bytes = contents(good);
    auto with = [&](std::size_t at, const void* value, std::size_t n) {
      std::string b = bytes;
      std::memcpy(&b[at], value, n);
      return b;
    };
    const std::int16_t nine = 9, zero = 0;
    const float negative = -4, nan = std::nanf("");
    const std::int16_t bigDim = 30000;
    cases.push_back({"dim0.nii", with(40, &nine, 2), "dim[0]"});
    cases.push_back({"dim2.nii", with(44, &zero, 2), "dim[2]"});
    cases.push_back({"offset.nii", with(108, &negative, 4), "vox_offset"});
    cases.push_back({"nanoffset.nii", with(108, &nan, 4), "vox_offset"});
    cases.push_back({"bigdim.nii", with(42, &bigDim, 2), "truncated"});
    // ITK's NIfTI reader aborts the process (vnl's SVD) on a NaN in the sform: a ReadError here.
    cases.push_back({"nansform.nii", with(312, &nan, 4), "sform"});
    cases.push_back({"nanpixdim.nii", with(80, &nan, 4), "pixdim"});
    cases.push_back({"nomagic.nii", with(344, "\0\0\0\0", 4), "magic"});  // niftilib would read it as Analyze 7.5
    // NIfTI-2's size with NIfTI-1's magic (a fuzzer's finding): niftilib read it as NIfTI-1 and
    // aborted on its NaN sform.
    const std::int32_t nifti2Size = 540;
    std::string mixed = with(0, &nifti2Size, 4);
    std::memcpy(&mixed[280], &nan, 4);
    cases.push_back({"nifti2size.nii", mixed, "sizeof_hdr 540"});
    const float far = 1e24f;
    cases.push_back({"faroffset.nii", with(108, &far, 4), "truncated"});
    // An sform singular to single precision, with an offset of 5e7 beside 3e-39 (a fuzzer's
    // finding): ITK 5.2's NIfTI reader never returned on it.
    {
      std::string b = bytes;
      const std::int16_t qformCode = 0, sformCode = 1;
      const float sform[12] = {1, 0, -5e7f, 0, 1, 0, 1, 3e-39f, 0, 1, 5e7f, 0};
      std::memcpy(&b[252], &qformCode, 2);
      std::memcpy(&b[254], &sformCode, 2);
      std::memcpy(&b[280], sform, sizeof sform);
      cases.push_back({"singularsform.nii", b, "sform (srow_x to srow_z) is singular"});
      // Found by a search of random sforms on which ITK's SVD never returns: a rotation of
      // 1 um voxels (in mm) beside offsets of 4e12 and 2.6e-30.
      const float regular[12] = {0.00107906f, 0.000295631f, 0, -4.1007e+12f, -0.000295631f, 0.00107906f, 0, 0,
                                 0, 0, 0.00146083f, -2.58811e-30f};
      std::memcpy(&b[280], regular, sizeof regular);
      cases.push_back({"offsetsform.nii", b, "more than 1e24 apart"});
    }
    // Datatypes niftilib rejects with a line of its own on stderr, or that are not one scalar.
    const std::int16_t badType = 9999;
    cases.push_back({"datatype.nii", with(70, &badType, 2), "datatype 9999 is not a NIfTI-1 datatype"});
  }
  for (const Case& c : cases) {
    const std::string path = dir / c.name;
    writeFile(path, c.bytes);
    SCOPED_TRACE(c.name);
    expectReadError([&] { io::loadVolume(path); }, {path, c.expected});
  }
  expectReadError([&] { io::loadVolume(dir / "absent.nrrd"); }, {dir / "absent.nrrd", "no such file"});
  expectReadError([&] { io::loadVolume(dir / "absent.dcm"); }, {"no such file"});
  expectReadError([&] { io::loadVolume(dir.path().string()); }, {dir.path().string()});  // no DICOM series
  const std::string unknown = dir / "notes.txt";
  writeFile(unknown, "hello");
  expectReadError([&] { io::loadVolume(unknown); }, {unknown});
  if (::geteuid() != 0) {  // root reads anything
    const std::string locked = dir / "locked.nrrd";
    writeFile(locked, okNrrd + "\n" + data);
    fs::permissions(locked, fs::perms::none);
    expectReadError([&] { io::loadVolume(locked); }, {locked});
  }
}

/// A NIfTI sform with small voxels far from the origin (1 um voxels, in mm, half a metre away:
/// a condition number near 1e9) is not refused with the singular ones above: ITK reads it (from
/// the qform it falls back to), with the geometry it was written with.
TEST(LoadVolume, SmallVoxelsFarFromTheOriginLoad) {
  TempDir dir;
  ImageGeometry g = testGeometry();
  g.spacing = {1e-3, 1e-3, 2e-3};
  g.origin = {500, -400, 300};
  const std::string path = dir / "far.nii";
  io::writeVolume(io::AnyVolume(makeVolume<std::int16_t>(kDims, g)), path);
  const LoadedVolume loaded = io::loadVolume(path);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(loaded.view.geometry.spacing[i], g.spacing[i], 1e-8);
    EXPECT_NEAR(loaded.view.geometry.origin[i], g.origin[i], 1e-3);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(loaded.view.geometry.direction[i][j], g.direction[i][j], 1e-5);
  }
}

/// What ITK refuses reaches the user as one line without ITK's pointers ("NrrdImageIO(0x55...)")
/// or its "ITK ERROR:", saying what is wrong, and nothing else is printed on stderr.
TEST(LoadVolume, ItkErrorsAreOneLineWithoutPointers) {
  TempDir dir;
  // gzip-encoded voxels that end early: teem's chain of messages ends with what is wrong.
  const std::string cut = dir / "cut.nrrd";
  const std::string full = gzipped(std::string(7 * 5 * 3 * 2, '\5'));
  writeFile(cut, nrrdHeader("int16", kDims, "endian: little\nencoding: gzip\n") + "\n" + full.substr(0, full.size() - 12));
  // A NIfTI datatype niftilib does not know: refused before niftilib prints its own line.
  const std::string nifti = dir / "datatype.nii";
  io::writeVolume(io::AnyVolume(makeVolume<std::int16_t>(kDims)), nifti);
  std::string bytes = contents(nifti);
  const std::int16_t badType = 1;  // DT_BINARY: niftilib's "bad datatype"
  std::memcpy(&bytes[70], &badType, 2);
  writeFile(nifti, bytes);
  std::vector<std::string> paths = {cut, nifti};
#ifdef SURFTRACK_FUZZ_DIR
  // A TIFF whose pages differ (ITK's reader overflowed its buffer on it), with tags out of
  // order: libtiff warned on stderr as ITK opened it.
  paths.push_back(dir / "pages.tif");
  writeFile(paths.back(), contents(SURFTRACK_FUZZ_DIR "/findings/tif/pages-unlike-the-first-itk-overflow.tif"));
#endif
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    testing::internal::CaptureStderr();
    std::string message;
    try {
      io::loadVolume(path);
    } catch (const io::ReadError& e) {
      message = e.what();
    }
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.find("(0x"), std::string::npos) << message;
    EXPECT_EQ(message.find("ITK ERROR"), std::string::npos) << message;
    EXPECT_EQ(message.find("[nrrd]"), std::string::npos) << message;
    EXPECT_EQ(err, "") << "printed on stderr besides the error";
  }
}

/// A file whose voxels are not one scalar of a supported type: the message lists the types, and
/// every type it lists loads (as a NRRD file written here, the type by the message's name).
TEST(LoadVolume, UnsupportedVoxelsNameTheTypesThatLoad) {
  TempDir dir;
  const std::string nifti = dir / "complex.nii";  // NIfTI complex64
  io::writeVolume(io::AnyVolume(makeVolume<float>(kDims)), nifti);
  std::string bytes = contents(nifti);
  const std::int16_t complex64 = 32, bits = 64;
  std::memcpy(&bytes[70], &complex64, 2);
  std::memcpy(&bytes[72], &bits, 2);
  writeFile(nifti, bytes + std::string(kDims.count() * 4, '\0'));
  const std::string channels = dir / "channels.mha";  // three channels per voxel: ITK's vector
  writeFile(channels, metaHeader("MET_UCHAR", kDims, "ElementNumberOfChannels = 3\n", "LOCAL") +
                          std::string(kDims.count() * 3, '\7'));
  for (const auto& [path, what] : {std::pair{nifti, std::string("complex64")}, std::pair{channels, std::string("3 components")}}) {
    SCOPED_TRACE(path);
    std::string message;
    try {
      io::loadVolume(path);
      ADD_FAILURE() << "loaded";
    } catch (const io::ReadError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find(what), std::string::npos) << message;
    const std::string lead = "of type ";
    const std::size_t at = message.find(lead);
    ASSERT_NE(at, std::string::npos) << message;
    std::vector<std::string> names;
    std::string list = message.substr(at + lead.size());
    for (std::size_t start = 0;;) {
      std::size_t end = list.find(", ", start);
      const std::size_t orAt = list.find(" or ", start);
      if (end == std::string::npos || (orAt != std::string::npos && orAt < end)) end = orAt;
      names.push_back(list.substr(start, end == std::string::npos ? std::string::npos : end - start));
      if (end == std::string::npos) break;
      start = end + (list.compare(end, 4, " or ") == 0 ? 4 : 2);
    }
    EXPECT_EQ(names.size(), 10u) << message;
    for (const std::string& name : names) {
      const ScalarType type = io::parseScalarType(name);
      const std::string file = dir / ("listed-" + name + ".nrrd");
      writeFile(file, nrrdHeader(name, kDims, "endian: little\nencoding: raw\n") + "\n" +
                          std::string(kDims.count() * sizeOf(type), '\1'));
      const LoadedVolume loaded = io::loadVolume(file);
      EXPECT_EQ(loaded.view.type, type) << name;
    }
  }
}

/// Every prefix of a valid header, parsed as a whole file and as the head of a longer one: the
/// parsers of io/VolumeHeader.h give a layout, ask for more bytes (only of a longer file) or
/// throw HeaderError — never another exception (a substr past the buffer throws
/// std::out_of_range), whatever byte the cut falls on.
TEST(LoadVolume, EveryCutOfAHeaderIsAHeaderErrorOrMoreBytes) {
  TempDir dir;
  std::vector<std::pair<std::string, std::string>> files = {
      {"mhd", metaHeader("MET_SHORT", kDims, "ElementNumberOfChannels = 1\n", "LIST") + "a.raw\nb.raw\r\nc.raw\n"},
      {"mhd", metaHeader("MET_SHORT", kDims, "", "slice%03d.raw 1 3 1")},
      {"nhdr", nrrdHeader("int16", kDims, "endian: little\nencoding: raw\ndata file: LIST\n") + "a.raw\r\nb.raw\rc.raw\n"},
      {"nhdr", nrrdHeader("int16", kDims, "endian: little\nencoding: raw\ndata file: s%02d.raw 1 3 1 2\n")},
  };
  for (const std::string ext : {"nii", "nrrd", "mha"}) {
    const std::string path = dir / ("cut." + ext);
    io::writeVolume(io::AnyVolume(makeVolume<std::int16_t>(kDims)), path);
    files.emplace_back(ext, contents(path));
  }
  for (const auto& [ext, bytes] : files) {
    const auto parse = ext == "nii" ? io::parseNifti1Header
                     : ext == "mha" || ext == "mhd" ? io::parseMetaImageHeader
                                                    : io::parseNrrdHeader;
    int layouts = 0;
    for (std::size_t n = 0; n <= bytes.size(); ++n) {
      const std::string head = bytes.substr(0, n);  // (a buffer of exactly n bytes)
      for (const std::uint64_t fileSize : {std::uint64_t(n), std::uint64_t(bytes.size())}) {
        SCOPED_TRACE(ext + ": the first " + std::to_string(n) + " of " + std::to_string(bytes.size()) +
                     " bytes, of a file of " + std::to_string(fileSize));
        try {
          const auto layout = parse(head, fileSize);
          if (!layout) {
            EXPECT_LT(n, fileSize) << "more bytes asked of a whole file";
          }
          layouts += layout.has_value();
        } catch (const io::HeaderError& e) {
          EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        } catch (const std::exception& e) {
          ADD_FAILURE() << "not a HeaderError: " << e.what();
        }
      }
    }
    EXPECT_GT(layouts, 0) << ext << ": the whole header never parsed";
  }
}

#ifdef SURFTRACK_FUZZ_DIR
/// The fuzzers' corpus and kept findings (fuzz/corpus/<format>/, fuzz/findings/<format>/, of
/// fuzz/run_fuzzers.sh), replayed as fuzz/fuzz_volume_header.cpp runs them, through this build:
/// each input is a ReadError or a volume whose every voxel reads, with the type, dimensions
/// and geometry of readVolume, and its voxels unless ITK decoded them (a finding once crashed,
/// hung or made the two disagree; a hang would stop this test).
TEST(LoadVolume, FuzzCorpusAndFindingsReplay) {
  TempDir dir;
  std::string pattern(65536, '\0');  // the fuzz target's data file next to each input
  for (std::size_t i = 0; i < pattern.size(); ++i) pattern[i] = char(i * 131 + (i >> 8));
  writeFile(dir / "data.raw", pattern);
  int replayed = 0, findings = 0;
  for (const std::string kind : {"corpus", "findings"}) {
    const fs::path root = fs::path(SURFTRACK_FUZZ_DIR) / kind;
    if (!fs::is_directory(root)) continue;
    for (const auto& formatDir : fs::directory_iterator(root)) {
      const std::string format = formatDir.path().filename().string();
      // The chunked stores' formats are replayed by tests/test_chunked_fuzz_replay.cpp.
      if (format == "zarr" || format == "n5" || format == "omezarr" || format == "blosc" || format == "zstd" ||
          format == "gzip")
        continue;
      for (const auto& entry : fs::directory_iterator(formatDir.path())) {
        const std::string bytes = contents(entry.path().string());
        SCOPED_TRACE(entry.path().string());
        const std::string input = dir / ("input." + format);
        io::ReadOptions options;
        std::function<LoadedVolume()> load;
        std::function<io::AnyVolume()> read;
        if (format == "raw") {  // the layout from the first 5 bytes (fuzzRaw)
          if (bytes.size() < 5) continue;
          io::RawLayout layout;
          const auto b = [&](int i) { return static_cast<unsigned char>(bytes[std::size_t(i)]); };
          layout.type = ScalarType(b(0) % 10);
          layout.bigEndian = b(0) & 0x80;
          layout.headerBytes = b(1) % 32;
          layout.dims = {1 + b(2) % 16, 1 + b(3) % 16, 1 + b(4) % 16};
          writeFile(input, bytes.substr(5));
          load = [=] { return io::loadRawVolume(input, layout); };
          read = [=] { return io::readRawVolume(input, layout); };
        } else {
          if (format == "tif" && bytes.size() % 3 != 0) options.channel = int(bytes.size() % 3) - 1;
          writeFile(input, bytes);
          load = [=] { return io::loadVolume(input, options); };
          read = [=] { return io::readVolume(input, options); };
        }
        ++replayed;
        findings += kind == "findings";
        LoadedVolume loaded;
        try {
          loaded = load();
        } catch (const io::ReadError& e) {
          EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
          continue;
        }
        const io::AnyVolume volume = read();
        const bool decoded = loaded.decodeReason.find("(decoded by ITK)") != std::string::npos;
        if (!decoded) {
          expectSame(loaded, volume, entry.path().string());
          continue;
        }
        ASSERT_EQ(loaded.view.type, io::scalarTypeOf(volume));
        ASSERT_EQ(loaded.view.dims, io::dimsOf(volume));
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(loaded.view.geometry.spacing[i], io::geometryOf(volume).spacing[i], 1e-9);
      }
    }
  }
  EXPECT_GT(findings, 0) << SURFTRACK_FUZZ_DIR "/findings holds no finding";
  std::printf("[          ] %d inputs replayed, %d of them kept findings\n", replayed, findings);
}
#endif

/// Random damage to the headers of valid files: a ReadError or a volume whose every voxel can be
/// read, never a crash (the fuzzer, fuzz/, does this at scale).
TEST(LoadVolume, DamagedHeadersNeverCrash) {
  TempDir dir;
  const DenseImage<std::int16_t> image = makeVolume<std::int16_t>(kDims);
  std::mt19937 random(12345);
  int loaded = 0, mapped = 0, errors = 0;
  for (const std::string ext : {"nrrd", "nhdr", "mha", "mhd", "nii"}) {
    const std::string path = dir / ("d." + ext);
    io::writeVolume(io::AnyVolume(image), path);
    const std::string original = contents(path);
    const std::size_t headerEnd = ext == "nii" ? 352 : ext == "nrrd" || ext == "mha" ? attachedOffset(path) : original.size();
    for (int trial = 0; trial < 150; ++trial) {
      std::string bytes = original;
      const int edits = 1 + int(random() % 4);
      for (int e = 0; e < edits; ++e) {
        const std::size_t at = random() % std::min(headerEnd, bytes.size());
        switch (random() % 3) {
          case 0: bytes[at] = char(random()); break;                            // replace a byte
          case 1: bytes.erase(at, 1 + random() % 8); break;                     // delete bytes
          default: bytes.insert(at, std::string(1 + random() % 4, char(random()))); break;  // insert
        }
      }
      writeFile(path, bytes);
      try {
        const LoadedVolume v = io::loadVolume(path);
        double sum = 0;  // touch every voxel
        visitScalarType(v.view.type, [&](auto t) {
          using T = decltype(t);
          const Dims d = v.view.dims;
          for (int z = 0; z < d.nz; ++z)
            for (int y = 0; y < d.ny; ++y)
              for (int x = 0; x < d.nx; ++x) {
                T value;
                std::memcpy(&value, voxelAt(v.view, x, y, z), sizeof(T));
                sum += double(value);
              }
        });
        ++loaded;
        mapped += v.mapped;
        // Whatever loadVolume accepts, readVolume reads the same way.
        io::AnyVolume read;
        try {
          read = io::readVolume(path);
        } catch (const io::ReadError& e) {
          ADD_FAILURE() << "loadVolume reads what readVolume rejects: " << e.what();
          continue;
        }
        expectSame(v, read, path + " damaged, trial " + std::to_string(trial));
      } catch (const io::ReadError& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        ++errors;
      }
    }
  }
  EXPECT_GT(errors, 0);
  EXPECT_GT(loaded, 0);
  std::printf("[          ] damaged headers: %d loaded (%d mapped), %d ReadErrors\n", loaded, mapped, errors);
}

// ---------------------------------------------------------------------------------------------
// Laziness.

TEST(LoadVolume, AFreshlyMappedLargeFileIsNotReadUntilTouched) {
  TempDir dir;
  struct statfs fsInfo {};
  ASSERT_EQ(::statfs(dir.path().c_str(), &fsInfo), 0);
  if (fsInfo.f_type == 0x01021994)  // TMPFS_MAGIC: the file's pages live in memory, always
    GTEST_SKIP() << dir.path() << " is a tmpfs: its pages are always resident";

  const Dims dims{512, 512, 256};  // 64 MiB of uint8
  const std::string path = dir / "large.nrrd";
  {
    const std::string header = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 512 512 256\nencoding: raw\n\n";
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::write(fd, header.data(), header.size()), ssize_t(header.size()));
    std::vector<unsigned char> slice(std::size_t(dims.nx) * dims.ny);
    for (int z = 0; z < dims.nz; ++z) {
      for (std::size_t i = 0; i < slice.size(); ++i) slice[i] = static_cast<unsigned char>(i * 7 + z);
      ASSERT_EQ(::write(fd, slice.data(), slice.size()), ssize_t(slice.size()));
    }
    // Written pages stay in the page cache: write them back, then ask the kernel to drop them,
    // so that what residentBytes() reports is what loading and touching bring back.
    ASSERT_EQ(::fdatasync(fd), 0);
    ASSERT_EQ(::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED), 0);
    ::close(fd);
  }
  const LoadedVolume v = io::loadVolume(path);
  ASSERT_TRUE(v.mapped) << v.decodeReason;
  ASSERT_EQ(v.dataBytes, dims.count());
  const std::uintmax_t before = v.residentBytes();
  // Reading the header brings in its page and some read-ahead, nothing like 64 MiB.
  EXPECT_LT(before, v.dataBytes / 16) << "resident after loading: " << before;
  // Touch one byte per page of the first half: those pages become resident.
  const auto* bytes = static_cast<const unsigned char*>(v.view.data);
  unsigned sum = 0;
  for (std::uintmax_t i = 0; i < v.dataBytes / 2; i += 4096) sum += bytes[i];
  const std::uintmax_t after = v.residentBytes();
  EXPECT_GE(after, v.dataBytes / 2 * 9 / 10) << "resident after touching half: " << after << " (sum " << sum << ")";
  EXPECT_LE(after, v.dataBytes);
  EXPECT_EQ(bytes[std::size_t(dims.nx) * dims.ny * 3 + 10], static_cast<unsigned char>(10 * 7 + 3));
  std::printf("[          ] 64 MiB mapped: %.2f MiB resident after loading, %.2f MiB after touching half\n",
              double(before) / (1 << 20), double(after) / (1 << 20));
}

// With Access::Sparse (a seeded extraction) a page fault reads its own page only: touching one
// byte every 256 KiB brings in about one page each, not the read-around of each fault.
TEST(LoadVolume, SparseAccessReadsThePagesTouchedOnly) {
  TempDir dir;
  struct statfs fsInfo {};
  ASSERT_EQ(::statfs(dir.path().c_str(), &fsInfo), 0);
  if (fsInfo.f_type == 0x01021994)  // TMPFS_MAGIC
    GTEST_SKIP() << dir.path() << " is a tmpfs: its pages are always resident";
  const std::string path = dir / "sparse.raw";
  const std::size_t bytes = std::size_t(64) << 20;
  {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    std::vector<unsigned char> chunk(std::size_t(1) << 20);
    for (std::size_t i = 0; i < chunk.size(); ++i) chunk[i] = static_cast<unsigned char>(i * 13);
    for (std::size_t at = 0; at < bytes; at += chunk.size())
      ASSERT_EQ(::write(fd, chunk.data(), chunk.size()), ssize_t(chunk.size()));
    ASSERT_EQ(::fdatasync(fd), 0);
    ASSERT_EQ(::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED), 0);
    ::close(fd);
  }
  io::RawLayout layout;
  layout.dims = Dims{1024, 1024, 64};
  const LoadedVolume v = io::loadRawVolume(path, layout);
  ASSERT_TRUE(v.mapped) << v.decodeReason;
  v.advise(LoadedVolume::Access::Sparse);
  const std::uintmax_t before = v.residentBytes();
  const auto* data = static_cast<const unsigned char*>(v.view.data);
  unsigned sum = 0;
  const std::size_t stride = std::size_t(256) << 10, touches = bytes / stride;
  for (std::size_t i = 0; i < bytes; i += stride) sum += data[i];
  const std::uintmax_t after = v.residentBytes();
  EXPECT_EQ(data[stride + 5], static_cast<unsigned char>((stride + 5) * 13));
  // One 4 KiB page per touch, give or take the pages resident before; read-around would bring
  // in 32 or more per touch.
  EXPECT_LE(after - before, touches * 4 * 4096) << "sum " << sum;
  EXPECT_GE(after, touches * 4096 * 9 / 10);
  std::printf("[          ] %zu touches: %.2f MiB resident (%.2f MiB before)\n", touches,
              double(after) / (1 << 20), double(before) / (1 << 20));
}

}  // namespace
