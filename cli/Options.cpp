// The command line of each subcommand, parsed with CLI11. A value that decides alone whether it
// is valid (a number, a range, one of a set) is checked by a CLI11 validator on its option;
// the rules between options (one seed rule, --iso or --label, the raw layout) are checked
// after parsing. The help texts are CLI11's, laid out by HelpFormatter.
#include "Options.h"

#include <filesystem>
#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cctype>
#include <functional>
#include <map>
#include <memory>
#include <utility>

#include <CLI/CLI.hpp>

#include "Labels.h"  // defaultLabelWalls
#include "Refine.h"  // kMaxSmoothIterations

namespace surftrack::cli {

namespace {

// --- values ----------------------------------------------------------------------------------

/// A finite decimal number ("nan", "inf" and hexadecimal are not).
std::optional<double> toNumber(const std::string& text) {
  double value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || text.empty() || !std::isfinite(value)) return std::nullopt;
  return value;
}

/// A decimal integer, with an optional sign.
std::optional<long long> toInteger(const std::string& text) {
  long long value = 0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || begin == end) return std::nullopt;
  return value;
}

/// A label, exactly: decimal digits with an optional sign up to 64 bits (segment ids above
/// 2^53 included), or a number that is an integer of at most 2^53 ("1e3", "5.0"), where doubles
/// are still exact.
/// A number of bytes: decimal digits with an optional suffix K, M or G (powers of 1024, either
/// case, "KiB" etc. too): "536870912", "512M", "2G". None when it is not one or overflows 64 bits.
std::optional<std::uint64_t> toByteCount(const std::string& text) {
  std::size_t digits = 0;
  while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
  if (digits == 0) return std::nullopt;
  std::uint64_t value = 0;
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + digits, value);
  if (ec != std::errc()) return std::nullopt;
  std::string suffix = text.substr(digits);
  for (char& ch : suffix) ch = char(std::toupper(static_cast<unsigned char>(ch)));
  static const std::map<std::string, int> shifts = {{"", 0},   {"B", 0},    {"K", 10},   {"KB", 10}, {"KIB", 10},
                                                    {"M", 20}, {"MB", 20},  {"MIB", 20}, {"G", 30},  {"GB", 30},
                                                    {"GIB", 30}};
  const auto shift = shifts.find(suffix);
  if (shift == shifts.end() || (shift->second && value > (~std::uint64_t(0) >> shift->second))) return std::nullopt;
  return value << shift->second;
}

std::optional<LabelValue> toLabel(const std::string& text) {
  if (auto L = LabelValue::parse(text)) return L;
  const auto v = toNumber(text);
  if (!v || !(std::fabs(*v) <= 0x1p53)) return std::nullopt;
  return LabelValue::fromDouble(*v);
}

/// The comma-separated parts of `text`, spaces dropped: "1, 2,3" -> {"1", "2", "3"}.
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

std::array<double, 3> toTriple(const std::string& text) {
  const auto parts = splitCommas(text);
  return {*toNumber(parts[0]), *toNumber(parts[1]), *toNumber(parts[2])};
}

std::optional<Direction> parseDirection(const std::string& text) {
  static const std::map<std::string, Direction> names = {{"+x", 0}, {"x", 0},  {"-x", 1}, {"+y", 2}, {"y", 2},
                                                         {"-y", 3}, {"+z", 4}, {"z", 4},  {"-z", 5}};
  auto it = names.find(text);
  if (it == names.end()) return std::nullopt;
  return it->second;
}

// --- validators ------------------------------------------------------------------------------
// CLI11 reports a failed check as "--option: <message>" (a ValidationError, one line).

const CLI::Validator kNumber(
    [](std::string& s) { return toNumber(s) ? std::string() : "'" + s + "' is not a number"; }, "NUMBER");

/// A transform: checks a decimal integer and writes it without sign or leading zeros, so that
/// CLI11's own conversions (which read "010" as octal) see the value we see.
const CLI::Validator kInteger(
    [](std::string& s) {
      const auto v = toInteger(s);
      if (!v) return "'" + s + "' is not an integer";
      s = std::to_string(*v);
      return std::string();
    },
    "INTEGER");

const CLI::Validator kByteCount(
    [](std::string& s) {
      return toByteCount(s) ? std::string()
                            : "'" + s + "' is not a number of bytes (digits, optionally followed by K, M or G)";
    },
    "BYTES");

const CLI::Validator kLabel(
    [](std::string& s) {
      return toLabel(s) ? std::string() : "'" + s + "' is not an integer label (decimal, up to 64 bits)";
    },
    "LABEL");

/// `check`, a CLI11 validator, with the tool's own message when it fails.
CLI::Validator explained(const CLI::Validator& check,
                         std::function<std::string(const std::string&)> message) {
  return CLI::Validator(
      [check, message](std::string& s) { return check(s).empty() ? std::string() : message(s); },
      check.get_description());
}
CLI::Validator explained(const CLI::Validator& check, const std::string& message) {
  return explained(check, [message](const std::string&) { return message; });
}

