// parseTiffStack (io/TiffStack.h): the first page directory of a TIFF (TIFF 6.0, and BigTIFF),
// then the ImageJ description or the OME-XML it holds.
#include "TiffStack.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_set>
#include <vector>

#include "HeaderText.h"
#include "VolumeHeader.h"

namespace surftrack::io {

namespace {

using text::quote;
using text::trim;

/// The largest ImageDescription read: OME-XML grows with the planes it lists.
constexpr std::uint64_t kMaxDescription = std::uint64_t(16) << 20;

constexpr int kImageDescription = 270, kXResolution = 282, kYResolution = 283;
/// DateTime: TIFF 6.0 gives it 20 bytes ("YYYY:MM:DD HH:MM:SS" and a NUL). libtiff keeps as
/// many as the file holds, and ITK's TIFF reader copies 20 into its dictionary: a shorter one
/// would be read past its end, so it is refused.
constexpr int kDateTime = 306;
constexpr std::uint64_t kDateTimeBytes = 20;

/// What a page says about its voxels; ITK's TIFF reader reads every page as the first one
/// (its buffer and its scanlines sized by it).
struct PageShape {
  std::uint64_t width = 0, length = 0, bits = 1, samples = 1, format = 1, planar = 1;  // (TIFF 6.0's defaults)
  bool operator==(const PageShape&) const = default;
};

/// Where a page's pixels are: in strips of rowsPerStrip rows, or in tiles when tileWidth is
/// set; the number of offsets the page lists. libtiff sizes its arrays of offsets by the
/// number of strips or tiles the image's size implies, whatever the page lists, and cuts one
/// uncompressed strip into many: the checks below keep both within what the file can hold.
struct PageLayout {
  std::uint64_t compression = 1, rowsPerStrip = 0xffffffff, tileWidth = 0, tileLength = 0;
  std::uint64_t stripOffsets = 0, tileOffsets = 0;
};

/// ceil(a / b) for b > 0.
std::uint64_t howMany(std::uint64_t a, std::uint64_t b) { return a / b + (a % b != 0); }

/// Refuses a page whose strips or tiles libtiff would allocate beyond the file: fewer offsets
/// listed than the page's size needs (TIFF 6.0's StripsPerImage, TilesPerImage), or
/// uncompressed pixels larger than the file.
void requireLayoutInFile(const PageShape& shape, const PageLayout& layout, std::uint64_t fileSize,
                         const std::string& which) {
  const std::uint64_t planes = shape.planar == 2 ? shape.samples : 1;
  std::uint64_t needed = 0, listed = 0;
  std::string what;
  if (layout.tileWidth != 0 || layout.tileLength != 0) {
    if (layout.tileWidth == 0 || layout.tileLength == 0)
      throw HeaderError("the TIFF's " + which + " has a tile width or length of 0");
    needed = howMany(shape.width, layout.tileWidth) * howMany(shape.length, layout.tileLength);
    listed = layout.tileOffsets;
    what = "TileOffsets";
  } else {
    if (layout.rowsPerStrip == 0) throw HeaderError("the TIFF's " + which + " has RowsPerStrip 0");
    needed = howMany(shape.length, layout.rowsPerStrip);
    listed = layout.stripOffsets;
    what = "StripOffsets";
  }
  // (width and length are below 2^32, tiles at least 1 x 1: the products fit in 128 bits)
  const unsigned __int128 offsets = static_cast<unsigned __int128>(needed) * planes;
  if (offsets > listed)
    throw HeaderError("the TIFF's " + which + " lists " + std::to_string(listed) + " " + what + ", fewer than the " +
                      (offsets > ~std::uint64_t(0) ? std::string("2^64 or more") : std::to_string(std::uint64_t(offsets))) +
                      " its size of " + std::to_string(shape.width) + " x " + std::to_string(shape.length) +
                      " pixels needs (truncated or damaged file?)");
  const unsigned __int128 row = (static_cast<unsigned __int128>(shape.width) * shape.samples * shape.bits + 7) / 8;
  if (layout.compression == 1 && row * shape.length > fileSize)
    throw HeaderError("the TIFF's " + which + " holds " + std::to_string(shape.width) + " x " +
                      std::to_string(shape.length) + " uncompressed pixels, more than its file of " +
                      std::to_string(fileSize) + " bytes (truncated or damaged file?)");
}

/// The tags of the first page that matter here, and the number of pages.
struct FirstPage {
  std::string description;
  std::optional<double> xResolution, yResolution;  ///< pixels per unit
  std::int64_t pages = 0;
};

/// The most pages read: beyond, a TIFF is refused rather than walked for ever.
constexpr std::int64_t kMaxPages = std::int64_t(1) << 20;

/// Integers of the file's byte order.
class Bytes {
 public:
  explicit Bytes(bool bigEndian) : big_(bigEndian) {}
  std::uint64_t get(std::string_view b, std::size_t at, std::size_t n) const {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t byte = static_cast<unsigned char>(b[at + i]);
      v |= byte << (8 * (big_ ? n - 1 - i : i));
    }
    return v;
  }

