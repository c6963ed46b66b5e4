// The MetaImage header (MetaIO's "MetaImage" format, .mha and .mhd): "Key = Value" lines, the
// first one "ObjectType = Image", ending with the line "ElementDataFile = ...". The voxels
// follow that line (ElementDataFile = LOCAL) or are in the named file; HeaderSize moves them
// (> 0: that many bytes from the start of the data file; -1: the last bytes of the file).
// Keys are case-sensitive, a value begins after the '=' (or ':') and the blanks that follow, as
// MetaIO reads them; keys this parser does not use (Comment, AnatomicalOrientation, ...) are
// skipped, as MetaIO does.
#include <algorithm>
#include <optional>
#include <utility>
#include <vector>

#include "HeaderText.h"
#include "VolumeHeader.h"

namespace surftrack::io {

namespace {

using text::quote;
using text::trim;

struct MetaType {
  std::string_view name;
  ScalarType type;
};
// MetaIO's ElementType names for the ten scalar types. MET_LONG and MET_ULONG are 4 bytes in
// MetaIO (MET_ValueTypeSize), and ITK reads them as int and unsigned int.
constexpr MetaType kMetaTypes[] = {
    {"MET_UCHAR", ScalarType::UInt8},       {"MET_CHAR", ScalarType::Int8},
    {"MET_USHORT", ScalarType::UInt16},     {"MET_SHORT", ScalarType::Int16},
    {"MET_UINT", ScalarType::UInt32},       {"MET_INT", ScalarType::Int32},
    {"MET_ULONG", ScalarType::UInt32},      {"MET_LONG", ScalarType::Int32},
    {"MET_ULONG_LONG", ScalarType::UInt64}, {"MET_LONG_LONG", ScalarType::Int64},
    {"MET_FLOAT", ScalarType::Float32},     {"MET_DOUBLE", ScalarType::Float64}};

/// MetaIO's booleans: true when the value begins with T, t or 1.
bool metaBool(std::string_view value) {
  return !value.empty() && (value[0] == 'T' || value[0] == 't' || value[0] == '1');
}

class Parser {
 public:
  Parser(std::string_view head, std::uint64_t fileSize) : head_(head), fileSize_(fileSize) {}

  std::optional<DataLayout> parse() {
    const bool whole = head_.size() >= fileSize_;
    std::size_t pos = 0;
    bool first = true;
    for (;;) {
      // MetaIO skips white space (blank lines included) before a key.
      while (pos < head_.size() && (text::isBlank(head_[pos]) || head_[pos] == '\n')) ++pos;
      if (pos >= head_.size()) {
        if (!whole) return std::nullopt;
        if (first) throw HeaderError("not a MetaImage file: it is empty or blank");
        throw HeaderError("the MetaImage header ends before its ElementDataFile line (truncated file?)");
      }
      const text::Line line = text::lineAt(head_, pos);
      if (!line.ended && !whole) return std::nullopt;
      const std::size_t next = line.next;
      line_ = line.text;
      lineStart_ = pos;
      for (std::size_t i = 0; i < line_.size(); ++i)
        if (text::isControl(line_[i]) || (line_[i] == '\r' && i + 1 != line_.size()))
          fail("has a control character (byte " + std::to_string(static_cast<unsigned char>(line_[i])) + ")");
      const std::size_t sep = line_.find_first_of("=:");
      if (sep == std::string_view::npos) {
        // The last line of the file, cut short (of the first line, a part of "ObjectType").
        const std::string_view cut = trim(line_);
        if (!line.ended && (!first || std::string_view("ObjectType").substr(0, cut.size()) == cut))
          throw HeaderError("the MetaImage header ends within a line (truncated file?)");
        if (first) throw HeaderError("not a MetaImage file: it does not begin with 'ObjectType = Image'");
        fail("is not 'Key = Value'");
      }
      // MetaIO copies a key it does not know into a field name of 255 bytes (MET_InitReadField,
      // strcpy): a longer one would overflow it.
      if (sep >= kMaxKey) fail("has a key of more than " + std::to_string(kMaxKey - 1) + " characters");
      const std::string_view key = trim(line_.substr(0, sep));
      std::size_t v = sep;
      while (v < line_.size() && (line_[v] == '=' || line_[v] == ':' || text::isBlank(line_[v]))) ++v;
      // MetaIO strips what is not printable, or is white space, from the end of a value.
      value_ = line_.substr(v);
      while (!value_.empty() && (static_cast<unsigned char>(value_.back()) <= 0x20 ||
                                 static_cast<unsigned char>(value_.back()) >= 0x7f))
        value_.remove_suffix(1);
      if (first) {
        // ITK's MetaImageIO recognises a MetaImage by its first line (MetaIO's MET_ReadType).
        if (key != "ObjectType")
          throw HeaderError("not a MetaImage file: it does not begin with 'ObjectType = Image'");
        if (value_.substr(0, 5) != "Image")
          throw HeaderError("not a MetaImage image: ObjectType = " + quote(value_));
        first = false;
      }
      if (key == "ElementDataFile") {
        if (value_.substr(0, 4) == "LIST" && !listComplete(next, whole)) return std::nullopt;
        return finish(next);
      }
      field(key);
      pos = next;
    }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    std::size_t lineNo = 1;
    for (std::size_t i = 0; i < lineStart_; ++i) lineNo += head_[i] == '\n';
    throw HeaderError("malformed MetaImage header: line " + std::to_string(lineNo) + " " +
                      quote(trim(line_)) + " " + what);
  }

