// The NRRD header, after the NRRD file format specification (teem, "NRRD0001" to "NRRD0005"):
// the magic line, then "field: description" lines, "key:=value" pairs and "#" comments, ended by
// an empty line, after which the voxels follow (.nrrd) — or the voxels are in the file named by
// "data file:" (.nhdr, where the header may end at the end of the file). Lines end with "\n",
// "\r\n" or "\r"; a last line without an end is not part of the header, as teem reads it.
// Field names are matched without case and with or without their spaces ("byte skip",
// "byteskip"); a field may appear once; an unknown field is an error, as in teem.
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "HeaderText.h"
#include "VolumeHeader.h"

namespace surftrack::io {

namespace {

using text::quote;
using text::trim;

struct Name {
  std::string_view name;
  int value;
};

constexpr int kBlock = -1;  // the "block" type (opaque blocks of bytes)

// The NRRD type names and their synonyms (the specification's "type" field).
constexpr Name kTypes[] = {
    {"signed char", int(ScalarType::Int8)},   {"int8", int(ScalarType::Int8)},
    {"int8_t", int(ScalarType::Int8)},        {"uchar", int(ScalarType::UInt8)},
    {"unsigned char", int(ScalarType::UInt8)}, {"uint8", int(ScalarType::UInt8)},
    {"uint8_t", int(ScalarType::UInt8)},      {"short", int(ScalarType::Int16)},
    {"short int", int(ScalarType::Int16)},    {"signed short", int(ScalarType::Int16)},
    {"signed short int", int(ScalarType::Int16)}, {"int16", int(ScalarType::Int16)},
    {"int16_t", int(ScalarType::Int16)},      {"ushort", int(ScalarType::UInt16)},
    {"unsigned short", int(ScalarType::UInt16)}, {"unsigned short int", int(ScalarType::UInt16)},
    {"uint16", int(ScalarType::UInt16)},      {"uint16_t", int(ScalarType::UInt16)},
    {"int", int(ScalarType::Int32)},          {"signed int", int(ScalarType::Int32)},
    {"int32", int(ScalarType::Int32)},        {"int32_t", int(ScalarType::Int32)},
    {"uint", int(ScalarType::UInt32)},        {"unsigned int", int(ScalarType::UInt32)},
    {"uint32", int(ScalarType::UInt32)},      {"uint32_t", int(ScalarType::UInt32)},
    {"longlong", int(ScalarType::Int64)},     {"long long", int(ScalarType::Int64)},
    {"long long int", int(ScalarType::Int64)}, {"signed long long", int(ScalarType::Int64)},
    {"signed long long int", int(ScalarType::Int64)}, {"int64", int(ScalarType::Int64)},
    {"int64_t", int(ScalarType::Int64)},      {"ulonglong", int(ScalarType::UInt64)},
    {"unsigned long long", int(ScalarType::UInt64)}, {"unsigned long long int", int(ScalarType::UInt64)},
    {"uint64", int(ScalarType::UInt64)},      {"uint64_t", int(ScalarType::UInt64)},
    {"float", int(ScalarType::Float32)},      {"double", int(ScalarType::Float64)},
    {"block", kBlock}};

enum Encoding { kRaw, kText, kHex, kGzip, kBzip2, kZrl };
constexpr Name kEncodings[] = {{"raw", kRaw},    {"txt", kText},   {"text", kText},
                               {"ascii", kText}, {"hex", kHex},    {"gz", kGzip},
                               {"gzip", kGzip},  {"bz2", kBzip2},  {"bzip2", kBzip2},
                               {"zrl", kZrl}};
constexpr std::string_view kEncodingNames[] = {"raw", "text", "hex", "gzip", "bzip2", "zrl"};

// The "space" field's names, with the dimension of each space.
constexpr Name kSpaces[] = {
    {"right-anterior-superior", 3}, {"ras", 3}, {"left-anterior-superior", 3}, {"las", 3},
    {"left-posterior-superior", 3}, {"lps", 3}, {"right-anterior-superior-time", 4}, {"rast", 4},
    {"left-anterior-superior-time", 4}, {"last", 4}, {"left-posterior-superior-time", 4},
    {"lpst", 4}, {"scanner-xyz", 3}, {"scanner-xyz-time", 4}, {"scanner-xyzt", 4},
    {"3d-right-handed", 3}, {"3dr", 3}, {"3d-left-handed", 3}, {"3dl", 3},
    {"3d-right-handed-time", 4}, {"3drt", 4}, {"3d-left-handed-time", 4}, {"3dlt", 4}};

std::optional<int> lookup(std::string_view s, const auto& table) {
  for (const Name& n : table)
    if (text::equalsIgnoringCase(s, n.name)) return n.value;
  return std::nullopt;
}

enum Field {
  kContent, kNumber, kType, kBlockSize, kDimension, kSpace, kSpaceDimension, kSizes, kSpacings,
  kThicknesses, kAxisMins, kAxisMaxs, kSpaceDirections, kCenters, kKinds, kLabels, kUnits, kMin,
  kMax, kOldMin, kOldMax, kEndian, kEncoding, kLineSkip, kByteSkip, kSampleUnits, kSpaceUnits,
  kSpaceOrigin, kMeasurementFrame, kDataFile, kFieldCount
};

// Field names without their spaces, lower case.
constexpr Name kFields[] = {
    {"content", kContent},         {"number", kNumber},
    {"type", kType},               {"blocksize", kBlockSize},
    {"dimension", kDimension},     {"space", kSpace},
    {"spacedimension", kSpaceDimension}, {"sizes", kSizes},
    {"spacings", kSpacings},       {"thicknesses", kThicknesses},
    {"axismins", kAxisMins},       {"axismaxs", kAxisMaxs},
    {"spacedirections", kSpaceDirections}, {"centers", kCenters},
    {"centerings", kCenters},      {"kinds", kKinds},
    {"labels", kLabels},           {"units", kUnits},
    {"min", kMin},                 {"max", kMax},
    {"oldmin", kOldMin},           {"oldmax", kOldMax},
    {"endian", kEndian},           {"encoding", kEncoding},
    {"lineskip", kLineSkip},       {"byteskip", kByteSkip},
    {"sampleunits", kSampleUnits}, {"spaceunits", kSpaceUnits},
    {"spaceorigin", kSpaceOrigin}, {"measurementframe", kMeasurementFrame},
    {"datafile", kDataFile}};

std::optional<int> fieldOf(std::string_view name) {
  std::string squeezed;
  for (char c : name)
    if (c != ' ') squeezed += text::lower(c);
  return lookup(squeezed, kFields);
}

class Parser {
 public:
  Parser(std::string_view head, std::uint64_t fileSize) : head_(head), fileSize_(fileSize) {}

