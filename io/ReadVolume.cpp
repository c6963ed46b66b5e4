// The ITK half of io/: the only translation unit of the project that includes ITK headers.
// readVolume copies what ITK decodes into a DenseImage; the loader (io/LoadVolume.cpp) reads
// headers through it (readItkHeader) and views ITK's decoded buffer in place (decodeWithItk).
#include "ReadVolume.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <mutex>
#include <regex>
#include <sstream>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <gdcmTrace.h>
#include <gdcmUIDGenerator.h>
#include <itkGDCMImageIO.h>
#include <itkGDCMImageIOFactory.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageIOFactory.h>
#include <itkImageSeriesReader.h>
#include <itkImageSeriesWriter.h>
#include <itkMetaDataObject.h>
#include <itkMetaImageIOFactory.h>
#include <itkNiftiImageIOFactory.h>
#include <itkNrrdImageIOFactory.h>
#include <itkTIFFImageIOFactory.h>
#include <itkVTKImageIOFactory.h>
#include <zlib.h>

#include <cstdarg>

#include "Internal.h"
#include "MappedFile.h"
#include "TiffStack.h"
#include "VolumeHeader.h"

// ITK's own copy of libtiff (libitktiff, every name prefixed itk_; its header is not
// installed): libtiff's TIFFSetWarningHandler.
extern "C" {
using ItkTiffHandler = void (*)(const char* module, const char* format, va_list arguments);
ItkTiffHandler itk_TIFFSetWarningHandler(ItkTiffHandler handler);
}

namespace surftrack::io {

namespace {

namespace fs = std::filesystem;

/// Registers the ImageIO factories once. Registering them by hand, instead of through the
/// ITK_IO_FACTORY_REGISTER_MANAGER machinery of ${ITK_USE_FILE}, keeps ITK out of every other
/// target's compile flags.
void registerFactories() {
  static std::once_flag once;
  std::call_once(once, [] {
    itk::Object::GlobalWarningDisplayOff();  // ITK warnings are multi-line noise on stderr
    itk_TIFFSetWarningHandler(nullptr);       // and libtiff's (ITK's TIFF reader installs an
                                              // error handler of its own, not a warning one)
    gdcm::Trace::WarningOff();                // and so are GDCM's (DICOM)
    gdcm::Trace::ErrorOff();
    gdcm::Trace::DebugOff();
    itk::NiftiImageIOFactory::RegisterOneFactory();
    itk::NrrdImageIOFactory::RegisterOneFactory();
    itk::MetaImageIOFactory::RegisterOneFactory();
    itk::GDCMImageIOFactory::RegisterOneFactory();
    itk::TIFFImageIOFactory::RegisterOneFactory();
    itk::VTKImageIOFactory::RegisterOneFactory();
  });
}

/// Mutes std::cerr for its lifetime: ITK's MetaIO and NRRD readers write their complaints there
/// ("MetaImage: M_ReadElementsData: file stream is fail after read") before the exception that
/// reaches the user as one ReadError line. Process-wide while ITK reads: another thread's output
/// on std::cerr in that time is lost too (the tool reads its one file before it starts threads).
class MutedCerr {
 public:
  MutedCerr() : saved_(std::cerr.rdbuf(nullptr)) {}
  ~MutedCerr() { std::cerr.rdbuf(saved_); }  // (rdbuf() clears the error state muting set)
  MutedCerr(const MutedCerr&) = delete;
  MutedCerr& operator=(const MutedCerr&) = delete;

