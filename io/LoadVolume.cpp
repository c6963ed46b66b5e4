// loadVolume and loadRawVolume (io/LoadVolume.h): find where a file keeps its voxels, then map
// them in place, or read them, or let ITK decode them.
//
// Who reads what. The strict parsers of io/VolumeHeader.h find the data file, the byte offset
// of the first voxel, the voxel type, the dimensions, the byte order and whether the voxels are
// stored raw — what ITK does not expose. ITK reads the same header for the geometry, through
// the same ImageIO and itk::ImageFileReader as readVolume (io/Internal.h, readItkHeader), and
// the mapping is made only if ITK agrees on the type, the dimensions and the byte order.
// Parsing the geometry here too would mean re-deriving, to 1e-9, what ITK does with each
// format — NIfTI's choice between qform and sform and its RAS-to-LPS flip, NRRD's spaces and
// space directions, MetaImage's TransformMatrix (stored by columns) — and every ITK release
// that changes one of them would make loadVolume and readVolume disagree. Asking ITK costs one
// header read (well under a millisecond) and makes the mapped and decoded paths give the same
// ImageGeometry by construction. The parsers still check the geometry fields' syntax, so that
// a malformed header is a clear error before ITK sees it, and they alone decide where the
// voxels are, so nothing is mapped that ITK would decode differently (scaled NIfTI voxels,
// NRRD line skips, MetaImage channels: all go to ITK).
//
// NaN in NIfTI. niftilib, which ITK's NIfTI reader is built on, replaces NaN and infinite
// float32/float64 voxels with 0 as it reads them. A view in place cannot, so a float .nii is
// scanned once when it is loaded (a sequential read of the mapping, no copy) and decoded by ITK
// if it holds any: float NIfTI volumes are mapped but not lazy.
//
// Alignment. The engine reads a view's voxels as a T*, which must be aligned to sizeof(T). A
// mapping starts on a page, so voxels at a file offset that is not a multiple of sizeof(T) (an
// .mha or .nrrd whose text header has an odd length, say) cannot be viewed in place; they are
// read into one aligned buffer instead (decodeReason says so). NIfTI-1's vox_offset (352) and
// detached data files (offset 0) are always aligned.
#include "LoadVolume.h"

#include <algorithm>
#include <cmath>
#include <bit>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>

#include "Deflate.h"
#include "HeaderText.h"
#include "Internal.h"
#include "MappedFile.h"
#include "VolumeHeader.h"