  std::vector<double> numbers(std::size_t count) {
    const auto w = text::words(value_);
    if (w.size() != count) fail("needs " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (std::string_view s : w) {
      const auto x = text::toGeometryNumber(s);
      if (!x) fail("has " + quote(s) + " where a number (of magnitude at most 1e15) is expected");
      out.push_back(*x);
    }
    return out;
  }

  std::int64_t integer() {
    const auto x = text::toInteger(value_);
    if (!x) fail("needs an integer");
    return *x;
  }

  int requireNDims() {
    if (ndims_ == 0) fail("comes before NDims");
    return ndims_;
  }

  void field(std::string_view key) {
    if (key == "NDims") {
      const std::int64_t n = integer();
      if (n < 1 || n > 10) fail("is not a number of dimensions from 1 to 10");
      if (ndims_ != 0 && n != ndims_) fail("changes NDims");
      ndims_ = int(n);
    } else if (key == "DimSize") {
      const auto w = text::words(value_);
      if (w.size() != std::size_t(requireNDims())) fail("needs " + std::to_string(ndims_) + " sizes");
      sizes_.clear();
      for (std::string_view s : w) {
        const auto n = text::toInteger(s);
        if (!n || *n < 1) fail("has " + quote(s) + " where a positive integer is expected");
        sizes_.push_back(*n);
      }
    } else if (key == "ElementType") {
      type_.reset();
      otherType_.clear();
      for (const MetaType& t : kMetaTypes)
        if (value_ == t.name) type_ = t.type;
      if (!type_) {
        if (value_.size() > 6 && value_.substr(value_.size() - 6) == "_ARRAY" && value_.substr(0, 4) == "MET_")
          otherType_ = std::string(value_);  // a vector type: ITK reads it (or rejects it)
        else
          fail("is not a MetaImage element type (MET_UCHAR, MET_SHORT, MET_FLOAT, ...)");
      }
    } else if (key == "ElementNumberOfChannels") {
      channels_ = integer();
      if (channels_ < 1) fail("needs a positive number of channels");
    } else if (key == "BinaryData") {
      binary_ = metaBool(value_);
    } else if (key == "CompressedData") {
      compressed_ = metaBool(value_);
    } else if (key == "ElementByteOrderMSB" || key == "BinaryDataByteOrderMSB") {
      msb_ = metaBool(value_);
    } else if (key == "CompressedDataSize") {
      compressedSize_ = integer();
      if (compressedSize_ < 0) fail("is not a byte count");
    } else if (key == "HeaderSize") {
      headerSize_ = integer();
      if (headerSize_ < -1) fail("is neither -1 nor a byte count");
    } else if (key == "ElementSpacing" || key == "ElementSize" || key == "Offset" ||
               key == "Position" || key == "Origin" || key == "CenterOfRotation") {
      numbers(std::size_t(requireNDims()));
    } else if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation") {
      numbers(std::size_t(requireNDims()) * std::size_t(ndims_));
    } else if (key == "ElementToIntensityFunctionSlope") {
      slope_ = numbers(1)[0];
    } else if (key == "ElementToIntensityFunctionOffset") {
      intercept_ = numbers(1)[0];
    }
  }

