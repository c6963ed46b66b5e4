// Command-line arguments of the `surftrack` tool: what each subcommand accepts, parsed into
// plain structs. Any malformed command line throws UsageError (exit status 2).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "AdjacencyPair.h"
#include "LabelValue.h"
#include "ReadVolume.h"
#include "Surfel.h"

namespace surftrack::cli {

/// A malformed command line: the tool prints the message and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// --help: main prints `text` on stdout and exits with status 0.
struct HelpRequested {
  std::string text;
};

/// How to read the input volume: with ITK, or as a raw file of a stated layout; optional
/// overrides of the geometry.
struct InputOptions {
  std::string path;
  bool raw = false;              ///< --raw-dims given: read a headerless raw file
  io::RawLayout rawLayout;       ///< --raw-dims, --raw-type, --raw-endian, --raw-header
  std::optional<std::array<double, 3>> spacing;  ///< --spacing
  std::optional<std::array<double, 3>> origin;   ///< --origin
  bool ras = false;  ///< --frame ras: physical coordinates in RAS (nibabel, MNI), not ITK's LPS
  std::optional<int> channel;                    ///< --channel C: of a multi-channel TIFF stack or a chunked store
  std::optional<int> level;                      ///< --level L: of an OME-Zarr image (io/ChunkedStore.h)
  std::optional<int> time;                       ///< --time T: of a chunked store with a time axis
};

enum class SeedMode { Largest, All, Voxel, Ray, Surfel, Point };
enum class MappingMode { Default, Midpoint, Linear };

/// Post-processing of the surface (docs/cli.md, "Smoothing and decimation").
struct RefineOptions {
  int smoothIterations = 0;             ///< --smooth [N] (20 without N); 0: no smoothing
  std::optional<double> maxError;       ///< --max-error E: decimate within E (physical units)
  std::optional<double> reduction;      ///< --reduce F: decimate F of the triangles away
  bool decimate() const { return maxError || reduction; }
};

/// What surface to extract: a threshold or a label, a seed rule, a pair, a mapping.
struct SurfaceOptions {
  std::optional<double> iso;     ///< --iso S: 1-voxels are f > S
  std::optional<LabelValue> label;  ///< --label L: 1-voxels are f = L (exact: 64-bit ids)
  SeedMode seedMode = SeedMode::Largest;
  Voxel seedVoxel;               ///< --seed x,y,z (Voxel), --seed-ray x,y,z (Ray) or the c of --seed x,y,z,DIR
  Direction seedDirection = 0;   ///< the DIR of --seed x,y,z,DIR (SeedMode::Surfel)
  std::array<double, 3> seedPoint{};  ///< --seed-point X,Y,Z (physical coordinates)
  double maxSeedDistance = 256;  ///< --max-seed-distance D: the nearest-surfel search's bound, in voxels
  AdjacencyPair pair = AdjacencyPair::k26_6;
  MappingMode mapping = MappingMode::Default;
  int threads = 0;               ///< --threads N (0: all cores)
  RefineOptions refine;          ///< --smooth, --max-error, --reduce
};

struct OutputOptions {
  bool json = false;   ///< --json: a JSON object on stdout instead of the summary
  bool quiet = false;  ///< --quiet: nothing on stdout or stderr but errors
};

/// The multi-resolution precomputed format's options (labels and mesh).
struct PrecomputedOptions {
  int lods = 3;             ///< --lods N: levels of detail
  bool sharded = false;     ///< --sharded
  bool identityHash = false;  ///< --shard-hash identity (default murmurhash3_x86_128)
  int quantizationBits = 16;  ///< --quantization-bits 10|16
};

struct MeshOptions {
  InputOptions input;
  SurfaceOptions surface;
  std::string output;   ///< -o: .ply, .obj, .off or .stl
  bool ascii = false;   ///< --ascii: text PLY / STL
  int cacheMiB = 512;   ///< --cache: decoded chunks kept when a chunked store is read lazily
  /// --format precomputed | precomputed-multires: -o DIR/ is a Neuroglancer mesh directory
  /// holding the surface as one segment, id --id (default 1).
  std::string format;
  std::string unit;        ///< --unit U (precomputed output)
  LabelValue id = 1;       ///< --id N
  PrecomputedOptions precomputed;
  /// --dask ADDRESS with --all: every boundary of a chunked store by blocks on Dask (as labels').
  std::string dask;
  std::array<int, 3> block{256, 256, 256};  ///< --block BX,BY,BZ (with --dask)
  std::string workDir;                      ///< --work-dir DIR (with --dask)
  OutputOptions out;
};

struct InfoOptions {
  InputOptions input;
  OutputOptions out;
};

struct DemoOptions {
  std::string outputDir = "surftrack-demo";  ///< -o DIR
  int size = 128;                            ///< --size Q: phantom side
  double noise = 0.01;                       ///< --noise P: salt-and-pepper probability
  bool realData = true;                      ///< --no-mricron turns the MRI part off
  std::string mricronDir = "/usr/share/mricron/templates";  ///< --mricron-dir
  OutputOptions out;
};

/// `surftrack labels`: every label's surface.
struct LabelsOptions {
  InputOptions input;
  /// -o: a directory (DIR/), a name pattern with {label} and/or {name}, or one .ply file.
  std::string output;
  std::vector<LabelValue> labels;                  ///< --labels 3,17,42
  std::optional<std::array<LabelValue, 2>> range;  ///< --labels 10-20 (or 10..20)
  LabelValue background = 0;                       ///< --background L
  std::string labelNames;                          ///< --label-names FILE
  bool noNames = false;                            ///< --no-label-names: ignore a sidecar
  bool largest = false;                            ///< --largest
  std::vector<Voxel> seeds;                        ///< --seed x,y,z (repeatable)
  AdjacencyPair pair = AdjacencyPair::k26_6;
  /// --walls independent|shared; empty until parsed, then shared unless it is not made for the
  /// other options (--dask, --largest, --seed, --adjacency 18-6 or 6-18), then independent.
  std::string walls;
  int smoothIterations = 0;                        ///< --smooth [N] (shared walls): 0 none
  std::optional<double> maxError;                  ///< --max-error E (shared walls): decimation
  std::optional<double> reduction;                 ///< --reduce F (shared walls): decimation
  int threads = 0;
  bool ascii = false;
  std::string table;  ///< --table FILE.csv | FILE.json
  /// --format precomputed: -o DIR/ is a Neuroglancer precomputed mesh directory (legacy format)
  /// instead of one mesh file per label; precomputed-multires: the multi-resolution format.
  std::string format;
  std::string unit;   ///< --unit U: the physical unit of the volume's spacing (precomputed output)
  PrecomputedOptions precomputed;
  /// --dask ADDRESS: a chunked store meshed by blocks on Dask (cli/DaskLabels.h): "local:N" or a
  /// scheduler's address ("tcp://host:8786"); empty: the single pass.
  std::string dask;
  std::array<int, 3> block{256, 256, 256};  ///< --block BX,BY,BZ (with --dask)
  std::string workDir;                      ///< --work-dir DIR (with --dask): fragments kept, a run resumes
  /// --merge-budget B (with --dask): the fragment bytes of a label merged whole at most
  /// (surftrack.distributed.write_label_meshes' merge_budget); none: no limit.
  std::optional<std::uint64_t> mergeBudget;
  OutputOptions out;
};

MeshOptions parseMeshOptions(const std::vector<std::string>& args);
InfoOptions parseInfoOptions(const std::vector<std::string>& args);
DemoOptions parseDemoOptions(const std::vector<std::string>& args);
LabelsOptions parseLabelsOptions(const std::vector<std::string>& args);

/// "+x", "-x", "+y", "-y", "+z", "-z".
std::string directionName(Direction d);

/// The help texts.
std::string mainUsage();
std::string meshUsage();
std::string infoUsage();
std::string demoUsage();

}  // namespace surftrack::cli
