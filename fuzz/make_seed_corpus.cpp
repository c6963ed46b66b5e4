// Writes the seed corpus of fuzz/fuzz_volume_header.cpp: small valid files of every format,
// written by ITK (io::writeVolume) where ITK writes them and by hand for what it does not
// (big-endian voxels, byte skips, HeaderSize, TIFF stacks with ImageJ and OME metadata), in
// <dir>/<format>/ for the formats mha, mhd, nrrd, nhdr, nii, nii.gz, raw and tif. Detached
// headers are rewritten to name "data.raw", the data file the fuzz target puts next to each
// input. Usage: make_seed_corpus <dir>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "ReadVolume.h"

namespace fs = std::filesystem;
using namespace surftrack;

namespace {

fs::path gRoot;

std::string contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void put(const std::string& format, const std::string& name, const std::string& bytes) {
  fs::create_directories(gRoot / format);
  std::ofstream(gRoot / format / name, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

ImageGeometry geometry() {
  ImageGeometry g;
  g.spacing = {0.5, 0.75, 2.0};
  g.origin = {10, -20, 30};
  const double c = std::cos(0.4), s = std::sin(0.4);
  g.direction = {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
  return g;
}

template <class T>
io::AnyVolume volume() {
  DenseImage<T> image(Dims{3, 4, 2}, T{}, geometry());
  for (std::size_t i = 0; i < image.data().size(); ++i) image.data()[i] = T(i * 37 % 101);
  return io::AnyVolume(std::move(image));
}

/// A file written by ITK in `ext`, with its data file (if any) renamed "data.raw" in the header.
void written(const io::AnyVolume& v, const std::string& ext, const std::string& tag, bool compress) {
  const fs::path tmp = gRoot / "tmp";
  fs::create_directories(tmp);
  const fs::path file = tmp / ("seed." + ext);
  io::writeVolume(v, file.string(), compress);
  std::string bytes = contents(file);
  for (const std::string key : {"data file: ", "ElementDataFile = "}) {
    const std::size_t at = bytes.find(key);
    if (at == std::string::npos || bytes.compare(at + key.size(), 5, "LOCAL") == 0) continue;
    const std::size_t end = bytes.find('\n', at);
    bytes.replace(at + key.size(), end - at - key.size(), "data.raw");
  }
  put(ext, tag + (compress ? "-compressed" : "") + "." + ext, bytes);
}

/// A classic little-endian TIFF of `pages` pages of w x h uint8 voxels (value: page + 1), the
/// first page with `description` (ImageDescription) and an XResolution and YResolution of 10
/// pixels per unit: what ImageJ and OME writers write, in a form ITK does not.
std::string tiff(int pages, int w, int h, const std::string& description) {
  std::string out = "II*";
  out += '\0';
  auto u16 = [&](std::string& s, unsigned v) { s += char(v & 0xff); s += char(v >> 8); };
  auto u32 = [&](std::string& s, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s += char((v >> (8 * i)) & 0xff);
  };
  u32(out, 8);
  for (int p = 0; p < pages; ++p) {
    const bool first = p == 0;
    const int tags = first ? 12 : 9;
    const std::uint32_t ifd = std::uint32_t(out.size());
    const std::uint32_t extra = ifd + 2 + 12 * std::uint32_t(tags) + 4;  // description, rationals, voxels
    const std::uint32_t descriptionAt = extra, rationalsAt = descriptionAt + std::uint32_t(description.size() + 1);
    const std::uint32_t voxelsAt = first ? rationalsAt + 16 : extra;
    std::string d;
    u16(d, unsigned(tags));
    auto tag = [&](unsigned id, unsigned type, std::uint32_t count, std::uint32_t value) {
      u16(d, id);
      u16(d, type);
      u32(d, count);
      u32(d, value);
    };
    tag(256, 4, 1, std::uint32_t(w));
    tag(257, 4, 1, std::uint32_t(h));
    tag(258, 3, 1, 8);
    tag(259, 3, 1, 1);
    tag(262, 3, 1, 1);
    if (first) tag(270, 2, std::uint32_t(description.size() + 1), descriptionAt);
    tag(273, 4, 1, voxelsAt);
    tag(277, 3, 1, 1);
    tag(278, 4, 1, std::uint32_t(h));
    tag(279, 4, 1, std::uint32_t(w * h));
    if (first) {
      tag(282, 5, 1, rationalsAt);
      tag(283, 5, 1, rationalsAt + 8);
    }
    const std::uint32_t next = voxelsAt + std::uint32_t(w * h);
    u32(d, p + 1 < pages ? next : 0);
    if (first) {
      d += description;
      d += '\0';
      for (int r = 0; r < 2; ++r) {
        u32(d, 10);
        u32(d, 1);
      }
    }
    d += std::string(std::size_t(w * h), char(p + 1));
    out += d;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seed_corpus <dir>\n");
    return 2;
  }
  gRoot = argv[1];
  fs::create_directories(gRoot);
  const io::AnyVolume volumes[] = {volume<std::uint8_t>(), volume<std::int16_t>(), volume<std::uint32_t>(),
                                   volume<std::int64_t>(), volume<float>(), volume<double>()};
  for (const io::AnyVolume& v : volumes) {
    const std::string tag = toString(io::scalarTypeOf(v));
    for (const std::string ext : {"mha", "mhd", "nrrd", "nhdr", "nii"}) {
      written(v, ext, tag, false);
      if (ext != "nii") written(v, ext, tag, true);
    }
    written(v, "nii.gz", tag, false);  // (always gzip'd)
  }
  // By hand: what ITK does not write.
  const std::string nrrdStart =
      "NRRD0005\n# a comment\ntype: short\ndimension: 3\nsizes: 3 4 2\nspace: right-anterior-superior\n"
      "space directions: (0.5,0,0) none (0,0,2)\nspace origin: (1,2,3)\nkinds: domain domain domain\n"
      "key:=value\n";
  const std::string data(3 * 4 * 2 * 2, '\x11');
  put("nrrd", "big-endian.nrrd", nrrdStart + "endian: big\nencoding: raw\n\n" + data);
  put("nrrd", "byte-skip.nrrd", nrrdStart + "endian: little\nencoding: raw\nbyte skip: 6\n\n" + std::string(6, 's') + data);
  put("nrrd", "from-end.nrrd", nrrdStart + "endian: little\nencoding: raw\nbyte skip: -1\r\n\r\n" + std::string(3, 's') + data);
  put("nrrd", "text.nrrd", nrrdStart + "encoding: ascii\n\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24\n");
  put("nhdr", "byte-skip.nhdr", nrrdStart + "endian: little\nencoding: raw\nbyte skip: 16\ndata file: data.raw\n");
  put("nhdr", "line-skip.nhdr", nrrdStart + "endian: little\nencoding: raw\nline skip: 1\ndata file: data.raw\n");
  put("nhdr", "list.nhdr", nrrdStart + "endian: little\nencoding: raw\ndata file: LIST\ndata.raw\ndata.raw\n");
  const std::string metaStart =
      "ObjectType = Image\nNDims = 3\nDimSize = 3 4 2\nElementSpacing = 0.5 0.75 2\nOffset = 1 2 3\n"
      "TransformMatrix = 1 0 0 0 1 0 0 0 1\n";
  put("mha", "big-endian.mha", metaStart + "ElementByteOrderMSB = True\nElementType = MET_SHORT\nElementDataFile = LOCAL\n" + data);
  put("mha", "header-size.mha", metaStart + "HeaderSize = -1\nElementType = MET_SHORT\nElementDataFile = LOCAL\n" + data);
  put("mhd", "header-size.mhd", metaStart + "HeaderSize = 16\nElementType = MET_SHORT\nElementDataFile = data.raw\n");
  put("nhdr", "numbered.nhdr", nrrdStart + "endian: little\nencoding: raw\ndata file: dat%02d.raw 1 2 1 2\n");
  put("mhd", "numbered.mhd", metaStart + "ElementType = MET_SHORT\nElementDataFile = dat%d.raw 1 2 1\n");
  put("mhd", "list.mhd", metaStart + "ElementType = MET_SHORT\nElementDataFile = LIST\ndata.raw\ndata.raw\n");
  put("mhd", "channels.mhd", metaStart + "ElementNumberOfChannels = 2\nElementType = MET_SHORT\nElementDataFile = data.raw\n");
  // TIFF: written by ITK (one page per slice), and by hand with ImageJ and OME metadata.
  for (const io::AnyVolume& v : {volume<std::uint8_t>(), volume<std::int16_t>(), volume<float>()}) {
    try {
      written(v, "tif", toString(io::scalarTypeOf(v)), false);
    } catch (const std::exception&) {  // (a type ITK's TIFF writer does not write)
    }
  }
  put("tif", "imagej-c2.tif", tiff(6, 3, 4, "ImageJ=1.53t\nimages=6\nchannels=2\nslices=3\nhyperstack=true\nspacing=0.3\nunit=micron\n"));
  put("tif", "imagej-stack.tif", tiff(3, 3, 4, "ImageJ=1.53t\nimages=3\nslices=3\nspacing=2.5\nunit=nm\n"));
  put("tif", "imagej-frames.tif", tiff(4, 3, 4, "ImageJ=1.53t\nimages=4\nslices=2\nframes=2\n"));
  const std::string ome =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?><OME xmlns=\"http://www.openmicroscopy.org/Schemas/OME/2016-06\">"
      "<Image ID=\"Image:0\"><Pixels ID=\"Pixels:0\" DimensionOrder=\"XYZCT\" Type=\"uint8\" SizeX=\"3\" SizeY=\"4\" "
      "SizeC=\"2\" SizeZ=\"3\" SizeT=\"1\" PhysicalSizeX=\"0.1\" PhysicalSizeY=\"0.1\" PhysicalSizeZ=\"300\" "
      "PhysicalSizeZUnit=\"nm\"><Channel ID=\"Channel:0:0\" SamplesPerPixel=\"1\"/><Channel ID=\"Channel:0:1\" "
      "SamplesPerPixel=\"1\"/>";
  put("tif", "ome-c2.tif", tiff(6, 3, 4, ome + "<TiffData IFD=\"0\" PlaneCount=\"6\"/></Pixels></Image></OME>"));
  std::string planes;
  for (int c = 0; c < 2; ++c)
    for (int z = 0; z < 3; ++z)
      planes += "<TiffData FirstC=\"" + std::to_string(c) + "\" FirstZ=\"" + std::to_string(z) + "\" IFD=\"" +
                std::to_string(z + 3 * c) + "\" PlaneCount=\"1\"><UUID FileName=\"input.tif\">urn:uuid:1</UUID></TiffData>";
  put("tif", "ome-planes.tif", tiff(6, 3, 4, ome + planes + "</Pixels></Image></OME>"));
  // A float NIfTI with a NaN (which niftilib reads as 0).
  {
    DenseImage<float> image(Dims{3, 4, 2}, 1.5f, geometry());
    image.at(1, 1, 1) = std::nanf("");
    const io::AnyVolume v(std::move(image));
    written(v, "nii", "nan-float", false);
    written(v, "nii.gz", "nan-float", false);
  }
  // Raw: 5 bytes of layout (type | 0x80 for big-endian, header bytes, nx - 1, ny - 1, nz - 1),
  // then the file (fuzz/fuzz_volume_header.cpp, fuzzRaw).
  for (int type = 0; type < 10; ++type)
    for (int header : {0, 3}) {
      const int bytes = int(sizeOf(ScalarType(type))) * 3 * 4 * 2;
      std::string seed = {char(type | (type % 2 ? 0x80 : 0)), char(header), 2, 3, 1};
      seed += std::string(std::size_t(header), 'h') + std::string(std::size_t(bytes), '\x21');
      put("raw", toString(ScalarType(type)) + "-" + std::to_string(header) + ".raw", seed);
    }
  fs::remove_all(gRoot / "tmp");
  return 0;
}