  std::optional<DataLayout> parse() {
    const bool whole = head_.size() >= fileSize_;
    std::size_t pos = 0;
    std::size_t lineNo = 0;
    for (;;) {
      // One line: up to "\n", "\r\n" or "\r".
      std::size_t end = pos;
      while (end < head_.size() && head_[end] != '\n' && head_[end] != '\r') ++end;
      if (end >= head_.size()) {
        if (!whole) return std::nullopt;
        // The end of the file: a last line without its end is not part of the header.
        if (lineNo == 0)
          throw HeaderError(head_.substr(0, 4) == "NRRD" ? "the NRRD header ends within its first line (truncated file?)"
                                                          : "not a NRRD file: it does not begin with a NRRD000x line");
        return finish(head_.size(), /*blankLine=*/false);
      }
      std::size_t next = end + 1;
      if (head_[end] == '\r') {
        if (next >= head_.size() && !whole) return std::nullopt;  // "\r" or "\r\n"?
        if (next < head_.size() && head_[next] == '\n') ++next;
      }
      line_ = head_.substr(pos, end - pos);
      ++lineNo;
      lineNo_ = lineNo;
      for (char c : line_)
        if (text::isControl(c)) fail("has a control character (byte " + std::to_string(static_cast<unsigned char>(c)) + ")");
      if (lineNo == 1) {
        if (line_.size() != 8 || line_.substr(0, 7) != "NRRD000" || line_[7] < '1' || line_[7] > '5')
          throw HeaderError("not a NRRD file: it does not begin with a NRRD0001 to NRRD0005 line");
      } else if (line_.empty()) {
        return finish(next, /*blankLine=*/true);
      } else if (line_[0] != '#') {
        field();
        if (dataFiles_ == kList) {
          if (!listedNames(next, whole)) return std::nullopt;
          return finish(next, /*blankLine=*/false);
        }
      }
      pos = next;
    }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw HeaderError("malformed NRRD header: line " + std::to_string(lineNo_) + " " + quote(line_) +
                      " " + what);
  }