/// A validator calling a parser of the library, which throws std::invalid_argument.
template <class Parse>
CLI::Validator parsedBy(Parse parse, const std::string& description) {
  return CLI::Validator(
      [parse](std::string& s) {
        try {
          parse(s);
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
        return std::string();
      },
      description);
}

/// Three comma-separated values, each passing every validator of `element`.
CLI::Validator tripleOf(std::vector<CLI::Validator> element, const std::string& countMessage) {
  return CLI::Validator(
      [element, countMessage](std::string& s) {
        auto parts = splitCommas(s);
        if (parts.size() != 3) return countMessage + ", got '" + s + "'";
        for (std::string& part : parts)
          for (const CLI::Validator& check : element) {
            const std::string error = check(part);
            if (!error.empty()) return error;
          }
        return std::string();
      },
      "X,Y,Z");
}

const CLI::Validator kSeedCoordinate = explained(CLI::Range(-(1 << 20), 1 << 20), "coordinate out of range");

/// --seed: a voxel x,y,z or a surfel x,y,z,DIR.
const CLI::Validator kSeed(
    [](std::string& s) {
      const auto parts = splitCommas(s);
      if (parts.size() != 3 && parts.size() != 4)
        return "expected a voxel x,y,z or a surfel x,y,z,DIR (DIR one of +x -x +y -y +z -z), got '" + s + "'";
      for (int a = 0; a < 3; ++a) {
        std::string c = parts[a];
        std::string error = kInteger(c);
        if (error.empty()) error = kSeedCoordinate(c);
        if (!error.empty()) return error;
      }
      if (parts.size() == 4 && !parseDirection(parts[3]))
        return "'" + parts[3] + "' is not a direction (+x -x +y -y +z -z)";
      return std::string();
    },
    "x,y,z[,DIR]");

// --- help ------------------------------------------------------------------------------------

/// The help layout: "usage: <usage>", the description, then each group of options (with the
/// positionals) under its heading, the commands, the footer.
class HelpFormatter : public CLI::Formatter {
 public:
  explicit HelpFormatter(std::string usage) : usage_(std::move(usage)) { column_width(23); }

  std::string make_usage(const CLI::App*, std::string) const override { return "usage: " + usage_ + "\n"; }

  std::string make_group(std::string group, bool, std::vector<const CLI::Option*> opts) const override {
    std::string out = group + ":\n";
    for (const CLI::Option* opt : opts) out += make_option(opt, opt->get_positional());
    return out;
  }

  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode) const override {
    std::string out = make_usage(app, name);
    if (!app->get_description().empty()) out += "\n" + app->get_description() + "\n";
    const auto commands = app->get_subcommands({});
    if (!commands.empty()) {
      out += "\ncommands:\n";
      for (const CLI::App* command : commands) out += make_subcommand(command);
    }
    bool first = true;
    for (const std::string& group : app->get_groups()) {
      const auto opts = app->get_options([&](const CLI::Option* o) { return o->get_group() == group; });
      if (group.empty() || opts.empty()) continue;
      out += (first && commands.empty() ? "\n" : "") + make_group(group, false, opts);
      first = false;
    }
    if (!app->get_footer().empty()) out += "\n" + app->get_footer() + "\n";
    return out;
  }

 private:
  std::string usage_;
};

void setUsage(CLI::App& app, const std::string& usage) {
  app.formatter(std::make_shared<HelpFormatter>(usage));
}

/// Common settings: an option given twice keeps its last value (as in most tools), a flag
/// takes no value, an unknown argument is collected (rejectExtras names it).
void configure(CLI::App& app) {
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.option_defaults()->disable_flag_override();
  app.allow_extras();
}

/// The help flag, last in the "output" group.
void addHelp(CLI::App& app) { app.set_help_flag("-h,--help", "print this help and exit")->group("output"); }

CLI::Option* addValue(CLI::App& app, const std::string& names, const std::string& valueName,
                      std::function<void(const std::string&)> set, const std::string& description) {
  return app.add_option_function<std::string>(names, std::move(set), description)->option_text(valueName);
}

// --- options shared by the commands ----------------------------------------------------------

/// The options every command reading a volume accepts.
struct InputArgs {
  CLI::Option* dims = nullptr;
  CLI::Option* type = nullptr;
  CLI::Option* endian = nullptr;
  CLI::Option* header = nullptr;
};

constexpr long long kMaxDim = (1 << 19) - 3;

InputArgs addInputOptions(CLI::App& app, InputOptions& in) {
  InputArgs a;
  a.dims = addValue(
               app, "--raw-dims", "NX,NY,NZ",
               [&in](const std::string& s) {
                 const auto parts = splitCommas(s);
                 in.raw = true;
                 in.rawLayout.dims =
                     Dims{int(*toInteger(parts[0])), int(*toInteger(parts[1])), int(*toInteger(parts[2]))};
               },
               "the size of a headerless raw file (x fastest, then y, then z)")
               ->check(tripleOf(
                   {kInteger, explained(CLI::Range(1LL, kMaxDim), "dimensions must be in [1, 524285]")},
                   "expected NX,NY,NZ"))
               ->group("raw input");
  a.type =
      addValue(
          app, "--raw-type", "T", [&in](const std::string& s) { in.rawLayout.type = io::parseScalarType(s); },
          "its voxel type: uint8, int8, uint16, int16, uint32, int32, uint64, int64,\nfloat or double")
          ->check(parsedBy([](const std::string& s) { io::parseScalarType(s); }, "TYPE"))
          ->group("raw input");
  a.endian =
      addValue(
          app, "--raw-endian", "ORDER", [&in](const std::string& s) { in.rawLayout.bigEndian = s == "big"; },
          "its byte order: little (default) or big")
          ->check(explained(CLI::IsMember({"little", "big"}),
                            [](const std::string& s) { return "expected little or big, got '" + s + "'"; }))
          ->group("raw input");
  a.header =
      app.add_option("--raw-header", in.rawLayout.headerBytes, "bytes to skip at its start (default: 0)")
          ->option_text("BYTES")
          ->transform(kInteger)
          ->check(explained(CLI::Range(0LL, LLONG_MAX), "must not be negative"))
          ->group("raw input");
  addValue(
      app, "--spacing", "SX,SY,SZ", [&in](const std::string& s) { in.spacing = toTriple(s); },
      "the voxel spacing, instead of the file's")
      ->check(tripleOf({kNumber, explained(CLI::PositiveNumber, "every spacing must be positive")},
                       "expected three numbers X,Y,Z"))
      ->group("geometry override");
  addValue(
      app, "--origin", "OX,OY,OZ", [&in](const std::string& s) { in.origin = toTriple(s); },
      "the physical position of voxel (0,0,0), instead of the file's")
      ->check(tripleOf({kNumber}, "expected three numbers X,Y,Z"))
      ->group("geometry override");
  addValue(
      app, "--frame", "lps|ras", [&in](const std::string& s) { in.ras = s == "ras" || s == "RAS"; },
      "the frame of physical coordinates (outputs, --seed-point, --origin):\n"
      "lps (default: ITK's and DICOM's) or ras (nibabel's, MNI's: x and y negated)")
      ->check(explained(CLI::IsMember({"lps", "ras", "LPS", "RAS"}),
                        [](const std::string& s) { return "expected lps or ras, got '" + s + "'"; }))
      ->group("geometry override");
  app.add_option("--channel", in.channel,
                 "the channel to read, from 0, of a multi-channel TIFF stack\n(ImageJ or OME-TIFF) or a chunked store (default 0)")
      ->option_text("C")
      ->check(explained(CLI::Range(0, 1 << 30), [](const std::string& s) {
        return "expected a channel number from 0, got '" + s + "'";
      }))
      ->group("input and output");
  app.add_option("--level", in.level, "the resolution level of an OME-Zarr image, from 0 (default: 0, the finest)")
      ->option_text("L")
      ->check(explained(CLI::Range(0, 1 << 30), [](const std::string& s) {
        return "expected a level number from 0, got '" + s + "'";
      }))
      ->group("input and output");
  app.add_option("--time", in.time, "the time point to read, from 0, of a chunked store with a time axis (default 0)")
      ->option_text("T")
      ->check(explained(CLI::Range(0, 1 << 30), [](const std::string& s) {
        return "expected a time point from 0, got '" + s + "'";
      }))
      ->group("input and output");
  return a;
}

