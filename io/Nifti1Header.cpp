// The NIfTI-1 header (nifti1.h, "NIFTI-1 Data Format"): 348 bytes in the byte order of the
// writer (sizeof_hdr = 348 tells which), the voxels of a single-file image (magic "n+1") at
// byte vox_offset of the same file. Fields read here: sizeof_hdr (0), dim[8] (40), datatype
// (70), vox_offset (108), scl_slope (112), scl_inter (116), magic (344); the geometry (pixdim
// at 76, qform_code 252, sform_code 254, quatern_b..qoffset_z 256, srow_x..z 280) is ITK's to
// read, and only checked here: finite, and an sform ITK's reader can take (sformTrouble).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

#include "HeaderText.h"
#include "ReadVolume.h"
#include "VolumeHeader.h"

namespace surftrack::io {

namespace {

constexpr std::size_t kHeaderSize = 348;

/// NIfTI-1 datatype codes of the ten scalar types (nifti1.h, DT_*).
std::optional<ScalarType> niftiType(int datatype) {
  switch (datatype) {
    case 2: return ScalarType::UInt8;      // DT_UINT8
    case 256: return ScalarType::Int8;     // DT_INT8
    case 4: return ScalarType::Int16;      // DT_INT16
    case 512: return ScalarType::UInt16;   // DT_UINT16
    case 8: return ScalarType::Int32;      // DT_INT32
    case 768: return ScalarType::UInt32;   // DT_UINT32
    case 1024: return ScalarType::Int64;   // DT_INT64
    case 1280: return ScalarType::UInt64;  // DT_UINT64
    case 16: return ScalarType::Float32;   // DT_FLOAT32
    case 64: return ScalarType::Float64;   // DT_FLOAT64
    default: return std::nullopt;
  }
}

// ITK 5.2's NIfTI reader asks whether the sform is affine by inverting the 4x4 matrix
// M = [A t; 0 0 0 1] (A: the 3x3 part of srow_x..srow_z, t: their offsets) with a
// single-precision SVD (vnl_svd<float>, LINPACK's ssvdc), and uses the sform only if that SVD
// finds M well-conditioned in single precision. On some matrices singular to single precision
// the SVD produces a NaN and never returns, and neither does the reader: A singular (a zero
// row), or A regular beside an offset of 5e7 and an entry of 3e-39 (found by fuzz/). Measured
// on that SVD with random matrices of the magnitudes a header allows, each run under a time
// limit: every matrix that hung had a condition number above 1e8, and either A singular to
// single precision or nonzero magnitudes (with the 1 of the last row) more than 1e42 apart;
// none of 80,000 with a condition number up to 1e7 hung, nor any of 40,000 with A's condition
// number up to 1e7 and magnitudes within 1e24. Those two classes are accepted, the rest
// refused: ITK would not use such an sform anyway (it falls back to the qform). Real sforms are
// in the first class, or in the second when offsets are large beside the voxels (1 um voxels
// 5 cm from the origin: a condition number of 1e9, magnitudes 1e21 apart with the rounding
// residues of 1e-17 that rotations leave).
constexpr double kMaxSformCondition = 1e7;
constexpr double kMaxSformMagnitudeRatio = 1e24;

/// The Frobenius condition number ||M|| ||M^-1|| (at least the 2-norm one) of the sform s
/// (srow_x, srow_y, srow_z in float, as niftilib holds them), computed in double from
/// M^-1 = [A^-1, -A^-1 t; 0 1]: of the 4x4 M when `withOffsets`, else of A alone. Infinite or
/// NaN when A is singular.
double sformCondition(const float s[12], bool withOffsets) {
  auto a = [&](int r, int c) { return double(s[4 * r + c]); };
  const double cof[3][3] = {{a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1), a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2),
                             a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)},
                            {a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2), a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0),
                             a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)},
                            {a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0), a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1),
                             a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)}};  // A^-1 = cof / det
  const double det = a(0, 0) * cof[0][0] + a(0, 1) * cof[1][0] + a(0, 2) * cof[2][0];
  double norm = withOffsets ? 1 : 0, inverseNorm = norm;  // (the 1 of the last rows)
  for (int r = 0; r < 3; ++r) {
    double shift = 0;
    for (int c = 0; c < 4; ++c)
      if (c < 3 || withOffsets) norm += a(r, c) * a(r, c);
    for (int c = 0; c < 3; ++c) {
      const double inv = cof[r][c] / det;
      inverseNorm += inv * inv;
      shift -= inv * a(c, 3);
    }
    if (withOffsets) inverseNorm += shift * shift;
  }
  return std::sqrt(norm) * std::sqrt(inverseNorm);
}