  void field() {
    const std::size_t colon = line_.find(": ");
    std::optional<int> f;
    if (colon != std::string_view::npos) f = fieldOf(line_.substr(0, colon));
    if (!f) {
      if (line_.find(":=") != std::string_view::npos) return;  // a key/value pair
      fail(colon == std::string_view::npos ? "is neither 'field: description' nor 'key:=value'"
                                           : "is not a NRRD field");
    }
    if (seen_[*f]) fail("repeats a field");
    seen_[*f] = true;
    std::size_t v = colon + 2;
    while (v < line_.size() && (line_[v] == ' ' || line_[v] == '\t')) ++v;
    value_ = trim(line_.substr(v));
    switch (*f) {
      case kType: {
        const auto t = lookup(value_, kTypes);
        if (!t) fail("names no NRRD type");
        type_ = *t;
        break;
      }
      case kDimension: {
        const auto n = text::toInteger(value_);
        if (!n || *n < 1 || *n > 16) fail("is not a dimension from 1 to 16");
        dimension_ = int(*n);
        break;
      }
      case kSizes: {
        const auto w = perAxisWords();
        sizes_.clear();
        for (std::string_view s : w) {
          const auto n = text::toInteger(s);
          if (!n || *n < 1) fail("has " + quote(s) + " where a positive size is expected");
          sizes_.push_back(*n);
        }
        break;
      }
      case kSpacings: case kThicknesses: case kAxisMins: case kAxisMaxs:
        for (std::string_view s : perAxisWords())
          if (!text::equalsIgnoringCase(s, "nan") && !text::toGeometryNumber(s))
            fail("has " + quote(s) + " where a number (of magnitude at most 1e15) is expected");
        break;
      case kCenters: case kKinds:
        perAxisWords();
        break;
      case kEncoding: {
        const auto e = lookup(value_, kEncodings);
        if (!e) fail("names no NRRD encoding");
        encoding_ = *e;
        break;
      }
      case kEndian:
        if (text::equalsIgnoringCase(value_, "little")) bigEndian_ = false;
        else if (text::equalsIgnoringCase(value_, "big")) bigEndian_ = true;
        else fail("is neither little nor big");
        break;
      case kByteSkip: {
        const auto n = text::toInteger(value_);
        if (!n || *n < -1) fail("is neither -1 nor a byte count");
        byteSkip_ = *n;
        break;
      }
      case kLineSkip: {
        const auto n = text::toInteger(value_);
        if (!n || *n < 0) fail("is not a line count");
        lineSkip_ = *n;
        break;
      }
      case kDataFile:
        if (value_.empty()) fail("names no data file");
        dataFile_ = value_;
        if (value_.substr(0, 4) == "LIST") {
          dataFiles_ = kList;  // the file names follow, one a line: the header's fields end here
        } else if (isFilePattern(value_)) {
          requireFilePattern();
          dataFiles_ = kNumbered;
        }
        break;
      case kSpace: {
        if (seen_[kSpaceDimension]) fail("comes after 'space dimension'");
        const auto d = lookup(value_, kSpaces);
        if (!d) fail("names no NRRD space");
        spaceDim_ = *d;
        break;
      }
      case kSpaceDimension: {
        if (seen_[kSpace]) fail("comes after 'space'");
        const auto n = text::toInteger(value_);
        if (!n || *n < 1 || *n > 8) fail("is not a space dimension from 1 to 8");
        spaceDim_ = int(*n);
        break;
      }
      case kSpaceDirections: {
        if (dimension_ == 0) fail("comes before 'dimension'");
        std::string_view rest = value_;
        for (int a = 0; a < dimension_; ++a) vector(rest, /*noneAllowed=*/true);
        if (!trim(rest).empty()) fail("has more than " + std::to_string(dimension_) + " directions");
        break;
      }
      case kSpaceOrigin: {
        std::string_view rest = value_;
        vector(rest, /*noneAllowed=*/false);
        if (!trim(rest).empty()) fail("has more than one vector");
        break;
      }
      default:
        break;  // content, labels, units, min, max, ...: no bearing on where the voxels are
    }
  }