  // MetaIO splits ElementDataFile = LIST ... and numbered-file patterns into words at spaces
  // (MET_StringToWordArray), each in a buffer of 80 bytes (METAIO_MAX_WORD_SIZE), and joins a
  // pattern's words back into the first one's buffer: longer words would overflow them.
  static constexpr std::size_t kMaxWord = 80;
  static constexpr std::size_t kMaxKey = 255;

  /// The files of ElementDataFile = LIST [D], as MetaIO reads them: one name per line after the
  /// header (getline into 1024 bytes), one file for each D-dimensional block (D = NDims - 1 by
  /// default, as MetaIO takes it). A missing, empty or overlong name would make MetaIO read a
  /// file it cannot open into its buffer, and crash (found by fuzz/); a
  /// name without its newline is skipped. False if the head ends
  /// before the last name and the file is longer; the names go to listed_.
  bool listComplete(std::size_t start, bool whole) {
    const auto w = metaWords();
    int fileDims = 0;
    if (w.size() > 1) {
      const auto d = text::toInteger(w[1]);
      if (!d) fail("has " + quote(w[1]) + " where the dimension of the listed files is expected");
      fileDims = int(*d);
    }
    const int ndims = requireNDims();
    if (fileDims <= 0 || fileDims > ndims) fileDims = ndims - 1;
    if (sizes_.size() != std::size_t(ndims)) fail("comes before DimSize");
    std::int64_t files = 1;  // (at most one a line of the header's 1 MiB)
    for (int a = ndims; a > fileDims; --a) {
      if (sizes_[std::size_t(a - 1)] > std::int64_t(kMaxHeaderBytes) / files) fail("needs more listed files than its header can hold");
      files *= sizes_[std::size_t(a - 1)];
    }
    listed_.clear();
    std::size_t pos = start;
    for (std::int64_t i = 0; i < files; ++i) {
      const text::Line line = text::lineAt(head_, pos);
      if (!line.ended && !whole) return false;
      std::string_view name = line.text;
      if (!name.empty() && name.back() == '\r') name.remove_suffix(1);
      if (pos >= head_.size() || trim(name).empty())
        fail("lists " + std::to_string(i) + " data files, and the image needs " + std::to_string(files));
      // MetaIO tests for the end of the file after each getline and skips the name that ends
      // it without its '\n': that file's voxels would be left unread, as whatever the buffer
      // held (found by the sanitized test suite, whose allocator fills new memory).
      if (!line.ended)
        fail("lists " + std::to_string(i) + " data files, and the image needs " + std::to_string(files) +
             " (MetaIO skips a last name without its newline)");
      if (name.size() >= 1023) fail("lists a data file name of more than 1022 characters");
      for (char c : name)
        if (text::isControl(c)) fail("lists a data file name with a control character");
      listed_.emplace_back(name);
      pos = line.next;
    }
    return true;
  }