/// Why ITK cannot read the sform s (above), or nothing.
std::optional<std::string> sformTrouble(const float s[12]) {
  char text[240];
  const double conditionA = sformCondition(s, false);
  if (!(conditionA <= kMaxSformCondition)) {
    std::snprintf(text, sizeof text,
                  "the sform (srow_x to srow_z) is singular to single precision (the condition number of its "
                  "3x3 part is %.2g, above 1e7), which ITK's NIfTI reader cannot take",
                  conditionA);
    return std::string(text);
  }
  const double condition = sformCondition(s, true);
  if (condition <= kMaxSformCondition) return std::nullopt;
  double big = 1, small = 1;
  for (int i = 0; i < 12; ++i)
    if (s[i] != 0) {
      big = std::max(big, double(std::abs(s[i])));
      small = std::min(small, double(std::abs(s[i])));
    }
  if (big <= kMaxSformMagnitudeRatio * small) return std::nullopt;
  std::snprintf(text, sizeof text,
                "the sform (srow_x to srow_z) is singular to single precision (condition number %.2g, above "
                "1e7) and mixes magnitudes %.2g and %.2g (more than 1e24 apart), which ITK's NIfTI reader "
                "cannot take",
                condition, big, small);
  return std::string(text);
}

/// The NIfTI-1 datatypes that are not one scalar of the ten types (nifti1.h; DT_BINARY, 1, is
/// not one niftilib reads from a NIfTI file), or nullptr.
const char* otherNiftiType(int datatype) {
  switch (datatype) {
    case 32: return "complex64";     // DT_COMPLEX64
    case 128: return "rgb24";        // DT_RGB24
    case 1536: return "float128";    // DT_FLOAT128
    case 1792: return "complex128";  // DT_COMPLEX128
    case 2048: return "complex256";  // DT_COMPLEX256
    case 2304: return "rgba32";      // DT_RGBA32
    default: return nullptr;
  }
}

class Reader {
 public:
  Reader(std::string_view head, bool swapped) : head_(head), swapped_(swapped) {}

  template <class T>
  T get(std::size_t at) const {
    unsigned char b[sizeof(T)];
    std::memcpy(b, head_.data() + at, sizeof(T));  // the callers check at + sizeof(T) <= head_.size()
    if (swapped_)
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

 private:
  std::string_view head_;
  bool swapped_;
};

}  // namespace