namespace surftrack::io {

namespace {

namespace fs = std::filesystem;

using Parse = std::optional<DataLayout> (*)(std::string_view, std::uint64_t);

struct Format {
  std::string_view suffix;
  std::string_view name;
  Parse parse;
};

constexpr Format kFormats[] = {{".mha", "mha", parseMetaImageHeader},
                               {".mhd", "mhd", parseMetaImageHeader},
                               {".nrrd", "nrrd", parseNrrdHeader},
                               {".nhdr", "nhdr", parseNrrdHeader},
                               {".nii", "nii", parseNifti1Header}};

/// Whether the file name of `path` ends with `suffix` (lower case), whatever its case.
bool hasSuffix(const std::string& path, std::string_view suffix) {
  std::string name = fs::path(path).filename().string();
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

const Format* formatOf(const std::string& path) {
  for (const Format& f : kFormats)
    if (hasSuffix(path, f.suffix)) return &f;
  return nullptr;
}

std::string quoted(const std::string& path) { return "'" + path + "'"; }

/// A data file named by a header: relative to the header's directory unless absolute.
std::string dataPath(const std::string& header, const std::string& dataFile) {
  const fs::path data = dataFile;
  return data.is_relative() ? (fs::path(header).parent_path() / data).string() : data.string();
}

/// The header of `file`: its first 4 KiB, then 8 times more until the parser finds its end.
DataLayout readLayout(const detail::OpenFile& file, Parse parse, const std::string& path) {
  for (std::size_t n = 4096;; n *= 8) {
    n = std::min(n, kMaxHeaderBytes);
    const std::string head = file.head(n);
    // A file that shrank since it was opened: parse what there is.
    const std::uint64_t size = head.size() < std::min<std::uint64_t>(n, file.size()) ? head.size() : file.size();
    try {
      if (auto layout = parse(head, size)) return *layout;
    } catch (const HeaderError& e) {
      throw ReadError("cannot read " + quoted(path) + ": " + e.what());
    }
    if (n >= kMaxHeaderBytes)
      throw ReadError("cannot read " + quoted(path) + ": its header does not end within its first " +
                      std::to_string(kMaxHeaderBytes >> 20) + " MiB");
  }
}

void swapBytes(void* data, std::size_t count, std::size_t size) {
  auto* p = static_cast<unsigned char*>(data);
  for (std::size_t i = 0; i < count; ++i, p += size) std::reverse(p, p + size);
}

/// The voxels [offset, offset + nx ny nz sizeof(type)) of `file`, mapped in place when they
/// are aligned and need no byte swap, read into one buffer (and swapped) otherwise.
LoadedVolume viewVoxels(const detail::OpenFile& file, std::uint64_t offset, ScalarType type, Dims dims,
                        const ImageGeometry& geometry, bool swap) {
  LoadedVolume out;
  const std::size_t size = sizeOf(type);
  out.dataBytes = dims.count() * size;
  if (swap) {
    out.decodeReason = "its voxels are big-endian (read and byte-swapped)";
  } else if (offset % size != 0) {
    out.decodeReason = "its voxels at byte " + std::to_string(offset) + " are not aligned to their " +
                       std::to_string(size) + "-byte " + toString(type) + " values (read into memory)";
  } else {
    std::string why;
    out.owner = file.map(offset, out.dataBytes, why);
    out.mapped = out.owner != nullptr;
    if (!out.mapped) out.decodeReason = why + " (read into memory)";
  }
  if (!out.mapped) {
    std::shared_ptr<void> buffer = file.read(offset, out.dataBytes);
    if (swap) swapBytes(buffer.get(), dims.count(), size);
    out.owner = std::move(buffer);
  }
  out.view = VolumeView{out.owner.get(), type, dims,
                        {1, std::ptrdiff_t(dims.nx), std::ptrdiff_t(dims.nx) * dims.ny}, geometry};
  return out;
}

/// ITK decodes the file once; the LoadedVolume views ITK's buffer.
LoadedVolume decodedByItk(const std::string& path, std::string format, std::string reason,
                          const ReadOptions& options = {}) {
  LoadedVolume out = detail::decodeWithItk(path, options);
  if (!format.empty()) out.format = std::move(format);
  if (reason.empty())
    reason = out.format == "nii.gz" ? "it is gzip-compressed" : "ITK decodes " + out.format + " files";
  out.decodeReason = std::move(reason) + " (decoded by ITK)";
  return out;
}

/// Whether a dense float or double view holds a NaN or an infinity (all exponent bits set).
bool hasNonFinite(const VolumeView& v) {
  const auto* p = static_cast<const unsigned char*>(v.data);
  const std::size_t n = v.dims.count();
  bool found = false;
  if (v.type == ScalarType::Float32) {
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t bits;
      std::memcpy(&bits, p + 4 * i, 4);
      found |= (bits & 0x7f800000u) == 0x7f800000u;
    }
  } else if (v.type == ScalarType::Float64) {
    for (std::size_t i = 0; i < n; ++i) {
      std::uint64_t bits;
      std::memcpy(&bits, p + 8 * i, 8);
      found |= (bits & 0x7ff0000000000000ull) == 0x7ff0000000000000ull;
    }
  }
  return found;
}

std::string dimsText(Dims d) {
  return std::to_string(d.nx) + "x" + std::to_string(d.ny) + "x" + std::to_string(d.nz);
}

/// What ITK reads differently from the parser's layout (empty if nothing): the voxels are then
/// ITK's to decode.
std::string disagreement(const detail::ItkHeader& itk, const DataLayout& layout) {
  if (itk.type != layout.type) return "ITK reads its voxels as " + toString(itk.type) + ", not " + toString(layout.type);
  if (itk.dims != layout.dims)
    return "ITK reads it as " + dimsText(itk.dims) + " voxels, not " + dimsText(layout.dims);
  if (sizeOf(layout.type) > 1 && itk.byteOrder == detail::ItkHeader::ByteOrder::Big)
    return "ITK reads its voxels as big-endian";
  return {};
}

/// A gzip'd single-file NIfTI-1 image: its header inflated and parsed first (the strict parser
/// of a .nii, so that a malformed header is an error before ITK sees it), its geometry read by
/// ITK as for a mapped file, then the whole file inflated once, by libdeflate, into the buffer
/// the view reads (Deflate.h): no second copy. What the parser or ITK would decode otherwise
/// (scaled or big-endian voxels, NIfTI-2, non-finite floats, ...) goes to ITK, as before.
LoadedVolume loadGzippedNifti(const std::string& path) {
  const std::string name = "nii.gz";
  const detail::OpenFile file(path, "cannot read " + quoted(path));
  if (file.size() == 0) throw ReadError("cannot read " + quoted(path) + ": the file is empty");
  if (!detail::isGzip(file))  // (ITK would read it as a .nii, unchecked: niftilib's gzread reads plain files too)
    throw ReadError("cannot read " + quoted(path) + ": it is not gzip-compressed, as a .nii.gz file must be");
  std::string head(4096, '\0');
  head.resize(detail::inflateGzipPrefix(file, reinterpret_cast<unsigned char*>(head.data()), head.size(), false));
  DataLayout layout;
  try {
    // The inflated size is known here only if it is short; inflateGzip checks it otherwise.
    const std::optional<DataLayout> parsed = parseNifti1Header(head, head.size() < 4096 ? head.size() : UINT64_MAX);
    if (!parsed)
      throw HeaderError("its compressed data ends inside the NIfTI-1 header (truncated file?)");
    layout = *parsed;
    if (layout.decodeReason.empty()) text::requireStored(layout.offset + layout.dataBytes(), 1032, file.size());
  } catch (const HeaderError& e) {
    throw ReadError("cannot read " + quoted(path) + ": " + e.what());
  }
  if (!layout.decodeReason.empty()) return decodedByItk(path, name, layout.decodeReason);
  if (std::endian::native != std::endian::little && sizeOf(layout.type) > 1)
    return decodedByItk(path, name, "its voxels are little-endian, this machine is not");
  // Inflated before ITK reads the header, so that damage is reported as such.
  const detail::Inflated inflated = detail::inflateGzip(file, layout.offset + layout.dataBytes(), layout.offset);
  const detail::ItkHeader itk = detail::readItkHeader(path);
  if (std::string why = disagreement(itk, layout); !why.empty()) return decodedByItk(path, name, why);
  LoadedVolume out;
  out.format = name;
  out.dataBytes = layout.dataBytes();
  out.decodeReason = "it is gzip-compressed (inflated into memory)";
  out.owner = std::shared_ptr<const void>(inflated.owner, inflated.data + layout.offset);
  const Dims dims = layout.dims;
  out.view = VolumeView{out.owner.get(), layout.type, dims,
                        {1, std::ptrdiff_t(dims.nx), std::ptrdiff_t(dims.nx) * dims.ny}, itk.geometry};
  if (layout.nonFiniteReadAsZero && hasNonFinite(out.view))
    return decodedByItk(path, name, "its float voxels include NaN or infinite values, which NIfTI readers read as 0");
  return out;
}

}  // namespace

std::uintmax_t LoadedVolume::residentBytes() const {
  return mapped ? detail::residentBytes(view.data, dataBytes) : dataBytes;
}

void LoadedVolume::advise(Access access) const {
  if (mapped) detail::adviseAccess(view.data, dataBytes, access == Access::Sparse);
}

namespace {

double largestDifference(const std::array<std::array<double, 4>, 3>& a, const std::array<std::array<double, 4>, 3>& b) {
  double d = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) d = std::max(d, std::abs(a[i][j] - b[i][j]));
  return d;
}

/// A NIfTI-1 file whose qform and sform disagree: the line that says which one the geometry
/// follows (ITK's choice, found by comparing ITK's geometry with both), since nibabel's
/// `affine` (the sform) and other readers would place the volume elsewhere.
std::optional<std::string> formsWarning(const std::string& path, const ImageGeometry& g) {
  std::string head;
  try {
    const detail::OpenFile file(path, "cannot read " + quoted(path));
    if (hasSuffix(path, ".nii.gz")) {
      head.assign(348, '\0');
      head.resize(detail::inflateGzipPrefix(file, reinterpret_cast<unsigned char*>(head.data()), head.size(), false));
    } else {
      head = file.head(348);
    }
  } catch (const std::exception&) {
    return std::nullopt;  // (the volume was read: a second look at its header is only a courtesy)
  }
  const std::optional<NiftiForms> forms = niftiForms(head);
  if (!forms) return std::nullopt;
  double size = 1;
  for (const auto& row : forms->sform)
    for (double v : row) size = std::max(size, std::abs(v));
  if (largestDifference(forms->qform, forms->sform) <= 1e-4 * size) return std::nullopt;
  // ITK's geometry as a RAS affine: RAS = diag(-1, -1, 1) LPS.
  std::array<std::array<double, 4>, 3> itk{};
  for (int i = 0; i < 3; ++i) {
    const double sign = i < 2 ? -1.0 : 1.0;
    for (int j = 0; j < 3; ++j) itk[i][j] = sign * g.direction[i][j] * g.spacing[j];
    itk[i][3] = sign * g.origin[i];
  }
  const bool qform = largestDifference(itk, forms->qform) <= largestDifference(itk, forms->sform);
  auto at = [](const std::array<std::array<double, 4>, 3>& m) {
    std::ostringstream s;
    s.precision(6);
    s << "(" << m[0][3] << ", " << m[1][3] << ", " << m[2][3] << ")";
    return s.str();
  };
  return quoted(path) + ": its qform and sform disagree (voxel (0,0,0) at RAS " + at(forms->qform) +
         " by the qform, " + at(forms->sform) + " by the sform); the geometry follows the " +
         (qform ? "qform" : "sform") + ", as ITK reads it (nibabel's affine is the sform)";
}

}  // namespace