 private:
  std::streambuf* saved_;
};

/// An ITK exception as one line for a user: its description with white space collapsed,
/// without ITK's "ITK ERROR: NrrdImageIO(0x55e4aa74c3b0): " (a pointer tells a user nothing;
/// the reader's name is kept, as "ITK's NrrdImageIO: "), and of teem's chain of messages
/// "[nrrd] nrrdLoad: trouble ... [nrrd] _nrrdEncodingGzip_read: expected 48 bytes but received
/// 44" (ITK's NRRD reader) only the last one, which says what is wrong.
std::string oneLine(const itk::ExceptionObject& e) {
  std::string text;
  bool space = false;
  for (const char* p = e.GetDescription() ? e.GetDescription() : ""; *p; ++p) {
    const char ch = *p;
    if (ch == '\n' || ch == '\r' || ch == '\t' || ch == ' ') {
      space = !text.empty();
      continue;
    }
    if (space) text += ' ';
    space = false;
    text += ch;
  }
  static const std::regex prefix(R"(^(ITK ERROR: )?([A-Za-z_][A-Za-z0-9_:]*)\(0x[0-9a-fA-F]+\): )");
  std::string reader;
  std::smatch m;
  if (std::regex_search(text, m, prefix)) {
    reader = m[2].str();
    text = m.suffix().str();
  } else if (text.rfind("ITK ERROR: ", 0) == 0) {
    text.erase(0, 11);
  }
  if (const std::size_t last = text.rfind("[nrrd] "); last != std::string::npos) {
    text.erase(0, last + 7);
    static const std::regex function(R"(^[A-Za-z_][A-Za-z0-9_]*: )");
    text = std::regex_replace(text, function, "", std::regex_constants::format_first_only);
  }
  if (text.empty()) text = "unknown error";
  return reader.empty() ? "ITK: " + text : "ITK's " + reader + ": " + text;
}

std::string componentName(itk::IOComponentEnum c) {
  return itk::ImageIOBase::GetComponentTypeAsString(c);
}

std::optional<ScalarType> scalarTypeOf(itk::IOComponentEnum c) {
  using C = itk::IOComponentEnum;
  switch (c) {
    case C::UCHAR: return ScalarType::UInt8;
    case C::CHAR: return ScalarType::Int8;
    case C::SHORT: return ScalarType::Int16;
    case C::USHORT: return ScalarType::UInt16;
    case C::INT: return ScalarType::Int32;
    case C::UINT: return ScalarType::UInt32;
    case C::LONG: case C::LONGLONG: return ScalarType::Int64;
    case C::ULONG: case C::ULONGLONG: return ScalarType::UInt64;
    case C::FLOAT: return ScalarType::Float32;
    case C::DOUBLE: return ScalarType::Float64;
    default: return std::nullopt;
  }
}

template <class T>
using ImagePointer = typename itk::Image<T, 3>::Pointer;

/// The domain and geometry of an ITK image (or of a reader's output after
/// UpdateOutputInformation, before any voxel is read), with readVolume's checks.
template <class T>
std::pair<Dims, ImageGeometry> domainOf(const itk::Image<T, 3>* image, const std::string& path) {
  const auto region = image->GetLargestPossibleRegion();
  const auto size = region.GetSize();
  Dims dims{int(size[0]), int(size[1]), int(size[2])};
  if (dims.empty()) throw ReadError("cannot read '" + path + "': the image is empty");
  ImageGeometry geometry;
  for (int a = 0; a < 3; ++a) {
    geometry.spacing[a] = image->GetSpacing()[a];
    geometry.origin[a] = image->GetOrigin()[a];
    for (int b = 0; b < 3; ++b) geometry.direction[a][b] = image->GetDirection()(a, b);
    if (!(geometry.spacing[a] > 0) || !std::isfinite(geometry.spacing[a]))
      throw ReadError("cannot read '" + path + "': its voxel spacing is not positive");
  }
  return {dims, geometry};
}

/// Copies an ITK image into a DenseImage with its geometry.
template <class T>
AnyVolume toDense(const itk::Image<T, 3>* image, const std::string& path) {
  const auto [dims, geometry] = domainOf(image, path);
  DenseImage<T> out(dims, T{}, geometry);
  const T* buffer = image->GetBufferPointer();
  std::copy(buffer, buffer + dims.count(), out.data().begin());
  return AnyVolume(std::move(out));
}

/// Views an ITK image's own buffer (x fastest, contiguous), which `owner` keeps alive.
template <class T>
LoadedVolume toLoaded(const itk::SmartPointer<itk::Image<T, 3>>& image, const std::string& path) {
  const auto [dims, geometry] = domainOf(image.GetPointer(), path);
  LoadedVolume out;
  out.view = VolumeView::of<T>(image->GetBufferPointer(), dims, geometry);
  out.owner = std::shared_ptr<const void>(image->GetBufferPointer(), [image](const void*) {});
  out.dataBytes = dims.count() * sizeof(T);
  return out;
}

/// The image type whose reader gives readFileAs and readSeriesAs the output information (size,
/// spacing, origin, direction) ITK's readers give every pixel type: it does not depend on the
/// pixel type (ImageFileReader::GenerateOutputInformation, ImageSeriesReader's likewise).
using InformationImage = itk::Image<std::uint8_t, 3>;

/// A fresh image of T with the geometry of `information`.
template <class T>
ImagePointer<T> allocatedLike(const InformationImage* information) {
  auto image = itk::Image<T, 3>::New();
  image->SetRegions(information->GetLargestPossibleRegion());
  image->SetSpacing(information->GetSpacing());
  image->SetOrigin(information->GetOrigin());
  image->SetDirection(information->GetDirection());
  image->Allocate();
  return image;
}

/// The whole of an ImageIO's file, its own dimensions (2D for a 2D file).
itk::ImageIORegion wholeRegion(const itk::ImageIOBase* imageIO) {
  itk::ImageIORegion region(imageIO->GetNumberOfDimensions());
  for (unsigned d = 0; d < imageIO->GetNumberOfDimensions(); ++d) {
    region.SetIndex(d, 0);
    region.SetSize(d, imageIO->GetDimensions(d));
  }
  return region;
}

/// What ImageFileReader<Image<T, 3>> reads when T is the file's component type (readWithItk
/// chooses T so): its output information, and the voxels the ImageIO writes straight into the
/// image's buffer, as ImageFileReader::GenerateData does in that case. One reader type for all
/// the pixel types instead of ten keeps ITK's pixel conversions, which surftrack never uses, out
/// of the build (about 40 % of this file's compile time).
template <class T>
ImagePointer<T> readFileAs(itk::ImageIOBase* imageIO, const std::string& path) {
  auto reader = itk::ImageFileReader<InformationImage>::New();
  reader->SetFileName(path);
  reader->SetImageIO(imageIO);
  reader->UpdateOutputInformation();
  ImagePointer<T> image = allocatedLike<T>(reader->GetOutput());
  imageIO->SetFileName(path);
  imageIO->SetIORegion(wholeRegion(imageIO));
  imageIO->Read(image->GetBufferPointer());
  return image;
}

/// What ImageSeriesReader<Image<T, 3>> reads: its output information (the slices' positions
/// give the origin, the spacing between slices and the direction), and each file's voxels after
/// the previous ones', converted to T (the first file's type) as ITK converts them (a cast) when
/// a file's own type differs (another rescale slope).
template <class T>
ImagePointer<T> readSeriesAs(const std::vector<std::string>& files) {
  auto dicom = itk::GDCMImageIO::New();
  auto reader = itk::ImageSeriesReader<InformationImage>::New();
  reader->SetImageIO(dicom);
  reader->SetFileNames(files);
  reader->UpdateOutputInformation();
  ImagePointer<T> image = allocatedLike<T>(reader->GetOutput());
  const std::size_t total = image->GetLargestPossibleRegion().GetNumberOfPixels();
  std::size_t filled = 0;
  for (const std::string& file : files) {
    dicom->SetFileName(file);
    dicom->ReadImageInformation();
    const itk::ImageIORegion region = wholeRegion(dicom);
    const std::size_t voxels = region.GetNumberOfPixels();
    const auto type = scalarTypeOf(dicom->GetComponentType());
    if (dicom->GetNumberOfComponents() != 1 || !type || voxels > total - filled)
      throw ReadError("cannot read the DICOM series of '" + files.front() + "': '" + file +
                      "' does not hold a slice of the series' size and of one scalar a voxel");
    dicom->SetIORegion(region);
    T* into = image->GetBufferPointer() + filled;
    visitScalarType(*type, [&](auto v) {
      using S = decltype(v);
      if constexpr (std::is_same_v<S, T>) {
        dicom->Read(into);
      } else {
        std::vector<S> slice(voxels);
        dicom->Read(slice.data());
        std::transform(slice.begin(), slice.end(), into, [](S x) { return static_cast<T>(x); });
      }
    });
    filled += voxels;
  }
  if (filled != total)
    throw ReadError("cannot read the DICOM series of '" + files.front() + "': its files hold " +
                    std::to_string(filled) + " voxels, and its slices announce " + std::to_string(total));
  return image;
}

/// A ReadError for voxels surftrack does not read: `what` says what they are ("its voxels have
/// 3 components", "its voxel type is 'long double'").
ReadError unsupportedType(const std::string& path, const std::string& what) {
  return ReadError("cannot read '" + path + "': " + what + "; surftrack reads one scalar per voxel, of type " +
                   supportedTypesText());
}

/// "its voxels have N components (RGB, complex or vector voxels)".
std::string componentsText(unsigned components) {
  return "its voxels have " + std::to_string(components) + " components (RGB, complex or vector voxels)";
}

/// What readWithItk read besides the image: the format, and a TIFF stack's unit and channel.
struct ItkRead {
  std::string format;
  std::string unit;
  int channel = 0, channels = 1;
};

/// Reads the first DICOM series of a directory and hands the image to `use`.
template <class Use>
auto readDicomDirectory(const std::string& path, Use&& use) {
  auto names = itk::GDCMSeriesFileNames::New();
  names->SetUseSeriesDetails(true);
  names->SetDirectory(path);
  const auto& uids = names->GetSeriesUIDs();
  if (uids.empty()) throw ReadError("cannot read '" + path + "': no DICOM series in this directory");
  const std::vector<std::string> files = names->GetFileNames(uids.front());
  if (files.empty()) throw ReadError("cannot read '" + path + "': empty DICOM series");
  auto dicom = itk::GDCMImageIO::New();
  dicom->SetFileName(files.front());
  dicom->ReadImageInformation();
  if (dicom->GetNumberOfComponents() != 1)
    throw unsupportedType(path, componentsText(dicom->GetNumberOfComponents()));
  const auto type = scalarTypeOf(dicom->GetComponentType());
  if (!type) throw unsupportedType(path, "its voxel type is '" + componentName(dicom->GetComponentType()) + "'");
  ItkRead read;
  read.format = "dicom";
  return visitScalarType(*type, [&](auto v) { return use(readSeriesAs<decltype(v)>(files), read); });
}

std::string lowerName(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return name;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// Bytes of a file after decompression (gzip is detected; other files are counted as they
/// are), or -1 for a corrupt gzip stream. Reads the whole stream.
std::int64_t decompressedSize(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return -1;
  std::vector<char> buffer(1 << 20);
  std::int64_t total = 0;
  for (;;) {
    const int n = gzread(f, buffer.data(), unsigned(buffer.size()));
    if (n < 0) {
      gzclose(f);
      return -1;
    }
    if (n == 0) break;
    total += n;
  }
  int error = 0;
  gzerror(f, &error);
  gzclose(f);
  return error == Z_OK || error == Z_STREAM_END ? total : -1;
}

/// The size of a (possibly gzipped) file's content: the file size when it is not compressed.
std::int64_t contentSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[2] = {0, 0};
  in.read(reinterpret_cast<char*>(magic), 2);
  std::error_code ec;
  if (!(magic[0] == 0x1f && magic[1] == 0x8b)) return std::int64_t(fs::file_size(path, ec));
  return decompressedSize(path);
}

/// NIfTI (.nii, .nii.gz, .hdr/.img): ITK's reader fills a short data block with zeros without
/// a word, so compare the data size with the header's vox_offset + voxel bytes. The bytes per
/// voxel are those of the header's datatype (as niftilib reads it), not ITK's component size:
/// ITK reports scaled integer voxels (scl_slope) as float.
void requireCompleteNifti(const std::string& path, std::size_t voxels, std::size_t componentSize) {
  const std::string name = lowerName(path);
  std::string dataFile = path;
  double offset = 0;
  const bool single = endsWith(name, ".nii") || endsWith(name, ".nii.gz");
  const bool pair = endsWith(name, ".hdr") || endsWith(name, ".hdr.gz");
  if (!single && !pair) return;
  gzFile f = gzopen(path.c_str(), "rb");
  unsigned char header[544] = {};
  const int n = f ? gzread(f, header, sizeof header) : -1;
  if (f) gzclose(f);
  if (n < 348) throw ReadError("cannot read '" + path + "': the file is truncated (no complete NIfTI header)");
  std::int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, header, 4);
  const bool swapped = sizeofHdr != 348 && sizeofHdr != 540;
  auto get = [&](std::size_t at, std::size_t bytes, void* out) {
    unsigned char tmp[8];
    std::memcpy(tmp, header + at, bytes);
    if (swapped) std::reverse(tmp, tmp + bytes);
    std::memcpy(out, tmp, bytes);
  };
  get(0, 4, &sizeofHdr);
  std::int16_t datatype = 0;
  if (sizeofHdr == 348) {  // NIfTI-1 (or Analyze 7.5): datatype at 70, vox_offset at 108
    get(70, 2, &datatype);
    float voxOffset;
    get(108, 4, &voxOffset);
    if (single) offset = voxOffset;
  } else if (sizeofHdr == 540 && n >= 540) {  // NIfTI-2: datatype at 12, vox_offset at 168
    get(12, 2, &datatype);
    std::int64_t voxOffset;
    get(168, 8, &voxOffset);
    if (single) offset = double(voxOffset);
  } else {
    return;  // not a header we know: leave it to ITK
  }
  if (!(offset >= 0)) offset = 0;  // (a negative or NaN vox_offset must not hide a short file)
  std::size_t bytesPerVoxel = componentSize;
  switch (datatype) {  // nifti1.h's DT_* codes and their sizes
    case 2: case 256: bytesPerVoxel = 1; break;
    case 4: case 512: bytesPerVoxel = 2; break;
    case 128: bytesPerVoxel = 3; break;
    case 8: case 16: case 768: case 2304: bytesPerVoxel = 4; break;
    case 32: case 64: case 1024: case 1280: bytesPerVoxel = 8; break;
    case 1536: case 1792: bytesPerVoxel = 16; break;
    case 2048: bytesPerVoxel = 32; break;
    default: break;
  }
  const std::size_t dataBytes = voxels * bytesPerVoxel;
  if (pair) {
    dataFile = path.substr(0, path.size() - (endsWith(name, ".gz") ? 7 : 4)) + ".img";
    std::error_code ec;
    if (!fs::exists(dataFile, ec) && fs::exists(dataFile + ".gz", ec)) dataFile += ".gz";
  }
  const std::int64_t size = contentSize(dataFile);
  if (size < 0) throw ReadError("cannot read '" + path + "': corrupt compressed data");
  if (double(size) < offset + double(dataBytes))
    throw ReadError("cannot read '" + path + "': the file is truncated (" + std::to_string(size) +
                    " bytes of data where the header announces " +
                    std::to_string(std::int64_t(offset) + std::int64_t(dataBytes)) + ")");
}

/// A data file (.raw of a .mhd, data of a .nhdr) that is shorter than its header says is
/// read by some ITK readers without complaint; check the size where it is cheap to know.
void requireCompleteData(itk::ImageIOBase* imageIO, const std::string& path, std::size_t voxels) {
  requireCompleteNifti(path, voxels, imageIO->GetComponentSize());
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".mha" || ext == ".mhd") {
    // MetaImage: read the header lines up to ElementDataFile.
    std::ifstream in(path, std::ios::binary);
    std::string line, dataFile;
    bool compressed = false;
    std::streamoff headerEnd = 0;
    while (std::getline(in, line)) {
      // As MetaIO reads a line: the whole key (trimmed) before the first '=' or ':', the value
      // after it and any further '=', ':' and blanks; a boolean is true when it begins with T,
      // t or 1.
      const auto sep = line.find_first_of("=:");
      if (sep == std::string::npos) continue;
      std::string key = line.substr(0, sep);
      key.erase(0, std::min(key.size(), key.find_first_not_of(" \t\r")));
      key.erase(std::min(key.size(), key.find_last_not_of(" \t\r") + 1));
      const auto valueAt = line.find_first_not_of("=: \t", sep);
      const std::string value = valueAt == std::string::npos ? "" : line.substr(valueAt);
      if (key == "CompressedData" && !value.empty() && (value[0] == 'T' || value[0] == 't' || value[0] == '1'))
        compressed = true;
      if (key == "ElementDataFile") {
        dataFile = value;  // without what MetaIO strips from its end: white space, unprintable bytes
        while (!dataFile.empty() && (static_cast<unsigned char>(dataFile.back()) <= 0x20 ||
                                     static_cast<unsigned char>(dataFile.back()) >= 0x7f))
          dataFile.pop_back();
        headerEnd = in.tellg();
        break;
      }
    }
    if (dataFile.rfind("LIST", 0) == 0) {
      // MetaIO leaves the voxels of a blank, missing or unterminated entry of the list unread
      // (uninitialised): the loader's parser refuses such lists, and readVolume with it.
      std::error_code ec;
      const std::uintmax_t size = fs::file_size(path, ec);
      std::ifstream whole(path, std::ios::binary);
      std::string head(std::size_t(std::min<std::uintmax_t>(size, kMaxHeaderBytes)), '\0');
      head.resize(std::size_t(whole.read(head.data(), std::streamsize(head.size())).gcount()));
      try {
        parseMetaImageHeader(head, head.size() < size ? size : head.size());
      } catch (const HeaderError& e) {
        throw ReadError("cannot read '" + path + "': " + e.what());
      }
    }
    if (compressed || dataFile.empty()) return;
    const std::size_t bytes = voxels * imageIO->GetComponentSize();
    std::error_code ec;
    if (dataFile == "LOCAL" || dataFile == "Local" || dataFile == "local") {
      if (fs::file_size(path, ec) < std::uintmax_t(headerEnd) + bytes)
        throw ReadError("cannot read '" + path + "': the file is truncated");
    } else if (dataFile.find('%') == std::string::npos && dataFile.rfind("LIST", 0) != 0) {
      const fs::path data = fs::path(path).parent_path() / dataFile;
      if (!fs::exists(data, ec))
        throw ReadError("cannot read '" + path + "': its data file '" + data.string() + "' is missing");
      if (fs::file_size(data, ec) < bytes)
        throw ReadError("cannot read '" + path + "': its data file '" + data.string() + "' is truncated");
    }
  }
}