  std::vector<std::string_view> metaWords() {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < value_.size()) {
      while (i < value_.size() && value_[i] == ' ') ++i;
      const std::size_t start = i;
      while (i < value_.size() && value_[i] != ' ') ++i;
      if (i > start) out.push_back(value_.substr(start, i - start));
    }
    for (std::string_view word : out)
      if (word.size() >= kMaxWord) fail("has a word of more than 79 characters");
    if (metaWordCount() != out.size())
      fail("has three or more spaces in a row, which MetaIO counts as more words than it reads");
    return out;
  }

  /// The words MetaIO's MET_StringToWordArray counts in value_ (which has no trailing space):
  /// one more than the spaces that follow a non-space or an odd space of a run — a run of three
  /// or more spaces counts twice or more. MetaIO allocates that many words, fills those it finds,
  /// and then reads the others (uninitialised pointers: it crashed under fuzz/).
  std::size_t metaWordCount() const {
    std::size_t i = 0, n = 0;
    while (i < value_.size() && value_[i] == ' ') ++i;
    bool space = false;
    for (; i < value_.size(); ++i) {
      if (value_[i] == ' ' && !space) {
        ++n;
        space = true;
      } else {
        space = false;
      }
    }
    return value_.empty() ? 0 : n + 1;
  }

  /// "ElementDataFile = <pattern> [<first> [<last> [<step>]]]", numbered files as MetaIO reads
  /// them (the last three words are the numbers when there are more than four: a pattern with
  /// spaces). MetaIO passes the pattern to sprintf and divides by the step, which it computes
  /// as (last - first) / DimSize[NDims - 1] when only <last> is given: a pattern with another
  /// conversion than one integer, or a step of 0, would crash it.
  void requireFilePattern() {
    const auto w = metaWords();
    const std::size_t numbers = w.size() >= 4 ? 3 : w.size() - 1;
    const std::string_view pattern =
        trim(value_.substr(0, std::size_t(w[w.size() - numbers - 1].data() + w[w.size() - numbers - 1].size() - value_.data())));
    if (pattern.size() >= kMaxWord) fail("has a file name pattern of more than 79 characters");
    if (!text::isOneIntFormat(pattern))
      fail("has a file name pattern with other than one integer conversion (%d)");
    std::vector<std::int64_t> n;
    for (std::size_t i = w.size() - numbers; i < w.size(); ++i) {
      const auto x = text::toInteger(w[i]);
      if (!x || *x < -(std::int64_t(1) << 31) + 1 || *x > (std::int64_t(1) << 31) - 1)
        fail("has " + quote(w[i]) + " where a file number is expected");
      n.push_back(*x);
    }
    const std::int64_t slices = sizes_.back();
    const std::int64_t first = n.size() > 0 ? n[0] : 1;
    const std::int64_t last = n.size() > 1 ? n[1] : first + slices - 1;
    const std::int64_t step = n.size() > 2 ? n[2] : n.size() == 2 ? (last - first) / slices : 1;
    if (step == 0) fail("numbers its files with a step of 0");
    if ((last - first) / step < 0) fail("numbers its files from " + std::to_string(first) + " away from " + std::to_string(last));
  }