std::optional<DataLayout> parseNifti1Header(std::string_view head, std::uint64_t fileSize) {
  if (head.size() < kHeaderSize) {
    if (head.size() < fileSize) return std::nullopt;
    throw HeaderError("the file has " + std::to_string(fileSize) +
                      " bytes, fewer than a NIfTI-1 header (348 bytes) (truncated file?)");
  }
  DataLayout layout;
  const std::int32_t sizeofHdr = Reader(head, false).get<std::int32_t>(0);
  const std::int32_t swappedSize = Reader(head, true).get<std::int32_t>(0);
  const bool swapped = sizeofHdr != 348 && swappedSize == 348;
  if (sizeofHdr == 540 || swappedSize == 540) {
    // NIfTI-2 (nifti2.h) is ITK's to read; its geometry, doubles, is checked as NIfTI-1's below:
    // pixdim[0..3] at 104, qform_code at 344 and quatern_b..qoffset_z at 352, sform_code at 348
    // and srow_x..srow_z at 400.
    constexpr std::size_t kNifti2Size = 540;
    if (head.size() < kNifti2Size) {
      if (head.size() < fileSize) return std::nullopt;
      throw HeaderError("the file has " + std::to_string(fileSize) +
                        " bytes, fewer than a NIfTI-2 header (540 bytes) (truncated file?)");
    }
    const Reader r2(head, sizeofHdr != 540);
    // A NIfTI-2 header starts its magic at byte 4. ITK 5.2's niftilib reads NIfTI-1 only and
    // goes by the NIfTI-1 magic at byte 344: a 540-byte size with that magic is read as NIfTI-1
    // (and a NaN in its NIfTI-1 sform aborts the process), so it is refused here.
    const std::string_view magic2 = head.substr(4, 4);
    if (magic2 != std::string_view("n+2\0", 4) && magic2 != std::string_view("ni2\0", 4))
      throw HeaderError("malformed NIfTI header: its size (sizeof_hdr 540) is NIfTI-2's, but its magic is not "
                        "'n+2' or 'ni2'");
    auto requireFinite2 = [&](std::size_t at, int count, const char* field) {
      for (int i = 0; i < count; ++i)
        if (!(std::abs(r2.get<double>(at + 8 * std::size_t(i))) <= text::kMaxGeometryValue))
          throw HeaderError(std::string("malformed NIfTI-2 header: ") + field + " is not finite (or beyond 1e15)");
    };
    requireFinite2(104, 4, "pixdim");
    if (r2.get<std::int32_t>(344) > 0) requireFinite2(352, 6, "the qform (quatern_b to qoffset_z)");
    if (r2.get<std::int32_t>(348) > 0) {
      requireFinite2(400, 12, "the sform (srow_x to srow_z)");
      float sform[12];  // (niftilib's matrices are float, whatever the header stores)
      for (int i = 0; i < 12; ++i) sform[i] = float(r2.get<double>(400 + 8 * std::size_t(i)));
      if (const auto trouble = sformTrouble(sform)) throw HeaderError("malformed NIfTI-2 header: " + *trouble);
    }
    layout.decodeReason = "it is a NIfTI-2 file";
    return layout;
  }
  if (sizeofHdr != 348 && !swapped)
    throw HeaderError("not a NIfTI-1 file: its header size (sizeof_hdr) is " + std::to_string(sizeofHdr) +
                      ", not 348");
  const Reader r(head, swapped);
  // The geometry fields ITK turns into a matrix (and ITK's SVD aborts the process on a NaN or
  // an infinity): pixdim[0..3] always, quatern_b..qoffset_z when qform_code > 0, srow_x..srow_z
  // when sform_code > 0; finite and within +-1e15 (text::kMaxGeometryValue).
  auto requireFinite = [&](std::size_t at, int count, const char* field) {
    for (int i = 0; i < count; ++i)
      if (!(std::abs(r.get<float>(at + 4 * std::size_t(i))) <= text::kMaxGeometryValue))
        throw HeaderError(std::string("malformed NIfTI-1 header: ") + field + " is not finite (or beyond 1e15)");
  };
  requireFinite(76, 4, "pixdim");
  if (r.get<std::int16_t>(252) > 0) requireFinite(256, 6, "the qform (quatern_b to qoffset_z)");
  if (r.get<std::int16_t>(254) > 0) {
    requireFinite(280, 12, "the sform (srow_x to srow_z)");
    float sform[12];
    for (int i = 0; i < 12; ++i) sform[i] = r.get<float>(280 + 4 * std::size_t(i));
    if (const auto trouble = sformTrouble(sform)) throw HeaderError("malformed NIfTI-1 header: " + *trouble);
  }

  // Without the magic, niftilib (readVolume) reads the header as Analyze 7.5 and makes up
  // voxels it does not find: a .nii must say "n+1", or "ni1" for voxels in a separate .img file
  // (NIfTI-1, magic).
  const std::string_view magic = head.substr(344, 4);
  const bool separate = magic == std::string_view("ni1\0", 4);
  if (!separate && magic != std::string_view("n+1\0", 4))
    throw HeaderError("not a NIfTI-1 file: its magic is not 'n+1' (an Analyze 7.5 header in a .nii file?)");

  const int ndim = r.get<std::int16_t>(40);
  if (ndim < 1 || ndim > 7)
    throw HeaderError("malformed NIfTI-1 header: dim[0] is " + std::to_string(ndim) + ", not 1 to 7");
  std::vector<std::int64_t> sizes;
  for (int d = 1; d <= ndim; ++d) {
    const int n = r.get<std::int16_t>(40 + 2 * d);
    if (n < 1)
      throw HeaderError("malformed NIfTI-1 header: dim[" + std::to_string(d) + "] is " + std::to_string(n));
    sizes.push_back(n);
  }
  layout.dims = {int(sizes[0]), ndim > 1 ? int(sizes[1]) : 1, ndim > 2 ? int(sizes[2]) : 1};
  auto because = [&](const std::string& reason) {
    if (layout.decodeReason.empty()) layout.decodeReason = reason;
  };
  if (separate) because("its voxels are in a separate .img file (magic 'ni1')");
  for (int d = 4; d <= ndim; ++d)
    if (sizes[d - 1] != 1) because("it has more than one volume (dim[" + std::to_string(d) + "] > 1)");

  const int datatype = r.get<std::int16_t>(70);
  const auto type = niftiType(datatype);
  if (!type) {
    // Refused here rather than by ITK, whose niftilib prints its own line on stderr first.
    if (const char* name = otherNiftiType(datatype))
      throw HeaderError(std::string("its voxels are ") + name + " (NIfTI datatype " + std::to_string(datatype) +
                        "); surftrack reads one scalar per voxel, of type " + supportedTypesText());
    throw HeaderError("malformed NIfTI-1 header: datatype " + std::to_string(datatype) + " is not a NIfTI-1 datatype");
  }
  layout.type = *type;
  // niftilib's nifti_read_buffer sets non-finite float32 and float64 voxels to 0.
  layout.nonFiniteReadAsZero = *type == ScalarType::Float32 || *type == ScalarType::Float64;
  layout.bigEndian = swapped && sizeOf(*type) > 1;
  if (layout.bigEndian) because("its voxels are big-endian");

  // The NIfTI-1 header calls scl_slope = 0 unscaled, but ITK 5.2 reads it as a slope of 1 and
  // adds scl_inter (niftilib reads a non-finite slope or intercept as 0 first): only a slope of
  // 0 or 1 with no intercept leaves the voxels as stored. ITK rescales (and may change the voxel
  // type) otherwise.
  const auto finiteOrZero = [](float v) { return std::isfinite(v) ? v : 0.0f; };
  const float slope = finiteOrZero(r.get<float>(112)), inter = finiteOrZero(r.get<float>(116));
  if ((slope != 0 && slope != 1) || inter != 0) because("its voxels are scaled (scl_slope, scl_inter)");

  const float voxOffset = r.get<float>(108);
  if (!(voxOffset >= 0) || !std::isfinite(voxOffset))
    throw HeaderError("malformed NIfTI-1 header: vox_offset is not a byte offset");
  if (voxOffset < 352 || voxOffset != std::floor(voxOffset)) {
    because("its vox_offset is " + std::to_string(voxOffset) + " (a .nii file needs an integer >= 352)");
    return layout;
  }
  text::requireSizes(sizes, sizeOf(*type));
  if (separate) return layout;  // (the voxels are not in this file)
  if (double(voxOffset) > double(fileSize))
    throw HeaderError("the file has " + std::to_string(fileSize) + " bytes, but its header puts the voxels at byte " +
                      std::to_string(voxOffset) + " (truncated file?)");
  layout.offset = std::uint64_t(voxOffset);
  text::requireData(layout.offset, layout.dataBytes(), fileSize);
  return layout;
}

