#include "Options.h"

#include <charconv>
#include <cmath>
#include <cctype>
#include <map>
#include <utility>

namespace surftrack::cli {

namespace {

double parseDouble(const std::string& text, const std::string& what) {
  double value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || text.empty() || !std::isfinite(value))
    throw UsageError(what + ": '" + text + "' is not a number");
  return value;
}

long long parseInteger(const std::string& text, const std::string& what) {
  long long value = 0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || begin == end)
    throw UsageError(what + ": '" + text + "' is not an integer");
  return value;
}

std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::string cur;
  for (char ch : text) {
    if (ch == ',') {
      parts.push_back(cur);
      cur.clear();
    } else if (ch != ' ') {
      cur += ch;
    }
  }
  parts.push_back(cur);
  return parts;
}

std::array<double, 3> parseTriple(const std::string& text, const std::string& what) {
  auto parts = splitCommas(text);
  if (parts.size() != 3) throw UsageError(what + ": expected three numbers X,Y,Z, got '" + text + "'");
  return {parseDouble(parts[0], what), parseDouble(parts[1], what), parseDouble(parts[2], what)};
}

std::optional<Direction> parseDirection(const std::string& text) {
  static const std::map<std::string, Direction> names = {
      {"+x", 0}, {"x", 0}, {"-x", 1}, {"+y", 2}, {"y", 2}, {"-y", 3}, {"+z", 4}, {"z", 4}, {"-z", 5}};
  auto it = names.find(text);
  if (it == names.end()) return std::nullopt;
  return it->second;
}

/// Walks the argument list: options with a value accept "--opt VALUE" and "--opt=VALUE".
class ArgumentReader {
 public:
  explicit ArgumentReader(const std::vector<std::string>& args) : args_(args) {}

  bool next() {
    if (i_ >= args_.size()) return false;
    current_ = args_[i_++];
    inlineValue_.reset();
    if (current_.size() > 2 && current_.rfind("--", 0) == 0) {
      auto eq = current_.find('=');
      if (eq != std::string::npos) {
        inlineValue_ = current_.substr(eq + 1);
        current_ = current_.substr(0, eq);
      }
    }
    return true;
  }
  const std::string& name() const { return current_; }
  bool isOption() const { return current_.size() > 1 && current_[0] == '-' && !looksNumeric(current_); }
  std::string value() {
    if (inlineValue_) return *std::exchange(inlineValue_, std::nullopt);
    if (i_ >= args_.size()) throw UsageError("option " + current_ + " needs a value");
    return args_[i_++];
  }
  void noValue() const {
    if (inlineValue_) throw UsageError("option " + current_ + " takes no value");
  }

 private:
  static bool looksNumeric(const std::string& s) {
    return s.size() > 1 && s[0] == '-' && (std::isdigit(static_cast<unsigned char>(s[1])) || s[1] == '.');
  }
  const std::vector<std::string>& args_;
  std::size_t i_ = 0;
  std::string current_;
  std::optional<std::string> inlineValue_;
};

/// Which raw-layout options were given, to check they come together.
struct RawFlags {
  bool type = false;   ///< --raw-type
  bool other = false;  ///< --raw-endian, --raw-header
};

/// Options every command reading a volume accepts; returns false if `name` is not one.
bool parseInputOption(ArgumentReader& r, InputOptions& in, RawFlags& flags) {
  const std::string& n = r.name();
  if (n == "--raw-type") flags.type = true;
  if (n == "--raw-endian" || n == "--raw-header") flags.other = true;
  if (n == "--raw-dims") {
    auto parts = splitCommas(r.value());
    if (parts.size() != 3) throw UsageError("--raw-dims: expected NX,NY,NZ");
    int d[3];
    for (int a = 0; a < 3; ++a) {
      long long v = parseInteger(parts[a], "--raw-dims");
      if (v <= 0 || v > (1 << 19) - 3) throw UsageError("--raw-dims: dimensions must be in [1, 524285]");
      d[a] = int(v);
    }
    in.raw = true;
    in.rawLayout.dims = Dims{d[0], d[1], d[2]};
  } else if (n == "--raw-type") {
    try {
      in.rawLayout.type = io::parseScalarType(r.value());
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--raw-type: ") + e.what());
    }
  } else if (n == "--raw-endian") {
    std::string v = r.value();
    if (v == "little") in.rawLayout.bigEndian = false;
    else if (v == "big") in.rawLayout.bigEndian = true;
    else throw UsageError("--raw-endian: expected little or big, got '" + v + "'");
  } else if (n == "--raw-header") {
    long long v = parseInteger(r.value(), "--raw-header");
    if (v < 0) throw UsageError("--raw-header: must not be negative");
    in.rawLayout.headerBytes = std::size_t(v);
  } else if (n == "--spacing") {
    auto s = parseTriple(r.value(), "--spacing");
    for (double v : s)
      if (!(v > 0)) throw UsageError("--spacing: every spacing must be positive");
    in.spacing = s;
  } else if (n == "--origin") {
    in.origin = parseTriple(r.value(), "--origin");
  } else {
    return false;
  }
  return true;
}