/// -a/--adjacency, --ascii and --threads, in the "surface options" group.
void addSurfaceOptions(CLI::App& app, AdjacencyPair& pair, bool& ascii, int& threads,
                       const std::string& threadsHelp) {
  addValue(
      app, "-a,--adjacency", "K-L", [&pair](const std::string& s) { pair = parseAdjacencyPair(s); },
      "26-6 (default), 18-6, 6-18 or 6-26: adjacency of inside-outside voxels")
      ->check(parsedBy([](const std::string& s) { parseAdjacencyPair(s); }, "K-L"))
      ->group("surface options");
  app.add_flag("--ascii", ascii, "text PLY / STL")->group("surface options");
  app.add_option("--threads", threads, threadsHelp)
      ->option_text("N")
      ->check(explained(CLI::Range(0, 1024), [](const std::string& s) {
        return "--threads takes a number of threads from 0 (all cores) to 1024, got '" + s + "'";
      }))
      ->group("surface options");
}

void addOutputOptions(CLI::App& app, OutputOptions& out) {
  app.add_flag("--json", out.json, "a JSON object on stdout instead of the summary")->group("output");
  app.add_flag("-q,--quiet", out.quiet, "print nothing but errors")->group("output");
}

void addInput(CLI::App& app, InputOptions& in) {
  app.add_option("INPUT", in.path,
                 ".nii .nii.gz .nrrd .nhdr .mha .mhd .dcm .tif .vtk, a directory with\n"
                 "one DICOM series, a zarr, OME-Zarr or N5 directory, or a raw file\n"
                 "with --raw-dims and --raw-type")
      ->type_name("")
      ->group("input and output");
}

void checkRaw(const InputOptions& in, const InputArgs& a) {
  const bool type = a.type->count() > 0, other = a.endian->count() > 0 || a.header->count() > 0;
  if ((type || other) && !in.raw)
    throw UsageError("--raw-type, --raw-endian and --raw-header need --raw-dims");
  if (in.raw && !type)
    throw UsageError(
        "a raw file needs --raw-type (uint8, int8, uint16, int16, uint32, int32, uint64, int64, float or "
        "double)");
}

/// --lods, --sharded, --shard-hash, --quantization-bits: the multi-resolution format's options.
void addPrecomputedOptions(CLI::App& app, PrecomputedOptions& p) {
  const std::string group = "Neuroglancer output";
  app.add_option("--lods", p.lods, "precomputed-multires: levels of detail, 1 to 10 (default 3); each a\n"
                 "closed oriented mesh of the label's genus, level k within 0.5 (2^k - 1)\nvoxels of level 0")
      ->option_text("N")
      ->check(CLI::Range(1, 10))
      ->group(group);
  app.add_flag("--sharded", p.sharded, "precomputed-multires: the sharded layout (a few .shard files)")->group(group);
  addValue(
      app, "--shard-hash", "H", [&p](const std::string& h) { p.identityHash = h == "identity"; },
      "--sharded: the hash of ids to shards, murmurhash3_x86_128 (default) or\n"
      "identity (consecutive ids share a minishard)")
      ->check(explained(CLI::IsMember({"murmurhash3_x86_128", "identity"}),
                        [](const std::string& s) {
                          return "expected murmurhash3_x86_128 or identity, got '" + s + "'";
                        }))
      ->group(group);
  app.add_option("--quantization-bits", p.quantizationBits, "precomputed-multires: 10 or 16 (default 16)")
      ->option_text("B")
      ->check(CLI::IsMember({10, 16}))
      ->group(group);
}

/// The options of the precomputed formats agree with --format and -o.
void checkPrecomputedOptions(const CLI::App& app, const std::string& format, const std::string& output) {
  const bool multires = format == "precomputed-multires";
  for (const char* name : {"--lods", "--sharded", "--shard-hash", "--quantization-bits"})
    if (app.get_option(name)->count() > 0 && !multires)
      throw UsageError(std::string(name) + " is for --format precomputed-multires");
  if (app.get_option("--shard-hash")->count() > 0 && app.get_option("--sharded")->count() == 0)
    throw UsageError("--shard-hash is for the sharded layout: add --sharded");
  if (!format.empty() && (output.find('{') != std::string::npos ||
                          (output.back() != '/' && !std::filesystem::path(output).extension().empty())))
    throw UsageError("--format " + format + " writes a directory: give -o DIR/, not '" + output + "'");
}