 private:
  bool big_;
};

/// The byte size of one value of a TIFF field type (0: unknown type).
std::uint64_t typeSize(std::uint64_t type) {
  switch (type) {
    case 1: case 2: case 6: case 7: return 1;  // BYTE, ASCII, SBYTE, UNDEFINED
    case 3: case 8: return 2;                  // SHORT, SSHORT
    case 4: case 9: case 11: case 13: return 4;  // LONG, SLONG, FLOAT, IFD
    case 5: case 10: case 12: case 16: case 17: case 18: return 8;  // RATIONAL, SRATIONAL, DOUBLE, LONG8, SLONG8, IFD8
    default: return 0;
  }
}

/// Exactly `bytes` bytes at `offset` (HeaderError if the file ends before).
std::string readExactly(const ReadAt& read, std::uint64_t offset, std::size_t bytes) {
  std::string out = read(offset, bytes);
  if (out.size() < bytes) throw HeaderError("the TIFF file ends at a page directory or tag (truncated file?)");
  return out;
}

/// "3 x 4 pixels, 1 sample of 8 bits (format 1, planar 1)": a page's shape for messages.
std::string shapeText(const PageShape& p) {
  return std::to_string(p.width) + " x " + std::to_string(p.length) + " pixels, " + std::to_string(p.samples) +
         " sample of " + std::to_string(p.bits) + " bits (format " + std::to_string(p.format) + ", planar " +
         std::to_string(p.planar) + ")";
}

/// Every page directory of the TIFF (TIFF 6.0, and BigTIFF): the first page's description and
/// resolution, and that every page has the first's shape.
FirstPage readPages(const ReadAt& read, std::uint64_t fileSize) {
  const std::string head = read(0, 16);
  if (head.size() < 8 || !(head.compare(0, 2, "II") == 0 || head.compare(0, 2, "MM") == 0))
    throw HeaderError("not a TIFF file: it does not begin with 'II' or 'MM'");
  const Bytes b(head[0] == 'M');
  const std::uint64_t magic = b.get(head, 2, 2);
  if (magic != 42 && magic != 43) throw HeaderError("not a TIFF file: its version is " + std::to_string(magic) + ", not 42 or 43");
  const bool big = magic == 43;  // BigTIFF: 8-byte counts and offsets
  if (big && (head.size() < 16 || b.get(head, 4, 2) != 8))
    throw HeaderError("malformed BigTIFF header (truncated file?)");
  const std::size_t countBytes = big ? 8 : 2, entryBytes = big ? 20 : 12, valueBytes = big ? 8 : 4;
  FirstPage page;
  PageShape first;
  std::unordered_set<std::uint64_t> seen;
  for (std::uint64_t ifd = big ? b.get(head, 8, 8) : b.get(head, 4, 4); ifd != 0;) {
    const std::string which = page.pages == 0 ? "first page" : "page " + std::to_string(page.pages + 1);
    if (page.pages == kMaxPages) throw HeaderError("the TIFF has more than 2^20 pages");
    if (ifd < 8 || ifd > fileSize || fileSize - ifd < countBytes + valueBytes)
      throw HeaderError("the TIFF's " + which + " directory at byte " + std::to_string(ifd) + " is outside the file of " +
                        std::to_string(fileSize) + " bytes (truncated file?)");
    const std::uint64_t entries = b.get(readExactly(read, ifd, countBytes), 0, countBytes);
    if (entries > 65535) throw HeaderError("the TIFF's " + which + " has " + std::to_string(entries) + " tags, more than 65535");
    if (entries > (fileSize - ifd - countBytes - valueBytes) / entryBytes)
      throw HeaderError("the TIFF's " + which + " directory runs past the end of the file (truncated file?)");
    // The directory and the offset of the next one after it.
    const std::string table = readExactly(read, ifd + countBytes, std::size_t(entries * entryBytes) + valueBytes);
    PageShape shape;
    PageLayout layout;
    std::unordered_set<std::uint64_t> tags;
    for (std::uint64_t e = 0; e < entries; ++e) {
      const std::size_t at = std::size_t(e * entryBytes);
      const std::uint64_t tag = b.get(table, at, 2), type = b.get(table, at + 2, 2);
      const std::uint64_t count = big ? b.get(table, at + 4, 8) : b.get(table, at + 4, 4);
      const std::uint64_t size = typeSize(type);
      const std::size_t valueAt = at + 4 + (big ? 8 : 4);  // (after the tag, type and count)
      if (size == 0 || !tags.insert(tag).second) continue;  // (unknown types and repeated tags: libtiff ignores them)
      // Every tag's values lie in the file: libtiff allocates them by their count before it reads.
      if (count > fileSize / size ||
          (size * count > valueBytes && (b.get(table, valueAt, valueBytes) > fileSize - size * count)))
        throw HeaderError("the TIFF's tag " + std::to_string(tag) + " lies outside the file (truncated file?)");
      // The first `n` bytes of the tag's values: in the entry, or at the offset it holds.
      auto value = [&](std::uint64_t n) {
        if (size * count <= valueBytes) return table.substr(valueAt, std::size_t(n));
        return readExactly(read, b.get(table, valueAt, valueBytes), std::size_t(n));
      };
      // An ASCII value's count includes its NUL (TIFF 6.0): libtiff keeps an unknown tag's bytes
      // as they are, and ITK's reader takes a value of one byte for a NUL-terminated string.
      if (type == 2 && (count == 0 || (count == 1 && table[valueAt] != '\0')))
        throw HeaderError("the TIFF's tag " + std::to_string(tag) + " holds text without its NUL (" +
                          std::to_string(count) + (count == 1 ? " byte)" : " bytes)"));
      if (tag == kDateTime && type == 2 && count < kDateTimeBytes)
        throw HeaderError("the TIFF's DateTime tag holds " + std::to_string(count) + " bytes, not the 20 of TIFF 6.0");
      if (tag == 273 || tag == 324) {
        (tag == 273 ? layout.stripOffsets : layout.tileOffsets) = count;
        continue;
      }
      std::uint64_t* place = tag == 259 ? &layout.compression : tag == 278 ? &layout.rowsPerStrip
                           : tag == 322 ? &layout.tileWidth : tag == 323 ? &layout.tileLength : nullptr;
      if (place && count >= 1 && (type == 3 || type == 4 || type == 16)) {
        *place = b.get(value(size), 0, std::size_t(size));
        continue;
      }
      std::uint64_t* field = tag == 256 ? &shape.width : tag == 257 ? &shape.length : tag == 258 ? &shape.bits
                           : tag == 277 ? &shape.samples : tag == 339 ? &shape.format : tag == 284 ? &shape.planar
                                                                                        : nullptr;
      if (field && count >= 1 && (type == 3 || type == 4 || type == 16)) {
        *field = b.get(value(size), 0, std::size_t(size));
        continue;
      }
      if (page.pages > 0 || (tag != kImageDescription && tag != kXResolution && tag != kYResolution)) continue;
      const bool resolution = tag != kImageDescription;
      if ((resolution && (type != 5 || count != 1)) || (!resolution && type != 2 && type != 7))
        continue;  // (not of the type TIFF 6.0 gives these tags: ignored, as libtiff does)
      if (count > kMaxDescription) throw HeaderError("the TIFF's ImageDescription is longer than 16 MiB");
      const std::string bytes = value(size * count);
      if (resolution) {
        const double num = double(b.get(bytes, 0, 4)), den = double(b.get(bytes, 4, 4));
        if (num > 0 && den > 0) (tag == kXResolution ? page.xResolution : page.yResolution) = num / den;
      } else {
        page.description = bytes.substr(0, bytes.find('\0'));
      }
    }
    requireLayoutInFile(shape, layout, fileSize, which);
    if (page.pages == 0) {
      first = shape;
      if (first.width == 0 || first.length == 0) throw HeaderError("the TIFF's first page has no width or length");
    } else if (!(shape == first)) {
      throw HeaderError("its " + which + " (" + shapeText(shape) + ") differs from its first (" + shapeText(first) +
                        "): ITK reads every page as the first");
    }
    ++page.pages;
    seen.insert(ifd);
    ifd = b.get(table, std::size_t(entries * entryBytes), valueBytes);
    if (seen.count(ifd) != 0) throw HeaderError("the TIFF's page directories form a loop");
  }
  return page;
}

/// A length unit and its size in micrometres; 0 for a unit that is not a length known here.
struct Unit {
  std::string name;  ///< canonical: "µm", "nm", ...; as written otherwise
  double micrometres = 0;
};

Unit unitOf(std::string_view s) {
  s = trim(s);
  struct Known {
    std::string_view spelling, name;
    double micrometres;
  };
  static constexpr Known kKnown[] = {
      {"µm", "µm", 1},        {"\xCE\xBCm", "µm", 1},  {"\\u00B5m", "µm", 1}, {"&#181;m", "µm", 1},
      {"&#xB5;m", "µm", 1},   {"um", "µm", 1},         {"micron", "µm", 1},   {"microns", "µm", 1},
      {"micrometer", "µm", 1}, {"micrometre", "µm", 1}, {"nm", "nm", 1e-3},    {"nanometer", "nm", 1e-3},
      {"pm", "pm", 1e-6},     {"mm", "mm", 1e3},       {"millimeter", "mm", 1e3}, {"cm", "cm", 1e4},
      {"centimeter", "cm", 1e4}, {"m", "m", 1e6},      {"meter", "m", 1e6},   {"Å", "Å", 1e-4},
      {"&#197;", "Å", 1e-4},  {"angstrom", "Å", 1e-4}, {"in", "inch", 25400}, {"inch", "inch", 25400}};
  for (const Known& k : kKnown)
    if (text::equalsIgnoringCase(s, k.spelling) && (k.spelling.size() > 2 || s == k.spelling))
      return {std::string(k.name), k.micrometres};
  if (s.empty() || text::equalsIgnoringCase(s, "pixel") || text::equalsIgnoringCase(s, "pixels")) return {};
  return {std::string(s), 0};
}

/// `value` of a unit `from` in the unit `to`; the same value when the units are the same.
double convert(double value, const Unit& from, const Unit& to, std::string_view what) {
  if (from.name == to.name) return value;
  if (from.micrometres > 0 && to.micrometres > 0) return value * from.micrometres / to.micrometres;
  throw HeaderError(std::string(what) + " is in '" + from.name + "', the other axes in '" +
                    (to.name.empty() ? "pixel" : to.name) + "': no common unit");
}

std::int64_t positiveCount(std::string_view value, std::string_view what) {
  const auto n = text::toInteger(trim(value));
  if (!n || *n < 1 || *n > std::numeric_limits<int>::max())
    throw HeaderError(std::string(what) + " is " + quote(value) + ", not a positive count");
  return *n;
}

double positiveSize(std::string_view value, std::string_view what) {
  const auto v = text::toGeometryNumber(trim(value));
  if (!v || !(*v > 0)) throw HeaderError(std::string(what) + " is " + quote(value) + ", not a positive size");
  return *v;
}

/// ImageJ's description: "key=value" lines (ImageJ's FileSaver, ij/io/TiffDecoder).
TiffStack imageJStack(const FirstPage& page) {
  TiffStack s;
  s.source = "ImageJ";
  std::optional<std::int64_t> images, channels, slices, frames;
  std::optional<double> spacing;
  std::string unit, zunit, yunit;
  std::size_t pos = 0;
  const std::string_view d = page.description;
  while (pos < d.size()) {
    const text::Line line = text::lineAt(d, pos);
    pos = line.next;
    const std::size_t eq = line.text.find('=');
    if (eq == std::string_view::npos) continue;
    const std::string_view key = trim(line.text.substr(0, eq)), value = trim(line.text.substr(eq + 1));
    if (key == "images") images = positiveCount(value, "ImageJ images");
    else if (key == "channels") channels = positiveCount(value, "ImageJ channels");
    else if (key == "slices") slices = positiveCount(value, "ImageJ slices");
    else if (key == "frames") frames = positiveCount(value, "ImageJ frames");
    else if (key == "spacing") spacing = positiveSize(value, "ImageJ spacing");
    else if (key == "unit") unit = value;
    else if (key == "yunit") yunit = value;
    else if (key == "zunit") zunit = value;
  }
  s.channels = channels.value_or(1);
  s.frames = frames.value_or(1);
  const std::int64_t perSlice = s.channels * s.frames;
  if (slices) {
    s.slices = *slices;
  } else {  // (a plain stack: images=40 alone)
    const std::int64_t all = images.value_or(perSlice);
    if (all % perSlice != 0)
      throw HeaderError("its ImageJ description announces " + std::to_string(all) + " images, not a multiple of " +
                        std::to_string(s.channels) + " channels x " + std::to_string(s.frames) + " frames");
    s.slices = all / perSlice;
  }
  if (s.slices > std::numeric_limits<int>::max() / perSlice)
    throw HeaderError("its ImageJ description announces more than 2^31 images");
  if (images && *images != s.pages())
    throw HeaderError("its ImageJ description announces " + std::to_string(*images) + " images, not channels x slices x frames = " +
                      std::to_string(s.pages()));
  s.channelsField = "ImageJ channels=" + std::to_string(s.channels);
  if (s.frames > 1)
    throw HeaderError("it has " + std::to_string(s.frames) + " time points (ImageJ frames=" + std::to_string(s.frames) +
                      "); surftrack reads one 3D image");
  const Unit u = unitOf(unit);
  s.unit = u.name;
  const double x = page.xResolution ? 1 / *page.xResolution : 1, y = page.yResolution ? 1 / *page.yResolution : 1;
  const double z = spacing.value_or(1);
  s.spacing = std::array<double, 3>{x, yunit.empty() ? y : convert(y, unitOf(yunit), u, "ImageJ's yunit"),
                                    zunit.empty() ? z : convert(z, unitOf(zunit), u, "ImageJ's zunit")};
  for (double v : *s.spacing)
    if (!(v > 0) || !std::isfinite(v)) throw HeaderError("its ImageJ voxel size is not positive");
  return s;
}

/// The attributes of the XML element that begins at `at` ("<Name a="1" b='2'>").
std::vector<std::pair<std::string_view, std::string_view>> attributes(std::string_view xml, std::size_t at) {
  std::vector<std::pair<std::string_view, std::string_view>> out;
  std::size_t i = at + 1;
  while (i < xml.size() && !text::isBlank(xml[i]) && xml[i] != '\n' && xml[i] != '>' && xml[i] != '/') ++i;
  for (;;) {
    while (i < xml.size() && (text::isBlank(xml[i]) || xml[i] == '\n')) ++i;
    if (i >= xml.size()) throw HeaderError("its OME-XML ends inside an element");
    if (xml[i] == '>' || xml[i] == '/') return out;
    const std::size_t nameStart = i;
    while (i < xml.size() && xml[i] != '=' && !text::isBlank(xml[i]) && xml[i] != '\n' && xml[i] != '>') ++i;
    const std::string_view name = xml.substr(nameStart, i - nameStart);
    while (i < xml.size() && (text::isBlank(xml[i]) || xml[i] == '\n')) ++i;
    if (i >= xml.size() || xml[i] != '=') throw HeaderError("its OME-XML has an attribute without a value");
    ++i;
    while (i < xml.size() && (text::isBlank(xml[i]) || xml[i] == '\n')) ++i;
    if (i >= xml.size() || (xml[i] != '"' && xml[i] != '\'')) throw HeaderError("its OME-XML has an unquoted attribute");
    const char quoteChar = xml[i++];
    const std::size_t end = xml.find(quoteChar, i);
    if (end == std::string_view::npos) throw HeaderError("its OME-XML ends inside an attribute");
    out.emplace_back(name, xml.substr(i, end - i));
    i = end + 1;
  }
}

std::optional<std::string_view> attribute(const std::vector<std::pair<std::string_view, std::string_view>>& a,
                                          std::string_view name) {
  for (const auto& [n, v] : a)
    if (n == name) return v;
  return std::nullopt;
}

/// The offsets of the elements <name ...> of `xml` from `from` to `to` (not <NameOther...>).
std::vector<std::size_t> elements(std::string_view xml, std::string_view name, std::size_t from = 0,
                                  std::size_t to = std::string_view::npos) {
  std::vector<std::size_t> out;
  std::string open(1, '<');
  open += name;
  for (std::size_t at = xml.find(open, from); at != std::string_view::npos && at < to; at = xml.find(open, at + 1)) {
    const std::size_t after = at + open.size();
    if (after < xml.size() && (text::isBlank(xml[after]) || xml[after] == '\n' || xml[after] == '>' || xml[after] == '/'))
      out.push_back(at);
  }
  return out;
}

/// OME-XML (the OME data model, Image/Pixels): one image, its planes in the file's pages in
/// DimensionOrder.
TiffStack omeStack(const FirstPage& page, std::string_view fileName) {
  TiffStack s;
  s.source = "OME-TIFF";
  const std::string_view xml = page.description;
  const auto images = elements(xml, "Image");
  if (images.size() != 1)
    throw HeaderError("its OME-XML describes " + std::to_string(images.size()) +
                      " images (series); surftrack reads a file of one");
  const auto pixelsAt = elements(xml, "Pixels", images[0]);
  if (pixelsAt.empty()) throw HeaderError("its OME-XML has no Pixels element");
  const auto pixels = attributes(xml, pixelsAt[0]);
  auto count = [&](std::string_view name) {
    const auto v = attribute(pixels, name);
    if (!v) throw HeaderError("its OME-XML Pixels element has no " + std::string(name));
    return positiveCount(*v, "OME " + std::string(name));
  };
  s.width = count("SizeX");
  s.height = count("SizeY");
  s.channels = count("SizeC");
  s.slices = count("SizeZ");
  s.frames = count("SizeT");
  s.channelsField = "OME SizeC=" + std::to_string(s.channels);
  if (s.channels > std::numeric_limits<int>::max() / s.slices / s.frames)
    throw HeaderError("its OME-XML announces more than 2^31 planes");
  const std::string order(attribute(pixels, "DimensionOrder").value_or(""));
  static constexpr std::string_view kOrders[] = {"XYZCT", "XYZTC", "XYCTZ", "XYCZT", "XYTCZ", "XYTZC"};
  bool known = false;
  for (std::string_view o : kOrders) known |= order == o;
  if (!known) throw HeaderError("its OME DimensionOrder is " + quote(order) + ", not one of XYZCT, XYCZT, ...");
  if (s.frames > 1)
    throw HeaderError("it has " + std::to_string(s.frames) + " time points (OME SizeT=" + std::to_string(s.frames) +
                      "); surftrack reads one 3D image");
  s.channelFirst = order.find('C') < order.find('Z');
  const std::size_t pixelsEnd = xml.find("</Pixels>", pixelsAt[0]);
  for (std::size_t channel : elements(xml, "Channel", pixelsAt[0], pixelsEnd)) {
    const auto samples = attribute(attributes(xml, channel), "SamplesPerPixel");
    if (samples && trim(*samples) != "1")
      throw HeaderError("its channels have " + std::string(trim(*samples)) +
                        " samples per pixel (RGB; OME SamplesPerPixel); surftrack reads one scalar per voxel");
  }
  // The planes: in the pages of this file, in DimensionOrder (a TiffData element maps planes
  // from FirstC, FirstZ, FirstT on to the pages from IFD on).
  const std::int64_t planes = s.pages();
  auto planeIndex = [&](std::int64_t c, std::int64_t z, std::int64_t t) {
    std::int64_t index = 0, stride = 1;
    for (char axis : order.substr(2)) {
      const std::int64_t v = axis == 'C' ? c : axis == 'Z' ? z : t, size = axis == 'C' ? s.channels : axis == 'Z' ? s.slices : s.frames;
      index += v * stride;
      stride *= size;
    }
    return index;
  };
  const auto tiffData = elements(xml, "TiffData", pixelsAt[0], pixelsEnd);
  std::int64_t covered = 0;
  for (std::size_t at : tiffData) {
    const auto a = attributes(xml, at);
    auto number = [&](std::string_view name, std::int64_t fallback) {
      const auto v = attribute(a, name);
      if (!v) return fallback;
      const auto n = text::toInteger(trim(*v));
      if (!n || *n < 0 || *n > planes) throw HeaderError("its OME TiffData " + std::string(name) + " is " + quote(*v));
      return *n;
    };
    const std::int64_t ifd = number("IFD", 0);
    const std::int64_t first = planeIndex(number("FirstC", 0), number("FirstZ", 0), number("FirstT", 0));
    const std::int64_t count = number("PlaneCount", tiffData.size() == 1 && !attribute(a, "IFD") ? planes : 1);
    if (ifd != first || first + count > planes)
      throw HeaderError("its OME TiffData puts planes in other pages than DimensionOrder does; not supported");
    covered += count;
    const std::size_t close = xml.find('>', at);
    const std::size_t end = close != std::string_view::npos && close > 0 && xml[close - 1] == '/'
                                ? close
                                : xml.find("</TiffData>", at);
    for (std::size_t uuid : elements(xml, "UUID", at, end)) {
      const auto file = attribute(attributes(xml, uuid), "FileName");
      if (file && *file != fileName)
        throw HeaderError("its OME TiffData puts planes in another file (" + quote(*file) + "); not supported");
    }
  }
  if (!tiffData.empty() && covered != planes)
    throw HeaderError("its OME TiffData maps " + std::to_string(covered) + " planes, and the image has " +
                      std::to_string(planes));
  // Physical sizes: micrometres unless a unit is named; converted to the unit of x.
  const auto sizeX = attribute(pixels, "PhysicalSizeX"), sizeY = attribute(pixels, "PhysicalSizeY"),
             sizeZ = attribute(pixels, "PhysicalSizeZ");
  if (sizeX || sizeY || sizeZ) {
    auto unit = [&](std::string_view name) { return unitOf(attribute(pixels, name).value_or("µm")); };
    const Unit ux = unit("PhysicalSizeXUnit");
    s.unit = ux.name;
    const double x = sizeX ? positiveSize(*sizeX, "OME PhysicalSizeX") : 1;
    s.spacing = std::array<double, 3>{
        x, sizeY ? convert(positiveSize(*sizeY, "OME PhysicalSizeY"), unit("PhysicalSizeYUnit"), ux, "OME PhysicalSizeY") : x,
        sizeZ ? convert(positiveSize(*sizeZ, "OME PhysicalSizeZ"), unit("PhysicalSizeZUnit"), ux, "OME PhysicalSizeZ") : 1};
  }
  return s;
}

}  // namespace

TiffStack parseTiffStack(const ReadAt& read, std::uint64_t fileSize, std::string_view fileName) {
  const FirstPage page = readPages(read, fileSize);
  const std::string_view d = trim(page.description);
  if (d.substr(0, 7) == "ImageJ=") return imageJStack(page);
  if ((d.substr(0, 5) == "<?xml" || d.substr(0, 4) == "<OME") && d.find("<OME") != std::string_view::npos)
    return omeStack(page, fileName);
  return TiffStack{};
}

}  // namespace surftrack::io