  /// "data file: LIST [<subdim>]": the names of the data files follow, one a line, up to an
  /// empty line or the end of the file, as teem reads them (_nrrdReadNrrdParse_data_file); one
  /// file per <subdim>-dimensional block (dimension - 1 by default). A name with a control byte
  /// made teem's messages read past their buffer (found by fuzz/); a count other than the
  /// blocks' is teem's error. False if the head ends before the list and the file is longer;
  /// the names go to listed_.
  bool listedNames(std::size_t pos, bool whole) {
    const std::string_view after = trim(value_.substr(4));
    int subdim = dimension_ - 1;
    if (!after.empty()) {
      const auto n = text::toInteger(after);
      if (!n || *n < 1 || *n > dimension_) fail("has " + quote(after) + " where a data file dimension in [1, dimension] is expected");
      subdim = int(*n);
    }
    if (!seen_[kSizes]) fail("comes before 'sizes'");
    std::int64_t files = 1;  // (at most one a line of the header's 1 MiB)
    for (int a = subdim; a < dimension_; ++a) {
      if (sizes_[std::size_t(a)] > std::int64_t(kMaxHeaderBytes) / files) fail("needs more listed files than its header can hold");
      files *= sizes_[std::size_t(a)];
    }
    listed_.clear();
    for (;;) {
      std::size_t end = pos;
      while (end < head_.size() && head_[end] != '\n' && head_[end] != '\r') ++end;
      if (end >= head_.size() && !whole) return false;
      const std::string_view name = head_.substr(pos, end - pos);
      if (name.empty()) break;
      for (char c : name)
        if (text::isControl(c)) fail("lists a data file name with a control character");
      listed_.emplace_back(name);
      if (end >= head_.size()) break;
      pos = end + 1;
      if (head_[end] == '\r' && pos < head_.size() && head_[pos] == '\n') ++pos;
    }
    if (std::int64_t(listed_.size()) != files)
      fail("lists " + std::to_string(listed_.size()) + " data files, and the image needs " + std::to_string(files));
    return true;
  }

  /// teem's test for numbered data files: the first '%' that is not "%%" is "%<digits>d"
  /// (any other name, '%' or not, is one file).
  static bool isFilePattern(std::string_view s) {
    std::size_t i = 0;
    for (;;) {
      i = s.find('%', i);
      if (i == std::string_view::npos || i + 1 >= s.size()) return false;
      if (s[i + 1] != '%') break;
      i += 2;
    }
    ++i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    return i < s.size() && s[i] == 'd';
  }