// --- parsing ---------------------------------------------------------------------------------

std::string oneLine(std::string message) {
  for (char& ch : message)
    if (ch == '\n' || ch == '\r') ch = ' ';
  return message;
}

void parse(CLI::App& app, const std::vector<std::string>& args) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    throw HelpRequested{app.help()};
  } catch (const CLI::ArgumentMismatch& e) {
    // Said as the tool always said it: a value given to a flag ("--json=1", which CLI11 reports
    // with the flag's name without dashes), no value after an option (CLI11: "--iso: 1
    // required TEXT missing").
    const std::string what = e.what();
    const auto endsWith = [&](const std::string& suffix) {
      return what.size() > suffix.size() &&
             what.compare(what.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    const std::string flagValue = " was given a disallowed flag override";
    if (endsWith(flagValue))
      throw UsageError("option --" + what.substr(0, what.size() - flagValue.size()) + " takes no value");
    const std::size_t colon = what.find(": ");
    if (endsWith(" missing") && colon != std::string::npos &&
        what.find(" required ", colon) != std::string::npos)
      throw UsageError("option " + what.substr(0, colon) + " needs a value");
    throw UsageError(oneLine(what));
  } catch (const CLI::ParseError& e) {
    throw UsageError(oneLine(e.what()));
  }
}

bool looksLikeOption(const std::string& s) {
  const bool numeric =
      s.size() > 1 && s[0] == '-' && (std::isdigit(static_cast<unsigned char>(s[1])) || s[1] == '.');
  return s.size() > 1 && s[0] == '-' && !numeric;
}

/// The first argument CLI11 did not take: an unknown option, or a positional the command does
/// not take (`positional` says what it does take). CLI11 also leaves there a "--" after which no
/// positional was expected.
void rejectExtras(const CLI::App& app, const std::string& command,
                  const std::string& positional = "one input volume only") {
  bool afterMark = false;
  for (const std::string& arg : app.remaining()) {
    if (arg == "--" && !afterMark) {
      afterMark = true;
      continue;
    }
    if (!afterMark && looksLikeOption(arg))
      throw UsageError("unknown option '" + (arg.rfind("--", 0) == 0 ? arg.substr(0, arg.find('=')) : arg) +
                       "' for 'surftrack " + command + "'");
    throw UsageError("unexpected argument '" + arg + "' (" + positional + ")");
  }
}

// --- the commands ----------------------------------------------------------------------------

const char* const kMeshSummary = "extract a surface and write it as a mesh";
const char* const kInfoSummary = "describe a volume: size, type, geometry, values";
const char* const kDemoSummary =
    "extract surfaces of a built-in phantom (and of the\nmricron-data MRI volumes when installed)";

/// --dask, --block, --work-dir (labels, and mesh --all): the block meshing of a chunked store.
void addDaskOptions(CLI::App& app, std::string& dask, std::string& block, std::string& workDir,
                    const std::string& group, const std::string& same) {
  app.add_option("--dask", dask, "local:N (N worker processes here) or a Dask scheduler's address\n"
                 "(tcp://host:8786): " + same + ", each\nblock meshed by a worker, no volume in one memory (docs/cli.md)")
      ->option_text("ADDRESS")
      ->group(group);
  app.add_option("--block", block, "the blocks' size in voxels (default 256,256,256)")
      ->option_text("BX,BY,BZ")
      ->check(tripleOf({kInteger, explained(CLI::Range(1LL, kMaxDim), "a block size is 1 to 524285 voxels")},
                       "expected three integers BX,BY,BZ"))
      ->group(group);
  app.add_option("--work-dir", workDir, "where the blocks' fragment files go, seen by every worker\n"
                 "(default: a temporary directory); kept, so that a run again resumes")
      ->option_text("DIR")
      ->group(group);
}

/// The --block of addDaskOptions, checked against --dask.
void parseDaskOptions(const std::string& dask, const std::string& blockText, const std::string& workDir,
                      std::array<int, 3>& block) {
  if (!blockText.empty()) {
    const auto parts = splitCommas(blockText);
    for (int k = 0; k < 3; ++k) block[std::size_t(k)] = int(*toInteger(parts[std::size_t(k)]));
  }
  if (dask.empty() && (!blockText.empty() || !workDir.empty()))
    throw UsageError("--block and --work-dir are for --dask");
}

struct MeshArgs {
  InputArgs input;
  std::vector<const CLI::Option*> seedRules;  ///< --seed, --seed-point, --largest, --all
  std::string block;                          ///< --block BX,BY,BZ
  CLI::Option* largest = nullptr;
  CLI::Option* all = nullptr;
  CLI::Option* mapping = nullptr;
};

MeshArgs defineMesh(CLI::App& app, MeshOptions& o, std::string& mapping) {
  configure(app);
  setUsage(app, "surftrack mesh INPUT -o OUTPUT [options]");
  app.description(
      "Tracks one boundary between the 1-voxels and the 0-voxels of INPUT and writes it as a\n"
      "closed triangle mesh.");
  MeshArgs a;
  addInput(app, o.input);
  app.add_option("-o,--output", o.output,
                 ".ply (binary unless --ascii), .obj, .off, .stl; vertices in physical\ncoordinates; "
                 "with --all, DIR/: one PLY per boundary, DIR/boundary_<k>.ply\n(largest first), and "
                 "DIR/boundaries.csv")
      ->option_text("OUTPUT")
      ->group("input and output");
  app.add_option("--cache", o.cacheMiB, "a chunked store read lazily (a seed rule with --iso or --label):\n"
                 "the decoded chunks kept in memory, in MiB (default 512)")
      ->option_text("MIB")
      ->check(CLI::Range(1, 1 << 20))
      ->group("input and output");
  app.add_option("--format", o.format, "precomputed or precomputed-multires: write -o DIR/ as a Neuroglancer\n"
                 "mesh directory holding the surface as segment --id (docs/cli.md,\n\"Neuroglancer output\")")
      ->option_text("F")
      ->check(CLI::IsMember({"precomputed", "precomputed-multires"}))
      ->group("Neuroglancer output");
  app.add_option("--unit", o.unit, "the unit of the volume's spacing, for --format: nm, um, mm, cm, m\n"
                 "(default: the unit the file states; mm for medical formats)")
      ->option_text("U")
      ->check(CLI::IsMember({"nm", "um", "µm", "mm", "cm", "m"}))
      ->group("Neuroglancer output");
  addValue(app, "--id", "N", [&o](const std::string& s) { o.id = *toLabel(s); },
           "the segment id of the surface, for --format (default 1)")
      ->check(kLabel)
      ->group("Neuroglancer output");
  addPrecomputedOptions(app, o.precomputed);

  addValue(
      app, "--iso", "S", [&o](const std::string& s) { o.surface.iso = toNumber(s); },
      "voxels with value > S (default: Otsu's threshold of the histogram)")
      ->check(kNumber)
      ->group("what is inside (1-voxels)");
  addValue(
      app, "--label", "L", [&o](const std::string& s) { o.surface.label = toLabel(s); },
      "voxels with value = L (an integer, exact up to 64 bits)")
      ->check(kLabel)
      ->group("what is inside (1-voxels)");

  const std::string which = "which surface (one of)";
  a.largest =
      app.add_flag("--largest")->description("the boundary with the most surfels (default)")->group(which);
  a.all = app.add_flag("--all")->description("every boundary, in one mesh")->group(which);
  CLI::Option* seed = addValue(
                          app, "--seed", "x,y,z[,DIR]",
                          [&o](const std::string& s) {
                            const auto parts = splitCommas(s);
                            o.surface.seedVoxel = Voxel{int(*toInteger(parts[0])), int(*toInteger(parts[1])),
                                                        int(*toInteger(parts[2]))};
                            o.surface.seedMode = SeedMode::Voxel;
                            if (parts.size() == 4) {
                              o.surface.seedMode = SeedMode::Surfel;
                              o.surface.seedDirection = *parseDirection(parts[3]);
                            }
                          },
                          "voxel x,y,z: the boundary of the surfel nearest the voxel's centre\n"
                          "(its own face if it is on a boundary); the surfel and its distance are\n"
                          "printed. x,y,z,DIR: the boundary of surfel (c=(x,y,z), d=c+DIR), DIR one\n"
                          "of +x -x +y -y +z -z")
                          ->check(kSeed)
                          ->group(which);
  CLI::Option* seedRay = addValue(
                             app, "--seed-ray", "x,y,z",
                             [&o](const std::string& s) {
                               const auto parts = splitCommas(s);
                               o.surface.seedVoxel = Voxel{int(*toInteger(parts[0])), int(*toInteger(parts[1])),
                                                           int(*toInteger(parts[2]))};
                               o.surface.seedMode = SeedMode::Ray;
                             },
                             "the boundary first met walking from voxel x,y,z along +x (then -x,\n"
                             "+y, -y, +z, -z)")
                             ->check(tripleOf({kInteger}, "expected three integers x,y,z"))
                             ->group(which);
  CLI::Option* seedPoint = addValue(
                               app, "--seed-point", "X,Y,Z",
                               [&o](const std::string& s) {
                                 o.surface.seedPoint = toTriple(s);
                                 o.surface.seedMode = SeedMode::Point;
                               },
                               "the boundary of the surfel nearest a physical point (as VTK's\n"
                               "closest-point region)")
                               ->check(tripleOf({kNumber}, "expected three numbers X,Y,Z"))
                               ->group(which);
  a.seedRules = {seed, seedRay, seedPoint, a.largest, a.all};
  addValue(
      app, "--max-seed-distance", "D", [&o](const std::string& s) { o.surface.maxSeedDistance = *toNumber(s); },
      "--seed x,y,z and --seed-point: the nearest surfel within D voxels\n(of the smallest spacing), "
      "else an error (default: 256)")
      ->check(explained(kNumber & CLI::PositiveNumber, "--max-seed-distance takes a positive number of voxels"))
      ->group("surface options");

  addSurfaceOptions(app, o.surface.pair, o.ascii, o.surface.threads,
                    "threads for the scan of --largest / --all and for --smooth\n"
                    "(default 0: all cores); the mesh is the same for any number");
  a.mapping = app.add_option("--mapping", mapping,
                             "linear (default with --iso: vertices at the interpolated iso-value)\n"
                             "or midpoint (vertices halfway between the two voxels)")
                  ->option_text("M")
                  ->transform(CLI::Transformer(std::map<std::string, std::string>{{"iso", "linear"}}))
                  ->check(explained(
                      CLI::IsMember({"midpoint", "linear"}),
                      [](const std::string& s) { return "expected midpoint or linear, got '" + s + "'"; }))
                  ->group("surface options");
  const std::string refine = "smoothing and decimation (after extraction)";
  app.add_option("--smooth", o.surface.refine.smoothIterations,
                 "Taubin lambda|mu smoothing, N iterations (default 20), every vertex\nkept on its "
                 "surfel's segment: same voxels inside, same topology")
      ->option_text("[N]")
      ->expected(0, 1)
      ->default_str("20")
      ->check(explained(CLI::Range(1, kMaxSmoothIterations), [](const std::string& s) {
        return "--smooth takes a number of iterations from 1 to " + std::to_string(kMaxSmoothIterations) +
               ", got '" + s + "'";
      }))
      ->group(refine);
  addValue(
      app, "--max-error", "E", [&o](const std::string& s) { o.surface.refine.maxError = *toNumber(s); },
      "decimate, keeping the surface within E (physical units) of the\nundecimated one; topology kept")
      ->check(explained(CLI::PositiveNumber, "--max-error takes a positive distance"))
      ->group(refine);
  addValue(
      app, "--reduce", "F", [&o](const std::string& s) { o.surface.refine.reduction = *toNumber(s); },
      "decimate, removing the fraction F in [0, 1) of the triangles (as far as\n--max-error and "
      "the topology allow)")
      ->check(explained(CLI::Range(0.0, 0.999999), [](const std::string& s) {
        return "--reduce takes a fraction in [0, 1), got '" + s + "'";
      }))
      ->group(refine);

  addDaskOptions(app, o.dask, a.block, o.workDir, "by blocks on Dask (a chunked store, --all --iso S)",
                 "the same file as the single pass");
  a.input = addInputOptions(app, o.input);
  addOutputOptions(app, o.out);
  addHelp(app);
  return a;
}

void defineInfo(CLI::App& app, InfoOptions& o, InputArgs& a) {
  configure(app);
  setUsage(app, "surftrack info INPUT [options]");
  app.description(
      "Prints the size, voxel type, spacing, origin, direction, value range, a histogram summary,\n"
      "Otsu's threshold (the default --iso of 'surftrack mesh') and, for integer images with few\n"
      "values, the labels present.");
  addInput(app, o.input);
  a = addInputOptions(app, o.input);
  addOutputOptions(app, o.out);
  addHelp(app);
}

void defineDemo(CLI::App& app, DemoOptions& o) {
  configure(app);
  setUsage(app, "surftrack demo [options]");
  app.description(
      "Builds a phantom (a sphere minus three orthogonal cylinders, Q^3 voxels, with P salt-and-\n"
      "pepper noise), tracks the surface of its seed and writes DIR/phantom.nrrd and DIR/phantom.ply.\n"
      "With the Debian package mricron-data installed, it also extracts the cortical surface of\n"
      "ch2better.nii.gz and one label of the aal.nii.gz atlas.");
  const std::string group = "options";
  app.add_option("-o,--output", o.outputDir, "the output directory (default: surftrack-demo)")
      ->option_text("DIR")
      ->group(group);
  app.add_option("--size", o.size, "the phantom side, 16 to 1024 (default: 128)")
      ->option_text("Q")
      ->transform(kInteger)
      ->check(explained(CLI::Range(16, 1024), "the phantom side must be in [16, 1024]"))
      ->group(group);
  addValue(
      app, "--noise", "P", [&o](const std::string& s) { o.noise = *toNumber(s); },
      "the salt-and-pepper noise probability, 0 to 0.5 (default: 0.01)")
      ->check(kNumber)
      ->check(explained(CLI::Range(0.0, 0.5), "the noise probability must be in [0, 0.5]"))
      ->group(group);
  app.add_flag_callback(
         "--no-mricron", [&o] { o.realData = false; }, "skip the MRI part")
      ->group(group);
  app.add_option("--mricron-dir", o.mricronDir,
                 "where mricron-data's volumes are\n(default: " + o.mricronDir + ")")
      ->option_text("DIR")
      ->group(group);
  addOutputOptions(app, o.out);
  addHelp(app);
}

const char* const kLabelsSummary = "every label of a label image as a closed surface";

/// --labels: "3,17,42" or one range "10-20" / "10..20".
void parseLabelList(const std::string& text, LabelsOptions& o) {
  const auto parts = splitCommas(text);
  for (const std::string& part : parts) {
    std::size_t dash = part.find("..");
    std::size_t skip = 2;
    if (dash == std::string::npos && part.size() > 1) {
      dash = part.find('-', 1);
      skip = 1;
    }
    if (dash != std::string::npos) {
      const auto a = toLabel(part.substr(0, dash)), b = toLabel(part.substr(dash + skip));
      if (!a || !b) throw UsageError("--labels: '" + part + "' is not a range A-B of integers");
      if (*a > *b) throw UsageError("--labels: the range '" + part + "' is empty");
      if (parts.size() > 1) throw UsageError("--labels: give a list of labels or one range, not both");
      o.range = std::array<LabelValue, 2>{*a, *b};
    } else {
      const auto v = toLabel(part);
      if (!v) throw UsageError("--labels: '" + part + "' is not an integer label");
      o.labels.push_back(*v);
    }
  }
}

/// The values of `labels` checked after parsing.
struct LabelsArgs {
  std::string labels;               ///< --labels, parsed by parseLabelList
  std::vector<std::string> seeds;   ///< --seed, each x,y,z
  std::string block;                ///< --block BX,BY,BZ
  InputArgs input;
};

void defineLabels(CLI::App& app, LabelsOptions& o, LabelsArgs& args) {
  configure(app);
  setUsage(app, "surftrack labels INPUT -o OUTPUT [options]");
  app.description(
      "Extracts every boundary of every label of an integer label image (an atlas, a\n"
      "segmentation) as closed triangle meshes, in one pass; neighbouring labels share their\n"
      "interface vertices exactly (midpoint mapping).");
  addInput(app, o.input);
  app.add_option("-o,--output", o.output,
                 "DIR/: one file per label, DIR/{label}_{name}.ply (DIR must not exist or\n"
                 "be empty); a pattern with {label} and {name} (any of .ply .obj .off .stl);\n"
                 "or FILE.ply: every label in one PLY with a label property per face and\n"
                 "per vertex. Outputs are written completely or not at all")
      ->option_text("OUTPUT")
      ->group("input and output");
  app.add_option("--table", o.table, "a table of one row per label (.csv or .json): voxels, surfels,\n"
                 "boundaries, Euler characteristic, genus, area, volume (physical units)")
      ->option_text("FILE")
      ->group("input and output");
  app.add_option("--format", o.format, "precomputed: write -o DIR/ as a Neuroglancer precomputed mesh\n"
                 "directory (legacy format, nanometres; docs/cli.md, \"Neuroglancer output\");\n"
                 "precomputed-multires: Neuroglancer's multi-resolution format (Draco\n"
                 "fragments, --lods levels of detail, --sharded)")
      ->option_text("F")
      ->check(CLI::IsMember({"precomputed", "precomputed-multires"}))
      ->group("input and output");
  addPrecomputedOptions(app, o.precomputed);
  app.add_option("--unit", o.unit, "the unit of the volume's spacing, for --format precomputed: nm, um,\n"
                 "mm, cm, m (default: the unit the file states; mm for NIfTI, NRRD,\n"
                 "MetaImage and DICOM, as ITK reads them)")
      ->option_text("U")
      ->check(CLI::IsMember({"nm", "um", "µm", "mm", "cm", "m"}))
      ->group("input and output");
  const std::string which = "which labels and boundaries";
  app.add_option("--labels", args.labels, "labels 3,17,42 or a range 10-20 (default: every label)")
      ->option_text("LIST")
      ->group(which);
  addValue(app, "--background", "L", [&o](const std::string& s) { o.background = *toLabel(s); },
           "the label of no surface (default: 0)")
      ->check(kLabel)
      ->group(which);
  app.add_flag("--largest", o.largest, "only the largest boundary of each label (default: all)")->group(which);
  app.add_option("--seed", args.seeds, "only the boundaries reached from voxel x,y,z (walking +x to its\n"
                 "label's boundary); repeat for several")
      ->option_text("x,y,z")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(tripleOf({kInteger, kSeedCoordinate}, "expected three integers x,y,z"))
      ->group(which);
  app.add_option("--label-names", o.labelNames, "a text file of lines 'value name' (default: the atlas's\n"
                 "sidecar, aal.nii.txt for aal.nii.gz, when there is one)")
      ->option_text("FILE")
      ->group(which);
  app.add_flag("--no-label-names", o.noNames, "ignore the sidecar names")->group(which);
  app.add_option("--walls", o.walls, "shared (default): one conforming complex, walls shared triangle for\n"
                 "triangle (docs/theory.md); independent: each label against the rest\n"
                 "(the default with --dask, --largest, --seed, --adjacency 18-6 or 6-18)")
      ->option_text("W")
      ->check(CLI::IsMember({"independent", "shared"}))
      ->group(which);
  app.add_option("--smooth", o.smoothIterations,
                 "with --walls shared: Taubin lambda|mu smoothing of the whole complex,\nN iterations (default " +
                     std::to_string(kLabelSmoothIterations) +
                     "), every vertex moved once, on its surfel's\nsegment: walls still shared, same voxels, same "
                     "topology")
      ->option_text("[N]")
      ->expected(0, 1)
      ->default_str(std::to_string(kLabelSmoothIterations))
      ->check(explained(CLI::Range(1, kMaxSmoothIterations), [](const std::string& s) {
        return "--smooth takes a number of iterations from 1 to " + std::to_string(kMaxSmoothIterations) +
               ", got '" + s + "'";
      }))
      ->group(which);
  addValue(
      app, "--max-error", "E", [&o](const std::string& s) { o.maxError = *toNumber(s); },
      "with --walls shared: decimate the complex, each wall once, within E\n(physical units) of the "
      "undecimated walls; walls and junction lines still shared,\neach label's topology kept")
      ->check(explained(CLI::PositiveNumber, "--max-error takes a positive distance"))
      ->group(which);
  addValue(
      app, "--reduce", "F", [&o](const std::string& s) { o.reduction = *toNumber(s); },
      "with --walls shared: decimate the complex, removing the fraction F in\n[0, 1) of each wall's "
      "triangles (as far as --max-error and the topology allow)")
      ->check(explained(CLI::Range(0.0, 0.999999), [](const std::string& s) {
        return "--reduce takes a fraction in [0, 1), got '" + s + "'";
      }))
      ->group(which);
  addDaskOptions(app, o.dask, args.block, o.workDir, "by blocks on Dask (a chunked store, -o DIR/)",
                 "the same files and table as the single pass");
  addValue(app, "--merge-budget", "B", [&o](const std::string& s) { o.mergeBudget = *toByteCount(s); },
           "with --dask: a label whose fragments take more than B bytes (512M,\n"
           "2G) is not merged whole: its figures come from a tree of groups of\n"
           "blocks, its mesh is streamed (docs/cli.md)")
      ->check(kByteCount)
      ->group("by blocks on Dask (a chunked store, -o DIR/)");
  addSurfaceOptions(app, o.pair, o.ascii, o.threads,
                    "threads for the scan and the labels (default 0: all cores);\n"
                    "the meshes are the same for any number");
  args.input = addInputOptions(app, o.input);
  addOutputOptions(app, o.out);
  addHelp(app);
}

void defineMain(CLI::App& app) {
  setUsage(app, "surftrack COMMAND [ARGS]");
  app.description(
      "Extracts ONE connected iso-surface from a 3D image by tracking its digital boundary\n"
      "(Lachaud & Montanvert, \"Continuous analogs of digital boundaries\").");
  app.add_subcommand("mesh", kMeshSummary);
  app.add_subcommand("info", kInfoSummary);
  app.add_subcommand("labels", kLabelsSummary);
  app.add_subcommand("demo", kDemoSummary);
  app.add_flag("--version")->description("print the version and exit")->group("options");
  app.set_help_flag("-h,--help", "print this help and exit")->group("options");
  app.footer("Run 'surftrack COMMAND --help' for the options of a command.");
}

}  // namespace

