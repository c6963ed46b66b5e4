// Reading the text headers of MetaImage and NRRD files: lines, words, strict numbers, and the
// checks the parsers share (voxel counts that overflow, files shorter than their header says).
// Everything works on string_views into the caller's buffer and never reads outside it.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "VolumeHeader.h"

namespace surftrack::io::text {

inline bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r'; }

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && (isBlank(s.front()) || s.front() == '\n')) s.remove_prefix(1);
  while (!s.empty() && (isBlank(s.back()) || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

inline char lower(char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; }

inline bool equalsIgnoringCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

/// One line of a header: the bytes of `s` from `pos` up to its '\n' (not included), and where
/// the next line begins — after that '\n', or at s.size() when the line runs to the end of `s`
/// without one. A cursor moved only by `next` never passes the end of `s`, so that every
/// substr and index that follows stays inside it.
struct Line {
  std::string_view text;
  std::size_t next = 0;
  bool ended = false;  ///< the line has its '\n'
};

/// The line of `s` that begins at `pos` (a `pos` past the end gives an empty line at the end).
inline Line lineAt(std::string_view s, std::size_t pos) {
  if (pos > s.size()) pos = s.size();
  const std::size_t eol = s.find('\n', pos);
  if (eol == std::string_view::npos) return {s.substr(pos), s.size(), false};
  return {s.substr(pos, eol - pos), eol + 1, true};
}

/// Words separated by blanks.
inline std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && isBlank(s[i])) ++i;
    const std::size_t start = i;
    while (i < s.size() && !isBlank(s[i])) ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

/// A header's text for messages: at most 60 characters, control bytes as '?'.
inline std::string quote(std::string_view s) {
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < 60; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += c >= 0x20 && c < 0x7f ? char(c) : '?';
  }
  if (s.size() > 60) out += "...";
  return out + "'";
}

/// A whole word as a decimal integer (optional sign), or nothing.
inline std::optional<std::int64_t> toInteger(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

/// A whole word as a finite decimal number, or nothing.
inline std::optional<double> toNumber(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

/// Bytes allowed in a header's text besides the printable ones: tab, and the line ends (a C0
/// control byte, NUL above all, would make the C readers of these formats see other names and
/// values than the parser does).
inline bool isControl(char c) {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && c != '\t' && c != '\n' && c != '\r') || u == 0x7f;
}

/// Raw voxels stored in a way that expands by at most `maxExpansion`: `dataBytes` of them need
/// storedBytes >= dataBytes / maxExpansion (give or take 4 KiB of headers and padding).
inline void requireStored(std::uint64_t dataBytes, double maxExpansion, std::uint64_t storedBytes) {
  if (maxExpansion > 0 && double(dataBytes) > maxExpansion * double(storedBytes) + 4096.0)
    throw HeaderError("the header announces " + std::to_string(dataBytes) + " bytes of voxels, more than the " +
                      std::to_string(storedBytes) + " bytes of encoded data can hold (truncated file?)");
}

/// The largest magnitude accepted in a header's geometry (spacings, origins, direction
/// matrices): far beyond any scanner's millimetres, and small enough that ITK's products of
/// them stay finite — ITK's matrix code (vnl) aborts the process on an infinity.
inline constexpr double kMaxGeometryValue = 1e15;

/// A whole word as a geometry number: finite and within +-kMaxGeometryValue.
inline std::optional<double> toGeometryNumber(std::string_view s) {
  const auto v = toNumber(s);
  if (!v || std::abs(*v) > kMaxGeometryValue) return std::nullopt;
  return v;
}

/// A file name pattern for numbered data files (NRRD "data file: <format> <min> <max> <step>",
/// MetaImage "ElementDataFile = <format> <min> <max> <step>") that its readers pass to
/// sprintf with one int: exactly one conversion "%[flags][width]d" (or i, u, x, X, o) and
/// otherwise only "%%". Anything else would have sprintf read arguments that do not exist. The
/// width is at most 10: teem's file name buffer holds 10 characters more than the format.
inline bool isOneIntFormat(std::string_view format) {
  int conversions = 0;
  for (std::size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') continue;
    if (++i < format.size() && format[i] == '%') continue;
    while (i < format.size() && (format[i] == '0' || format[i] == '-' || format[i] == '+' || format[i] == ' ' ||
                                 format[i] == '#'))
      ++i;
    int width = 0;
    while (i < format.size() && format[i] >= '0' && format[i] <= '9') {
      width = width * 10 + (format[i] - '0');
      if (width > 10) return false;
      ++i;
    }
    if (i >= format.size() || std::string_view("diuxXo").find(format[i]) == std::string_view::npos) return false;
    ++conversions;
  }
  return conversions == 1;
}

/// Axes of `sizes` voxels of `bytes` each: HeaderError if an axis is not in [1, INT_MAX] (the
/// engine's coordinates are ints) or the voxels would exceed 2^62 bytes.
inline void requireSizes(const std::vector<std::int64_t>& sizes, std::size_t bytes) {
  std::uint64_t total = bytes;
  for (std::int64_t n : sizes) {
    if (n < 1 || n > std::numeric_limits<int>::max())
      throw HeaderError("an image size of " + std::to_string(n) + " voxels is not supported");
    if (total > (std::uint64_t(1) << 62) / std::uint64_t(n))
      throw HeaderError("the image is larger than 2^62 bytes");
    total *= std::uint64_t(n);
  }
}

/// The voxels of a raw file are the bytes [offset, offset + bytes) of a file of fileSize bytes:
/// HeaderError "truncated file?" otherwise.
inline void requireData(std::uint64_t offset, std::uint64_t bytes, std::uint64_t fileSize) {
  if (offset > fileSize || fileSize - offset < bytes)
    throw HeaderError("the file has " + std::to_string(fileSize) + " bytes, but its header announces " +
                      std::to_string(bytes) + " bytes of voxel data at byte " + std::to_string(offset) +
                      " (truncated file?)");
}

}  // namespace surftrack::io::text