std::optional<NiftiForms> niftiForms(std::string_view head) {
  if (head.size() < kHeaderSize) return std::nullopt;
  std::int32_t sizeofHdr = 0;
  std::memcpy(&sizeofHdr, head.data(), 4);
  const Reader r(head, sizeofHdr != 348);
  if (r.get<std::int16_t>(252) <= 0 || r.get<std::int16_t>(254) <= 0) return std::nullopt;
  NiftiForms f;
  // The qform (nifti1.h, method 2): R from the quaternion (b, c, d), a = sqrt(1 - b^2 - c^2 -
  // d^2), times diag(dx, dy, qfac dz), then the offsets.
  double b = r.get<float>(256), c = r.get<float>(260), d = r.get<float>(264);
  double a = 1.0 - (b * b + c * c + d * d);
  if (a < 1e-7) {  // (as niftilib: a unit quaternion with a = 0, the rest normalised)
    const double n = std::sqrt(b * b + c * c + d * d);
    if (n > 0) b /= n, c /= n, d /= n;
    a = 0;
  } else {
    a = std::sqrt(a);
  }
  auto positive = [](double v) { return v > 0 ? v : 1.0; };
  const double qfac = r.get<float>(76) < 0 ? -1.0 : 1.0;
  const double dx = positive(r.get<float>(80)), dy = positive(r.get<float>(84)), dz = qfac * positive(r.get<float>(88));
  const double R[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                          {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                          {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
  const double scale[3] = {dx, dy, dz};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) f.qform[i][j] = R[i][j] * scale[j];
    f.qform[i][3] = r.get<float>(268 + 4 * std::size_t(i));
    for (int j = 0; j < 4; ++j) f.sform[i][j] = r.get<float>(280 + 16 * std::size_t(i) + 4 * std::size_t(j));
  }
  return f;
}

}  // namespace surftrack::io