  /// The ElementDataFile line; the header ends at `dataStart`.
  DataLayout finish(std::size_t dataStart) {
    for (const auto& [missing, name] : {std::pair{ndims_ == 0, "NDims"}, std::pair{sizes_.empty(), "DimSize"},
                                        std::pair{!type_ && otherType_.empty(), "ElementType"}})
      if (missing) throw HeaderError(std::string("malformed MetaImage header: no ") + name + " before ElementDataFile");
    if (value_.empty()) fail("names no data file");
    DataLayout layout;
    layout.type = type_.value_or(ScalarType::UInt8);
    text::requireSizes(sizes_, sizeOf(layout.type) * std::size_t(channels_));
    layout.dims = {int(sizes_[0]), sizes_.size() > 1 ? int(sizes_[1]) : 1, sizes_.size() > 2 ? int(sizes_[2]) : 1};
    layout.bigEndian = msb_;
    auto because = [&](const std::string& reason) {
      if (layout.decodeReason.empty()) layout.decodeReason = reason;
    };
    if (!otherType_.empty()) because("its element type is " + otherType_);
    if (channels_ > 1) because("it has " + std::to_string(channels_) + " channels per voxel");
    for (std::size_t a = 3; a < sizes_.size(); ++a)
      if (sizes_[a] != 1) because("it is a " + std::to_string(ndims_) + "-D image");
    if (compressed_) because("its voxels are compressed (CompressedData = True)");
    if (!binary_) because("its voxels are stored as text (BinaryData = False)");
    if (msb_ && sizeOf(layout.type) > 1) because("its voxels are big-endian (ByteOrderMSB = True)");
    if (slope_ != 1 || intercept_ != 0) because("its voxels are rescaled (ElementToIntensityFunction)");

    const bool local = value_ == "LOCAL" || value_ == "Local" || value_ == "local";
    if (!local) {
      layout.severalDataFiles = value_.substr(0, 4) == "LIST" || value_.find('%') != std::string_view::npos;
      if (value_.substr(0, 4) == "LIST") {
        layout.listedFiles = listed_;
        layout.listedPartBytes = layout.dataBytes() / listed_.size();  // (as MetaIO reads each)
        because("its voxels are in a list of files (ElementDataFile = LIST)");
      } else if (value_.find('%') != std::string_view::npos) {
        requireFilePattern();
        because("its voxels are in numbered files (ElementDataFile = " + std::string(value_) + ")");
      }
      layout.dataFile = std::string(value_);
    }
    const std::uint64_t bytes = layout.dataBytes() * std::uint64_t(channels_);
    if (headerSize_ > 0) {
      layout.offset = std::uint64_t(headerSize_);
      if (local && layout.offset < dataStart) fail("comes after HeaderSize = " + std::to_string(headerSize_) + " bytes");
    } else if (headerSize_ == -1) {
      layout.fromEnd = true;
    } else {
      layout.offset = local ? dataStart : 0;
    }
    // Compressed (zlib's deflate) or text voxels: a bound on what their bytes can hold.
    layout.deflated = compressed_ && binary_;
    layout.deflatedBytes = std::uint64_t(compressedSize_);
    if (compressed_) layout.maxExpansion = 1032;
    else if (!binary_) layout.maxExpansion = double(sizeOf(layout.type)) / 2;
    if (local && binary_ && !compressed_) {
      if (layout.fromEnd) {
        if (fileSize_ < bytes || fileSize_ - bytes < dataStart) text::requireData(dataStart, bytes, fileSize_);
        layout.offset = fileSize_ - bytes;
      }
      text::requireData(layout.offset, bytes, fileSize_);
    } else if (local && !layout.fromEnd) {
      const std::uint64_t stored = layout.offset <= fileSize_ ? fileSize_ - layout.offset : 0;
      if (compressedSize_ > 0) text::requireData(layout.offset, std::uint64_t(compressedSize_), fileSize_);
      text::requireStored(bytes, layout.maxExpansion,
                          compressedSize_ > 0 ? std::min<std::uint64_t>(stored, std::uint64_t(compressedSize_)) : stored);
    }
    return layout;
  }

  std::string_view head_;
  std::uint64_t fileSize_;
  std::string_view line_, value_;
  std::vector<std::string> listed_;
  std::size_t lineStart_ = 0;
  int ndims_ = 0;
  std::vector<std::int64_t> sizes_;
  std::optional<ScalarType> type_;
  std::string otherType_;
  std::int64_t channels_ = 1, headerSize_ = 0, compressedSize_ = 0;
  bool binary_ = true, compressed_ = false, msb_ = false;
  double slope_ = 1, intercept_ = 0;
};

}  // namespace

std::optional<DataLayout> parseMetaImageHeader(std::string_view head, std::uint64_t fileSize) {
  return Parser(head, fileSize).parse();
}

}  // namespace surftrack::io