std::string directionName(Direction d) {
  static const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  return d < 6 ? names[d] : "?";
}

MeshOptions parseMeshOptions(const std::vector<std::string>& args) {
  MeshOptions o;
  std::string mapping;
  CLI::App app;
  const MeshArgs a = defineMesh(app, o, mapping);
  parse(app, args);
  rejectExtras(app, "mesh");

  std::vector<std::string> rules;
  for (const CLI::Option* opt : app.parse_order())
    if (std::find(a.seedRules.begin(), a.seedRules.end(), opt) != a.seedRules.end())
      rules.push_back(opt->get_name());
  if (rules.size() > 1)
    throw UsageError("give only one of --seed, --seed-ray, --seed-point, --largest, --all (got " + rules[0] + " and " +
                     rules[1] + ")");
  if (a.largest->count()) o.surface.seedMode = SeedMode::Largest;
  if (a.all->count()) o.surface.seedMode = SeedMode::All;
  if (a.mapping->count())
    o.surface.mapping = mapping == "midpoint" ? MappingMode::Midpoint : MappingMode::Linear;

  if (o.input.path.empty()) throw UsageError("missing the input volume: surftrack mesh INPUT -o OUTPUT");
  if (o.output.empty()) throw UsageError("missing the output mesh: -o OUTPUT (.ply, .obj, .off or .stl)");
  if (o.surface.iso && o.surface.label) throw UsageError("give --iso or --label, not both");
  if (o.surface.label && o.surface.mapping == MappingMode::Linear)
    throw UsageError("--mapping linear interpolates an iso-value: it needs --iso, not --label");
  if (o.format.empty() && (!o.unit.empty() || app.get_option("--id")->count() > 0))
    throw UsageError("--unit and --id are for --format precomputed or precomputed-multires");
  if (o.id.negative() || o.id == LabelValue(0))
    throw UsageError("--id " + o.id.text() + ": Neuroglancer's segment ids are positive uint64 values");
  checkPrecomputedOptions(app, o.format, o.output);
  parseDaskOptions(o.dask, a.block, o.workDir, o.block);
  if (!o.dask.empty() && (o.surface.seedMode != SeedMode::All || !o.surface.iso || o.surface.refine.smoothIterations > 0 ||
                          o.surface.refine.maxError || o.surface.refine.reduction))
    throw UsageError("--dask meshes every boundary of a threshold: give --all and --iso S (not --label, a seed "
                     "rule, Otsu's default, --smooth or decimation)");
  if (!o.dask.empty() && !o.format.empty()) throw UsageError("--dask writes one mesh file: not with --format");
  checkRaw(o.input, a.input);
  return o;
}