static LoadedVolume loadFile(const std::string& path, const ReadOptions& options);

LoadedVolume loadVolume(const std::string& path, const ReadOptions& options) {
  LoadedVolume out = loadFile(path, options);
  if (hasSuffix(path, ".nii") || hasSuffix(path, ".nii.gz"))
    if (auto w = formsWarning(path, out.view.geometry)) out.warnings.push_back(std::move(*w));
  return out;
}

static LoadedVolume loadFile(const std::string& path, const ReadOptions& options) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw ReadError("cannot read " + quoted(path) + ": no such file");
  const Format* format = formatOf(path);
  if (!format && !hasSuffix(path, ".nii.gz")) return decodedByItk(path, "", "", options);
  // (The formats read here, mapped or inflated or decoded, hold one channel.)
  detail::requireChannel(path, options, 1, "");
  if (hasSuffix(path, ".nii.gz") && !fs::is_directory(path, ec)) {
    try {
      return loadGzippedNifti(path);
    } catch (const std::bad_alloc&) {
      throw ReadError("cannot read " + quoted(path) + ": out of memory");
    }
  }
  if (!format || fs::is_directory(path, ec)) return decodedByItk(path, "", "");
  try {
    const detail::OpenFile file(path, "cannot read " + quoted(path));
    if (file.size() == 0) throw ReadError("cannot read " + quoted(path) + ": the file is empty");
    const DataLayout layout = readLayout(file, format->parse, path);
    const std::string name(format->name);
    if (!layout.decodeReason.empty()) {
      // Before ITK sees a detached header: its one data file is a regular file (not a FIFO
      // that would block, not a device) holding enough encoded bytes for the voxels.
      std::optional<detail::OpenFile> separate;
      if (!layout.dataFile.empty() && !layout.severalDataFiles) {
        const std::string data = dataPath(path, layout.dataFile);
        separate.emplace(data, "cannot read " + quoted(path) + ": its data file " + quoted(data));
        try {  // (the whole file: a byte skip may count decoded bytes)
          text::requireStored(layout.dataBytes(), layout.maxExpansion, separate->size());
        } catch (const HeaderError& e) {
          throw ReadError(separate->context() + ": " + e.what());
        }
      }
      // A list of files: each a regular file with its part of the voxels (MetaIO reads what it
      // cannot open into its buffer, and may crash).
      if (!layout.listedFiles.empty()) {
        const std::uint64_t part = layout.listedPartBytes;
        for (const std::string& listed : layout.listedFiles) {
          const std::string data = dataPath(path, listed);
          const detail::OpenFile each(data, "cannot read " + quoted(path) + ": its listed data file " + quoted(data));
          if (each.size() < part)
            throw ReadError(each.context() + " has " + std::to_string(each.size()) + " bytes, fewer than the " +
                            std::to_string(part) + " its part of the voxels needs (truncated file?)");
        }
      }
      // A MetaImage's compressed voxels: inflated once here, so that a corrupt stream is an
      // error (ITK 5.2's MetaIO reports none, and may never return), where MetaIO reads it —
      // CompressedDataSize bytes from the voxels' offset, or without it the whole file.
      if (layout.deflated && (separate || layout.dataFile.empty())) {
        const detail::OpenFile& data = separate ? *separate : file;
        const std::uint64_t bytes = layout.dataBytes();
        std::uint64_t start = 0, length = data.size();
        if (layout.deflatedBytes > 0) {
          start = layout.fromEnd ? (data.size() >= bytes ? data.size() - bytes : 0) : layout.offset;
          length = layout.deflatedBytes;
        }
        detail::requireDeflated(data, start, length, bytes);
      }
      return decodedByItk(path, name, layout.decodeReason);
    }
    if (std::endian::native != std::endian::little && sizeOf(layout.type) > 1)
      return decodedByItk(path, name, "its voxels are little-endian, this machine is not");

    // The file that holds the voxels, and their offset in it.
    std::optional<detail::OpenFile> separate;
    if (!layout.dataFile.empty()) {
      const std::string data = dataPath(path, layout.dataFile);
      separate.emplace(data, "cannot read " + quoted(path) + ": its data file " + quoted(data));
    }
    const detail::OpenFile& data = separate ? *separate : file;
    const std::uint64_t bytes = layout.dataBytes();
    std::uint64_t offset = layout.offset;
    if (separate) {  // (the parsers checked the size of the header's own file)
      if (layout.fromEnd) offset = data.size() >= bytes ? data.size() - bytes : 0;
      if (offset > data.size() || data.size() - offset < bytes)
        throw ReadError(data.context() + " has " + std::to_string(data.size()) + " bytes, but the header announces " +
                        std::to_string(bytes) + " bytes of voxel data at byte " + std::to_string(offset) +
                        " (truncated file?)");
    }

    // The geometry, as readVolume reads it; map only if ITK sees the same voxels.
    const detail::ItkHeader itk = detail::readItkHeader(path);
    if (std::string why = disagreement(itk, layout); !why.empty()) return decodedByItk(path, name, why);

    LoadedVolume out = viewVoxels(data, offset, layout.type, layout.dims, itk.geometry, /*swap=*/false);
    out.format = name;
    // NIfTI floats: readVolume reads NaN and infinity as 0 (niftilib). One pass over the
    // voxels, without a copy, tells whether the file has any; if so, ITK decodes it as readVolume.
    if (layout.nonFiniteReadAsZero && hasNonFinite(out.view))
      return decodedByItk(path, name, "its float voxels include NaN or infinite values, which NIfTI readers read as 0");
    return out;
  } catch (const std::bad_alloc&) {
    throw ReadError("cannot read " + quoted(path) + ": out of memory");
  }
}

LoadedVolume loadRawVolume(const std::string& path, const RawLayout& layout) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw ReadError("cannot read " + quoted(path) + ": no such file");
  try {
    const detail::OpenFile file(path, "cannot read " + quoted(path));
    detail::requireRawLayout(path, layout, file.size());
    const bool swap = sizeOf(layout.type) > 1 && layout.bigEndian != (std::endian::native == std::endian::big);
    LoadedVolume out = viewVoxels(file, layout.headerBytes, layout.type, layout.dims, layout.geometry, swap);
    out.format = "raw";
    return out;
  } catch (const std::bad_alloc&) {
    throw ReadError("cannot read " + quoted(path) + ": out of memory");
  }
}

}  // namespace surftrack::io