TiffStack tiffStackOf(const std::string& path);

/// Whether `path` begins as a TIFF or BigTIFF does ("II*\0", "MM\0*", "II+\0", "MM\0+"), as
/// libtiff, and so ITK's TIFF reader, recognises one.
bool isTiff(const std::string& path) {
  char head[4] = {};
  std::ifstream in(path, std::ios::binary);
  if (!in.read(head, 4)) return false;
  const std::string_view h(head, 4);
  return h == std::string_view("II*\0", 4) || h == std::string_view("MM\0*", 4) || h == std::string_view("II+\0", 4) ||
         h == std::string_view("MM\0+", 4);
}

/// The ImageIO that reads the file `path`, after readVolume's checks (an existing, readable,
/// non-empty file ITK recognises, a 3D image of one scalar component per voxel), its header read;
/// `type` and `voxels` are the voxel type and count, `stack` what a TIFF's metadata says.
itk::ImageIOBase::Pointer openImageIO(const std::string& path, ScalarType& type, std::size_t& voxels,
                                      TiffStack* stack = nullptr) {
  std::error_code ec;
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw ReadError("cannot open '" + path + "': " + std::strerror(errno));
    if (fs::file_size(path, ec) == 0) throw ReadError("cannot read '" + path + "': the file is empty");
  }
  // A TIFF's directories are read by io/TiffStack.cpp before ITK opens it: it refuses what
  // libtiff would allocate without bound as ITK probes the file (CreateImageIO) and the tags
  // ITK's reader would read past (ReadImageInformation copies every tag into its dictionary).
  if (isTiff(path)) {
    TiffStack parsed = tiffStackOf(path);
    if (stack) *stack = std::move(parsed);
  }
  itk::ImageIOBase::Pointer imageIO =
      itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
  if (!imageIO)
    throw ReadError("cannot read '" + path +
                    "': not a recognised image file (NIfTI, NRRD, MetaImage, DICOM, TIFF, VTK); "
                    "for a raw file give --raw-dims and --raw-type");
  imageIO->SetFileName(path);
  if (std::string(imageIO->GetNameOfClass()) == "TIFFImageIO" && !isTiff(path))
    throw ReadError("cannot read '" + path + "': ITK reads it as a TIFF, and it does not begin as one");
  imageIO->ReadImageInformation();
  const unsigned dimension = imageIO->GetNumberOfDimensions();
  voxels = 1;
  for (unsigned d = 0; d < dimension; ++d) {
    voxels *= imageIO->GetDimensions(d);
    if (d >= 3 && imageIO->GetDimensions(d) != 1)
      throw ReadError("cannot read '" + path + "': a " + std::to_string(dimension) +
                      "D image with more than one volume; give a 3D image");
  }
  if (imageIO->GetNumberOfComponents() != 1)
    throw unsupportedType(path, componentsText(imageIO->GetNumberOfComponents()));
  const auto t = scalarTypeOf(imageIO->GetComponentType());
  if (!t) throw unsupportedType(path, "its voxel type is '" + componentName(imageIO->GetComponentType()) + "'");
  type = *t;
  return imageIO;
}