  /// "data file: <format> <min> <max> <step> [<subdim>]": teem passes <format> to sprintf with
  /// one int, so it may hold no other conversion.
  void requireFilePattern() {
    if (dimension_ == 0) fail("comes before 'dimension'");
    const auto w = text::words(value_);
    if (w.size() < 4 || w.size() > 5) fail("needs '<format> <min> <max> <step> [<subdim>]'");
    if (!text::isOneIntFormat(w[0])) fail("has a file name format with other than one integer conversion (%d)");
    std::int64_t n[4] = {0, 0, 0, 1};
    for (std::size_t i = 1; i < w.size(); ++i) {
      const auto x = text::toInteger(w[i]);
      if (!x || *x < -(std::int64_t(1) << 31) + 1 || *x > (std::int64_t(1) << 31) - 1)
        fail("has " + quote(w[i]) + " where an integer is expected");
      n[i - 1] = *x;
    }
    if (n[2] == 0) fail("numbers its files with a step of 0");
    if ((n[1] - n[0]) * n[2] < 0) fail("numbers its files from " + std::to_string(n[0]) + " away from " + std::to_string(n[1]));
    if (w.size() == 5 && (n[3] < 1 || n[3] > dimension_)) fail("has a data file dimension outside [1, dimension]");
  }

  std::vector<std::string_view> perAxisWords() {
    if (dimension_ == 0) fail("comes before 'dimension'");
    auto w = text::words(value_);
    if (w.size() != std::size_t(dimension_)) fail("needs " + std::to_string(dimension_) + " values");
    return w;
  }

  /// One space vector "(x,y,z)" (as many components as the space dimension) or "none".
  void vector(std::string_view& rest, bool noneAllowed) {
    if (spaceDim_ == 0) fail("comes before 'space' or 'space dimension'");
    while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
    if (noneAllowed && rest.substr(0, 4) == "none" && (rest.size() == 4 || rest[4] == ' ' || rest[4] == '\t')) {
      rest.remove_prefix(4);
      return;
    }
    if (rest.empty() || rest.front() != '(') fail("needs a vector '(x,y,z)'");
    const std::size_t close = rest.find(')');
    if (close == std::string_view::npos) fail("has a vector without ')'");
    std::string_view inside = rest.substr(1, close - 1);
    rest.remove_prefix(close + 1);
    int count = 0;
    bool anyNan = false, allNan = true;
    for (;;) {
      const std::size_t comma = inside.find(',');
      const std::string_view c = trim(inside.substr(0, comma));
      const bool nan = text::equalsIgnoringCase(c, "nan");
      if (!nan && !text::toGeometryNumber(c))
        fail("has " + quote(c) + " where a vector component (of magnitude at most 1e15) is expected");
      anyNan |= nan;
      allNan &= nan;
      ++count;
      if (comma == std::string_view::npos) break;
      inside.remove_prefix(comma + 1);
    }
    if (count != spaceDim_) fail("needs vectors of " + std::to_string(spaceDim_) + " components");
    if (anyNan && !allNan) fail("has a vector with some but not all components nan");
  }