bool parseOutputOption(ArgumentReader& r, OutputOptions& out) {
  if (r.name() == "--json") {
    r.noValue();
    out.json = true;
  } else if (r.name() == "--quiet" || r.name() == "-q") {
    r.noValue();
    out.quiet = true;
  } else {
    return false;
  }
  return true;
}

void checkRaw(const InputOptions& in, const RawFlags& flags) {
  if ((flags.type || flags.other) && !in.raw)
    throw UsageError("--raw-type, --raw-endian and --raw-header need --raw-dims");
  if (in.raw && !flags.type)
    throw UsageError("a raw file needs --raw-type (uint8, int16, uint16, int32, float or double)");
}

}  // namespace

std::string directionName(Direction d) {
  static const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  return d < 6 ? names[d] : "?";
}

MeshOptions parseMeshOptions(const std::vector<std::string>& args) {
  MeshOptions o;
  ArgumentReader r(args);
  RawFlags raw;
  int seedOptions = 0;
  std::string seedGiven;
  auto setSeed = [&](SeedMode mode) {
    if (++seedOptions > 1)
      throw UsageError("give only one of --seed, --seed-point, --largest, --all (got " + seedGiven +
                       " and " + r.name() + ")");
    seedGiven = r.name();
    o.surface.seedMode = mode;
  };
  while (r.next()) {
    const std::string n = r.name();
    if (!r.isOption()) {
      if (!o.input.path.empty()) throw UsageError("unexpected argument '" + n + "' (one input volume only)");
      o.input.path = n;
    } else if (n == "-o" || n == "--output") {
      o.output = r.value();
    } else if (n == "--iso") {
      o.surface.iso = parseDouble(r.value(), "--iso");
    } else if (n == "--label") {
      o.surface.label = parseDouble(r.value(), "--label");
    } else if (n == "--seed") {
      setSeed(SeedMode::Voxel);
      const std::string v = r.value();
      auto parts = splitCommas(v);
      if (parts.size() != 3 && parts.size() != 4)
        throw UsageError("--seed: expected a voxel x,y,z or a surfel x,y,z,DIR (DIR one of +x -x +y -y +z -z), got '" + v + "'");
      for (int a = 0; a < 3; ++a) {
        long long c = parseInteger(parts[a], "--seed");
        if (c < -(1 << 20) || c > (1 << 20)) throw UsageError("--seed: coordinate out of range");
        o.surface.seedVoxel[a] = int(c);
      }
      if (parts.size() == 4) {
        auto d = parseDirection(parts[3]);
        if (!d) throw UsageError("--seed: '" + parts[3] + "' is not a direction (+x -x +y -y +z -z)");
        o.surface.seedMode = SeedMode::Surfel;
        o.surface.seedDirection = *d;
      }
    } else if (n == "--seed-point") {
      setSeed(SeedMode::Point);
      o.surface.seedPoint = parseTriple(r.value(), "--seed-point");
    } else if (n == "--largest") {
      r.noValue();
      setSeed(SeedMode::Largest);
    } else if (n == "--all") {
      r.noValue();
      setSeed(SeedMode::All);
    } else if (n == "--adjacency" || n == "-a") {
      try {
        o.surface.pair = parseAdjacencyPair(r.value());
      } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--adjacency: ") + e.what());
      }
    } else if (n == "--mapping") {
      const std::string v = r.value();
      if (v == "midpoint") o.surface.mapping = MappingMode::Midpoint;
      else if (v == "linear" || v == "iso") o.surface.mapping = MappingMode::Linear;
      else throw UsageError("--mapping: expected midpoint or linear, got '" + v + "'");
    } else if (n == "--ascii") {
      r.noValue();
      o.ascii = true;
    } else if (n == "-h" || n == "--help") {
      throw HelpRequested{meshUsage()};
    } else if (!parseInputOption(r, o.input, raw) && !parseOutputOption(r, o.out)) {
      throw UsageError("unknown option '" + n + "' for 'surftrack mesh'");
    }
  }
  if (o.input.path.empty()) throw UsageError("missing the input volume: surftrack mesh INPUT -o OUTPUT");
  if (o.output.empty()) throw UsageError("missing the output mesh: -o OUTPUT (.ply, .obj, .off or .stl)");
  if (o.surface.iso && o.surface.label) throw UsageError("give --iso or --label, not both");
  if (o.surface.label && o.surface.mapping == MappingMode::Linear)
    throw UsageError("--mapping linear interpolates an iso-value: it needs --iso, not --label");
  checkRaw(o.input, raw);
  return o;
}