/// The format of a file ITK reads, for LoadedVolume::format: its extension ("nii.gz" for a
/// gzip'd NIfTI-1), "dicom", "tiff" or "vtk" from the ImageIO.
std::string formatOf(const itk::ImageIOBase* imageIO, const std::string& path) {
  const std::string io = imageIO->GetNameOfClass();
  if (io == "GDCMImageIO") return "dicom";
  if (io == "TIFFImageIO") return "tiff";
  if (io == "VTKImageIO") return "vtk";
  const std::string name = lowerName(path);
  if (endsWith(name, ".nii.gz")) return "nii.gz";
  const std::string ext = fs::path(name).extension().string();
  return ext.size() > 1 ? ext.substr(1) : io;
}

/// The name ITK's NIfTI reader should read the voxels of `path` from. niftilib looks for the
/// voxels of X.nii.gz by base name, X.nii first: when that file exists beside it, ITK gives the
/// header of X.nii.gz with the voxels of X.nii. Such a file is read through a link of its own in
/// an empty directory, removed with this object; any other file by its own name.
class SoleName {
 public:
  explicit SoleName(const std::string& path) : path_(path) {
    const std::string name = lowerName(path);
    std::error_code ec;
    if (!endsWith(name, ".nii.gz") || !fs::exists(path.substr(0, path.size() - 3), ec)) return;
    std::string dir = (fs::temp_directory_path() / "surftrack-nifti-XXXXXX").string();
    if (!::mkdtemp(dir.data())) throw ReadError("cannot read '" + path + "': " + std::strerror(errno));
    dir_ = dir;
    path_ = (fs::path(dir) / "volume.nii.gz").string();
    fs::create_symlink(fs::absolute(path), path_, ec);
    if (ec) throw ReadError("cannot read '" + path + "': " + ec.message());
  }
  ~SoleName() {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  SoleName(const SoleName&) = delete;
  SoleName& operator=(const SoleName&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_, dir_;
};

/// The ImageJ or OME metadata of the TIFF `path` (io/TiffStack.h).
TiffStack tiffStackOf(const std::string& path) {
  const detail::OpenFile file(path, "cannot read '" + path + "'");
  try {
    return parseTiffStack(
        [&](std::uint64_t offset, std::size_t bytes) {
          std::string out(bytes, '\0');
          out.resize(file.readAt(offset, out.data(), bytes));
          return out;
        },
        file.size(), fs::path(path).filename().string());
  } catch (const HeaderError& e) {
    throw ReadError("cannot read '" + path + "': " + e.what());
  }
}

/// The slices of channel `channel` of a TIFF stack that ITK read as one volume of all its pages
/// (a copy, unless the stack has one channel), with the voxel size its metadata states.
template <class T>
ImagePointer<T> stackChannel(const ImagePointer<T>& pages, const TiffStack& stack, int channel, const std::string& path) {
  using Image = itk::Image<T, 3>;
  const auto size = pages->GetLargestPossibleRegion().GetSize();
  if (std::int64_t(size[2]) != stack.pages())
    throw ReadError("cannot read '" + path + "': its " + stack.source + " metadata announces " +
                    std::to_string(stack.pages()) + " images (" + std::to_string(stack.channels) + " channels x " +
                    std::to_string(stack.slices) + " slices), and ITK reads " + std::to_string(size[2]) + " pages");
  if (stack.width != 0 && (std::int64_t(size[0]) != stack.width || std::int64_t(size[1]) != stack.height))
    throw ReadError("cannot read '" + path + "': its OME metadata announces " + std::to_string(stack.width) + " x " +
                    std::to_string(stack.height) + " pixels a plane, and ITK reads " + std::to_string(size[0]) + " x " +
                    std::to_string(size[1]));
  ImagePointer<T> out = pages;
  if (stack.channels > 1) {
    out = Image::New();
    typename Image::SizeType outSize = size;
    outSize[2] = std::size_t(stack.slices);
    out->SetRegions(typename Image::RegionType(outSize));
    out->SetSpacing(pages->GetSpacing());
    out->SetOrigin(pages->GetOrigin());
    out->SetDirection(pages->GetDirection());
    out->Allocate();
    const std::size_t plane = size[0] * size[1];
    for (std::int64_t z = 0; z < stack.slices; ++z) {
      const std::int64_t page = stack.channelFirst ? channel + stack.channels * z : z + stack.slices * channel;
      const T* from = pages->GetBufferPointer() + std::size_t(page) * plane;
      std::copy(from, from + plane, out->GetBufferPointer() + std::size_t(z) * plane);
    }
  }
  if (stack.spacing) {
    typename Image::SpacingType spacing;
    for (int a = 0; a < 3; ++a) spacing[a] = (*stack.spacing)[a];
    out->SetSpacing(spacing);
  }
  return out;
}

/// Reads `path` with ITK (a file, or a directory holding a DICOM series) and hands the decoded
/// image and what else was read (ItkRead) to `use`; readVolume's checks, ITK's errors as
/// ReadError.
template <class Use>
auto readWithItk(const std::string& path, const ReadOptions& options, Use&& use) {
  registerFactories();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw ReadError("cannot read '" + path + "': no such file");
  const MutedCerr muted;
  try {
    if (fs::is_directory(path, ec)) {
      detail::requireChannel(path, options, 1, "");
      return readDicomDirectory(path, use);
    }
    ScalarType type{};
    std::size_t voxels = 0;
    TiffStack stack;
    itk::ImageIOBase::Pointer imageIO = openImageIO(path, type, voxels, &stack);
    requireCompleteData(imageIO, path, voxels);
    ItkRead read;
    read.format = formatOf(imageIO, path);
    read.unit = stack.unit;
    read.channels = int(stack.channels);
    read.channel = detail::requireChannel(path, options, stack.channels, stack.channelsField);
    const SoleName sole(path);
    return visitScalarType(type, [&](auto v) {
      using T = decltype(v);
      ImagePointer<T> image = readFileAs<T>(imageIO, sole.path());
      if (!stack.source.empty()) image = stackChannel<T>(image, stack, read.channel, path);
      return use(image, read);
    });
  } catch (const itk::ExceptionObject& e) {
    throw ReadError("cannot read '" + path + "': " + oneLine(e));
  } catch (const std::bad_alloc&) {
    throw ReadError("cannot read '" + path + "': out of memory");
  }
}

}  // namespace

AnyVolume readVolume(const std::string& path, const ReadOptions& options) {
  return readWithItk(path, options, [&](auto image, const ItkRead&) -> AnyVolume {
    return toDense(image.GetPointer(), path);
  });
}

namespace detail {

LoadedVolume decodeWithItk(const std::string& path, const ReadOptions& options) {
  return readWithItk(path, options, [&](auto image, const ItkRead& read) -> LoadedVolume {
    LoadedVolume out = toLoaded(image, path);
    out.format = read.format;
    out.unit = read.unit;
    out.channel = read.channel;
    out.channels = read.channels;
    return out;
  });
}

int requireChannel(const std::string& path, const ReadOptions& options, std::int64_t channels, const std::string& field) {
  const std::string last = std::to_string(channels - 1);
  if (!options.channel) {
    if (channels == 1) return 0;
    throw ReadError("cannot read '" + path + "': it has " + std::to_string(channels) + " channels (" + field +
                    "); choose one with --channel C, C from 0 to " + last);
  }
  const int c = *options.channel;
  if (c < 0 || c >= channels)
    throw ReadError("cannot read '" + path + "': there is no channel " + std::to_string(c) + " (--channel): " +
                    (channels == 1 ? std::string("it has one channel, 0")
                                   : "it has " + std::to_string(channels) + " channels (" + field + "), 0 to " + last));
  return c;
}

ItkHeader readItkHeader(const std::string& path) {
  registerFactories();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw ReadError("cannot read '" + path + "': no such file");
  const MutedCerr muted;
  try {
    ItkHeader header;
    std::size_t voxels = 0;
    itk::ImageIOBase::Pointer imageIO = openImageIO(path, header.type, voxels);
    // The reader's output information is the geometry readVolume gives: ImageFileReader pads
    // 2D images to 3D, takes the direction cosines as the matrix's columns, etc.
    auto reader = itk::ImageFileReader<InformationImage>::New();  // (readFileAs)
    reader->SetFileName(path);
    reader->SetImageIO(imageIO);
    reader->UpdateOutputInformation();
    std::tie(header.dims, header.geometry) = domainOf(reader->GetOutput(), path);
    switch (imageIO->GetByteOrder()) {
      case itk::IOByteOrderEnum::BigEndian: header.byteOrder = ItkHeader::ByteOrder::Big; break;
      case itk::IOByteOrderEnum::LittleEndian: header.byteOrder = ItkHeader::ByteOrder::Little; break;
      default: header.byteOrder = ItkHeader::ByteOrder::Unknown; break;
    }
    return header;
  } catch (const itk::ExceptionObject& e) {
    throw ReadError("cannot read '" + path + "': " + oneLine(e));
  } catch (const std::bad_alloc&) {
    throw ReadError("cannot read '" + path + "': out of memory");
  }
}

}  // namespace detail

namespace {

/// The ITK image of a volume: same voxels, spacing, origin and direction.
template <class T>
typename itk::Image<T, 3>::Pointer toItkImage(const DenseImage<T>& volume) {
  using Image = itk::Image<T, 3>;
  auto image = Image::New();
  typename Image::RegionType region;
  typename Image::SizeType size;
  const Dims& dims = volume.dims();
  size[0] = dims.nx;
  size[1] = dims.ny;
  size[2] = dims.nz;
  region.SetSize(size);
  image->SetRegions(region);
  const ImageGeometry& g = volume.geometry();
  typename Image::SpacingType spacing;
  typename Image::PointType origin;
  typename Image::DirectionType direction;
  for (int a = 0; a < 3; ++a) {
    spacing[a] = g.spacing[a];
    origin[a] = g.origin[a];
    for (int b = 0; b < 3; ++b) direction(a, b) = g.direction[a][b];
  }
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->SetDirection(direction);
  image->Allocate();
  std::copy(volume.data().begin(), volume.data().end(), image->GetBufferPointer());
  return image;
}

template <class T>
void writeAs(const DenseImage<T>& volume, const std::string& path, bool compress) {
  using Image = itk::Image<T, 3>;
  const auto image = toItkImage(volume);
  auto writer = itk::ImageFileWriter<Image>::New();
  writer->SetFileName(path);
  writer->SetInput(image);
  writer->SetUseCompression(compress);
  writer->Update();
}

}  // namespace

void writeVolume(const AnyVolume& volume, const std::string& path) { writeVolume(volume, path, false); }

void writeVolume(const AnyVolume& volume, const std::string& path, bool compress) {
  registerFactories();
  try {
    std::visit([&](const auto& image) { writeAs(image, path, compress); }, volume);
  } catch (const itk::ExceptionObject& e) {
    throw std::runtime_error("cannot write '" + path + "': " + oneLine(e));
  }
}

namespace {

/// One 2D DICOM file per slice z, with the slice's position, the orientation and the spacing in
/// its header (ImagePositionPatient, ImageOrientationPatient, PixelSpacing, SliceThickness),
/// as a scanner writes a series.
template <class T>
void writeSeriesAs(const DenseImage<T>& volume, const std::string& directory) {
  using Image3 = itk::Image<T, 3>;
  using Image2 = itk::Image<T, 2>;
  const auto image = toItkImage(volume);
  const Dims& dims = volume.dims();
  const ImageGeometry& g = volume.geometry();
  auto dicom = itk::GDCMImageIO::New();
  dicom->KeepOriginalUIDOn();
  gdcm::UIDGenerator uids;
  const std::string study = uids.Generate(), series = uids.Generate();
  auto text = [](double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
  };
  std::vector<itk::MetaDataDictionary> dictionaries(dims.nz);
  std::vector<std::string> files;
  for (int z = 0; z < dims.nz; ++z) {
    itk::MetaDataDictionary& d = dictionaries[z];
    const auto p = g.toPhysical({0.0, 0.0, double(z)});
    auto put = [&](const char* tag, const std::string& value) {
      itk::EncapsulateMetaData<std::string>(d, tag, value);
    };
    put("0008|0060", "CT");
    put("0008|0016", "1.2.840.10008.5.1.4.1.1.2");  // CT Image Storage
    put("0020|000d", study);
    put("0020|000e", series);
    put("0008|0018", uids.Generate());
    put("0020|0013", std::to_string(z + 1));
    put("0020|0032", text(p[0]) + "\\" + text(p[1]) + "\\" + text(p[2]));
    put("0020|0037", text(g.direction[0][0]) + "\\" + text(g.direction[1][0]) + "\\" + text(g.direction[2][0]) +
                         "\\" + text(g.direction[0][1]) + "\\" + text(g.direction[1][1]) + "\\" +
                         text(g.direction[2][1]));
    put("0028|0030", text(g.spacing[1]) + "\\" + text(g.spacing[0]));  // row spacing \ column spacing
    put("0018|0050", text(g.spacing[2]));
    char name[32];
    std::snprintf(name, sizeof name, "slice%04d.dcm", z);
    files.push_back((fs::path(directory) / name).string());
  }
  auto writer = itk::ImageSeriesWriter<Image3, Image2>::New();
  writer->SetInput(image);
  writer->SetImageIO(dicom);
  writer->SetFileNames(files);
  std::vector<itk::MetaDataDictionary*> dictionaryPointers;
  for (auto& d : dictionaries) dictionaryPointers.push_back(&d);
  writer->SetMetaDataDictionaryArray(&dictionaryPointers);
  writer->Update();
}

}  // namespace

void writeDicomSeries(const AnyVolume& volume, const std::string& directory) {
  registerFactories();
  try {
    switch (scalarTypeOf(volume)) {
      case ScalarType::UInt8: return writeSeriesAs(std::get<DenseImage<std::uint8_t>>(volume), directory);
      case ScalarType::UInt16: return writeSeriesAs(std::get<DenseImage<std::uint16_t>>(volume), directory);
      default:
        throw std::runtime_error("cannot write a DICOM series of " + toString(scalarTypeOf(volume)) +
                                 " voxels (uint8 and uint16 only)");
    }
  } catch (const itk::ExceptionObject& e) {
    throw std::runtime_error("cannot write the DICOM series '" + directory + "': " + oneLine(e));
  }
}

}  // namespace surftrack::io