  /// The header ends at `dataStart` (after its empty line, or at the end of the file).
  DataLayout finish(std::size_t dataStart, bool blankLine) {
    for (const auto& [field, name] : {std::pair{kDimension, "dimension"}, std::pair{kType, "type"},
                                      std::pair{kSizes, "sizes"}, std::pair{kEncoding, "encoding"}})
      if (!seen_[field]) throw HeaderError(std::string("malformed NRRD header: no '") + name + "' field");
    DataLayout layout;
    auto because = [&](const std::string& reason) {
      if (layout.decodeReason.empty()) layout.decodeReason = reason;
    };
    std::size_t bytesPerVoxel = 1;
    if (type_ == kBlock) {
      because("its type is 'block'");
    } else {
      layout.type = ScalarType(type_);
      bytesPerVoxel = sizeOf(layout.type);
    }
    text::requireSizes(sizes_, bytesPerVoxel);
    layout.dims = {int(sizes_[0]), sizes_.size() > 1 ? int(sizes_[1]) : 1, sizes_.size() > 2 ? int(sizes_[2]) : 1};
    for (std::size_t a = 3; a < sizes_.size(); ++a)
      if (sizes_[a] != 1) because("it is a " + std::to_string(dimension_) + "-D image");
    // The specification requires "endian" where the encoding keeps the bytes of multi-byte
    // values (raw, hex, gzip, bzip2, zrl).
    if (bytesPerVoxel > 1 && encoding_ != kText && !seen_[kEndian])
      throw HeaderError("malformed NRRD header: no 'endian' field for " + std::to_string(bytesPerVoxel) +
                        "-byte voxels");
    layout.bigEndian = bigEndian_ && bytesPerVoxel > 1;
    if (encoding_ != kRaw) because("its voxels are " + std::string(kEncodingNames[encoding_]) + "-encoded");
    if (byteSkip_ == -1 && encoding_ != kRaw)
      throw HeaderError("malformed NRRD header: 'byte skip: -1' needs the raw encoding");
    if (layout.bigEndian) because("its voxels are big-endian");
    if (lineSkip_ > 0) because("its data file begins with lines to skip ('line skip')");

    // What encoded voxels need at least: deflate expands at most 1032 times, hex takes two
    // characters a byte, text at least two a value (a digit and a separator).
    if (encoding_ == kGzip) layout.maxExpansion = 1032;
    else if (encoding_ == kHex) layout.maxExpansion = 0.5;
    else if (encoding_ == kText) layout.maxExpansion = double(bytesPerVoxel) / 2;
    if (seen_[kDataFile]) {
      layout.severalDataFiles = dataFiles_ != kOne;
      layout.listedFiles = listed_;
      if (!listed_.empty() && encoding_ == kRaw && byteSkip_ >= 0 && lineSkip_ == 0)
        layout.listedPartBytes = layout.dataBytes() / listed_.size() + std::uint64_t(byteSkip_);
      if (dataFiles_ != kOne) because("its voxels are in several files ('data file: " + std::string(dataFile_) + "')");
      layout.dataFile = std::string(dataFile_);
      layout.fromEnd = byteSkip_ == -1;
      layout.offset = byteSkip_ > 0 ? std::uint64_t(byteSkip_) : 0;
      return layout;
    }
    if (!blankLine)
      throw HeaderError("the NRRD header has no 'data file' and does not end with an empty line "
                        "before its voxels (truncated file?)");
    const std::uint64_t bytes = layout.dataBytes();
    if (byteSkip_ == -1) {
      if (fileSize_ < bytes || fileSize_ - bytes < dataStart) text::requireData(dataStart, bytes, fileSize_);
      layout.offset = fileSize_ - bytes;
    } else {
      layout.offset = dataStart + std::uint64_t(byteSkip_);
    }
    if (encoding_ == kRaw && lineSkip_ == 0) text::requireData(layout.offset, bytes, fileSize_);
    // (teem applies a byte skip to decoded bytes: the encoded ones begin after the header.)
    if (lineSkip_ == 0) text::requireStored(bytes, layout.maxExpansion, fileSize_ - dataStart);
    return layout;
  }

  std::string_view head_;
  std::uint64_t fileSize_;
  std::string_view line_, value_, dataFile_;
  std::size_t lineNo_ = 0;
  std::array<bool, kFieldCount> seen_{};
  int type_ = 0, dimension_ = 0, spaceDim_ = 0, encoding_ = kRaw;
  std::vector<std::int64_t> sizes_;
  bool bigEndian_ = false;
  std::int64_t byteSkip_ = 0, lineSkip_ = 0;
  enum { kOne, kList, kNumbered } dataFiles_ = kOne;
  std::vector<std::string> listed_;
};

}  // namespace

std::optional<DataLayout> parseNrrdHeader(std::string_view head, std::uint64_t fileSize) {
  return Parser(head, fileSize).parse();
}

}  // namespace surftrack::io