InfoOptions parseInfoOptions(const std::vector<std::string>& args) {
  InfoOptions o;
  InputArgs a;
  CLI::App app;
  defineInfo(app, o, a);
  parse(app, args);
  rejectExtras(app, "info");
  if (o.input.path.empty()) throw UsageError("missing the input volume: surftrack info INPUT");
  checkRaw(o.input, a);
  return o;
}

DemoOptions parseDemoOptions(const std::vector<std::string>& args) {
  DemoOptions o;
  CLI::App app;
  defineDemo(app, o);
  parse(app, args);
  rejectExtras(app, "demo", "the demo reads no input");
  return o;
}

LabelsOptions parseLabelsOptions(const std::vector<std::string>& args) {
  LabelsOptions o;
  LabelsArgs a;
  CLI::App app;
  defineLabels(app, o, a);
  parse(app, args);
  rejectExtras(app, "labels");
  if (o.input.path.empty()) throw UsageError("missing the input volume: surftrack labels INPUT -o OUTPUT");
  if (o.output.empty())
    throw UsageError("missing the output: -o DIR/, -o a pattern with {label} or {name}, or -o FILE.ply");
  if (!a.labels.empty()) parseLabelList(a.labels, o);
  for (const std::string& s : a.seeds) {
    const auto parts = splitCommas(s);
    o.seeds.push_back(Voxel{int(*toInteger(parts[0])), int(*toInteger(parts[1])), int(*toInteger(parts[2]))});
  }
  if (o.largest && !o.seeds.empty()) throw UsageError("give --largest or --seed, not both");
  parseDaskOptions(o.dask, a.block, o.workDir, o.block);
  if (!o.dask.empty() && (o.largest || !o.seeds.empty() || !o.labels.empty() || o.range))
    throw UsageError("--dask meshes every boundary of every label into -o DIR/: not with --labels, --largest "
                     "or --seed yet");
  if (o.smoothIterations > 0 && !o.dask.empty()) throw UsageError("--smooth is not made by blocks: no --dask");
  if ((o.maxError || o.reduction) && !o.dask.empty())
    throw UsageError("--max-error and --reduce are not made by blocks: no --dask");
  if (o.walls.empty())
    o.walls = defaultLabelWalls(o.dask.empty() && !o.largest && o.seeds.empty(), o.pair,
                                o.smoothIterations > 0 || o.maxError || o.reduction) == LabelWalls::Shared
                  ? "shared"
                  : "independent";
  if (o.smoothIterations > 0 && o.walls != "shared")
    throw UsageError("--smooth on labels needs --walls shared: each label smoothed on its own would pull the "
                     "vertices it shares with its neighbours apart");
  if (o.mergeBudget && o.dask.empty()) throw UsageError("--merge-budget is for --dask (the single pass merges nothing)");
  if (o.mergeBudget && !o.format.empty())
    throw UsageError("--merge-budget is for mesh files: not with --format (Neuroglancer's formats hold every label's "
                     "mesh)");
  if ((o.maxError || o.reduction) && o.walls != "shared")
    throw UsageError("--max-error and --reduce on labels need --walls shared: each label decimated on its own "
                     "would no longer share its walls with its neighbours");
  if (o.noNames && !o.labelNames.empty()) throw UsageError("give --label-names or --no-label-names, not both");
  if (!o.unit.empty() && o.format.empty()) throw UsageError("--unit is for --format precomputed or precomputed-multires");
  checkPrecomputedOptions(app, o.format, o.output);
  checkRaw(o.input, a.input);
  return o;
}

std::string mainUsage() {
  CLI::App app;
  defineMain(app);
  return app.help();
}

std::string meshUsage() {
  MeshOptions o;
  std::string mapping;
  CLI::App app;
  defineMesh(app, o, mapping);
  return app.help();
}

std::string infoUsage() {
  InfoOptions o;
  InputArgs a;
  CLI::App app;
  defineInfo(app, o, a);
  return app.help();
}

std::string demoUsage() {
  DemoOptions o;
  CLI::App app;
  defineDemo(app, o);
  return app.help();
}

}  // namespace surftrack::cli