InfoOptions parseInfoOptions(const std::vector<std::string>& args) {
  InfoOptions o;
  ArgumentReader r(args);
  RawFlags raw;
  while (r.next()) {
    const std::string n = r.name();
    if (!r.isOption()) {
      if (!o.input.path.empty()) throw UsageError("unexpected argument '" + n + "' (one input volume only)");
      o.input.path = n;
    } else if (n == "-h" || n == "--help") {
      throw HelpRequested{infoUsage()};
    } else if (!parseInputOption(r, o.input, raw) && !parseOutputOption(r, o.out)) {
      throw UsageError("unknown option '" + n + "' for 'surftrack info'");
    }
  }
  if (o.input.path.empty()) throw UsageError("missing the input volume: surftrack info INPUT");
  checkRaw(o.input, raw);
  return o;
}

DemoOptions parseDemoOptions(const std::vector<std::string>& args) {
  DemoOptions o;
  ArgumentReader r(args);
  while (r.next()) {
    const std::string n = r.name();
    if (n == "-o" || n == "--output") {
      o.outputDir = r.value();
    } else if (n == "--size") {
      long long q = parseInteger(r.value(), "--size");
      if (q < 16 || q > 1024) throw UsageError("--size: the phantom side must be in [16, 1024]");
      o.size = int(q);
    } else if (n == "--noise") {
      double p = parseDouble(r.value(), "--noise");
      if (p < 0 || p > 0.5) throw UsageError("--noise: the noise probability must be in [0, 0.5]");
      o.noise = p;
    } else if (n == "--no-mricron") {
      r.noValue();
      o.realData = false;
    } else if (n == "--mricron-dir") {
      o.mricronDir = r.value();
    } else if (n == "-h" || n == "--help") {
      throw HelpRequested{demoUsage()};
    } else if (!parseOutputOption(r, o.out)) {
      throw UsageError("unknown argument '" + n + "' for 'surftrack demo'");
    }
  }
  return o;
}

std::string mainUsage() {
  return R"(usage: surftrack COMMAND [ARGS]

Extracts ONE connected iso-surface from a 3D image by tracking its digital boundary
(Lachaud & Montanvert, "Continuous analogs of digital boundaries").

commands:
  mesh INPUT -o OUTPUT [options]   extract a surface and write it as a mesh
  info INPUT [options]             describe a volume: size, type, geometry, values
  demo [-o DIR]                    extract surfaces of a built-in phantom (and of the
                                   mricron-data MRI volumes when installed)

Run 'surftrack COMMAND --help' for the options of a command.
)";
}

std::string meshUsage() {
  return R"(usage: surftrack mesh INPUT -o OUTPUT [options]

INPUT   .nii .nii.gz .nrrd .nhdr .mha .mhd .dcm .tif .vtk, a directory with one DICOM
        series, or a raw file with --raw-dims and --raw-type
OUTPUT  .ply (binary unless --ascii), .obj, .off, .stl; vertices in physical coordinates

what is inside (1-voxels):
  --iso S              voxels with value > S (default: Otsu's threshold of the histogram)
  --label L            voxels with value = L
which surface:
  --largest            the boundary with the most surfels (default)
  --all                every boundary, in one mesh
  --seed x,y,z         the boundary first met walking from voxel (x,y,z) along +x
                       (then -x, +y, -y, +z, -z); the surfel used is printed
  --seed x,y,z,DIR     the boundary of surfel (c=(x,y,z), normal DIR in +x -x +y -y +z -z)
  --seed-point X,Y,Z   like --seed, from the voxel nearest to a physical point
surface options:
  --adjacency K-L      26-6 (default), 18-6, 6-18 or 6-26: adjacency of inside-outside voxels
  --mapping M          linear (default with --iso: vertices at the interpolated iso-value)
                       or midpoint (vertices halfway between the two voxels)
  --ascii              text PLY / STL
raw input:
  --raw-dims NX,NY,NZ  --raw-type uint8|int16|uint16|int32|float|double
  --raw-endian little|big   --raw-header BYTES
geometry override:
  --spacing SX,SY,SZ   --origin OX,OY,OZ
output:
  --json               a JSON object on stdout instead of the summary
  --quiet, -q          print nothing but errors
)";
}

std::string infoUsage() {
  return R"(usage: surftrack info INPUT [--json] [--raw-dims NX,NY,NZ --raw-type T ...]

Prints the size, voxel type, spacing, origin, direction, value range, a histogram summary,
Otsu's threshold (the default --iso of 'surftrack mesh') and, for integer images with few
values, the labels present.
)";
}

std::string demoUsage() {
  return R"(usage: surftrack demo [-o DIR] [--size Q] [--noise P] [--no-mricron] [--json] [--quiet]

Builds a phantom (a sphere minus three orthogonal cylinders, Q^3 voxels, Q = 128, with
P = 1 % salt-and-pepper noise), tracks the surface of its seed and writes DIR/phantom.nrrd and
DIR/phantom.ply (DIR = surftrack-demo). With the Debian package mricron-data installed, it
also extracts the cortical surface of ch2better.nii.gz and one label of the aal.nii.gz atlas.
)";
}

}  // namespace surftrack::cli
