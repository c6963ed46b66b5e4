// The tool's pipeline on a volume in memory: choose the 1-voxels (iso-value or label), resolve
// the seed rule to a boundary surfel, track its kappa-lambda-boundary, convert it to a mesh
// placed in physical coordinates — or scan every boundary (--all). Records what it did, for
// the summary: the seed actually used, counts, timings per stage.
#pragma once

#include <array>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "ChunkedStore.h"
#include "MeshStats.h"
#include "Options.h"
#include "Progress.h"
#include "LoadVolume.h"
#include "ReadVolume.h"
#include "Extract.h"
#include "Refine.h"
#include "SurfaceMesh.h"
#include "VolumeView.h"

namespace surftrack::cli {

struct StageTiming {
  std::string name;
  double seconds = 0;
};

/// Measures stages one after the other.
class StageClock {
 public:
  StageClock() : last_(std::chrono::steady_clock::now()), start_(last_) {}
  /// Ends the running stage, records it as `name`.
  void lap(std::vector<StageTiming>& out, const std::string& name) {
    const auto now = std::chrono::steady_clock::now();
    out.push_back({name, std::chrono::duration<double>(now - last_).count()});
    last_ = now;
  }
  /// Starts the next stage now, without recording the time since the last lap.
  void skip() { last_ = std::chrono::steady_clock::now(); }
  double total() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point last_, start_;
};

/// Everything the summary reports about one extraction.
struct Extraction {
  // The input.
  std::string input;
  Dims dims;
  io::ScalarType type = io::ScalarType::UInt8;
  ImageGeometry geometry;
  /// The data range, when it was computed (Otsu's default); a seeded extraction never reads
  /// every voxel to find it.
  std::optional<std::array<double, 2>> dataRange;
  /// How the voxels are held: memory-mapped from the file (read on demand) or decoded once.
  std::string storage;            ///< "memory-mapped mha", "loaded nii.gz", "in memory", ...
  /// A chunked store read lazily: the chunks in the array, and what the cache did.
  std::uint64_t chunkCount = 0;
  std::optional<ChunkCacheCounters> chunks;
  bool mapped = false;            ///< memory-mapped: only the pages the engine touches are read
  std::string decodeReason;       ///< why the file was loaded whole rather than mapped
  std::uintmax_t voxelBytes = 0;  ///< nx ny nz sizeof(type)
  /// Bytes of voxels read: all of them when loaded whole; when mapped, those the engine asked
  /// for (Surface::voxelsRead, at most voxelBytes).
  std::uintmax_t voxelBytesRead = 0;
  /// Mapped: bytes of the file's voxels in memory after the extraction (the kernel reads whole
  /// pages and reads ahead; pages cached by earlier readers count too).
  std::optional<std::uintmax_t> voxelBytesResident;

  // The binary image and the surface options.
  std::string frame = "LPS";      ///< of the physical coordinates (LoadedVolume::frame)
  bool byLabel = false;
  double value = 0;               ///< the iso-value
  LabelValue label;               ///< the label (byLabel)
  bool valueFromOtsu = false;     ///< no --iso / --label: Otsu's threshold was used
  AdjacencyPair pair = AdjacencyPair::k26_6;
  std::string mapping;            ///< "linear" or "midpoint"

  // The seed.
  SeedMode seedMode = SeedMode::Largest;
  std::optional<std::array<double, 3>> seedPoint;  ///< --seed-point, physical
  std::optional<Voxel> seedVoxel;                  ///< --seed, or the voxel of --seed-point
  bool seedVoxelInside = false;                    ///< the seed voxel is a 1-voxel
  std::optional<double> seedDistance;              ///< nearest-surfel rule: physical distance
  std::optional<Direction> walkDirection;          ///< the ray that found the surfel
  int walkSteps = 0;                               ///< voxels walked along it
  std::optional<Surfel> seedSurfel;                ///< the surfel tracking started from
  std::size_t boundaries = 0;                      ///< --largest / --all: boundaries in the image

  // The result.
  std::vector<std::string> warnings;  ///< printed on stderr (e.g. a speck)
  std::size_t surfels = 0;
  std::optional<SmoothReport> smooth;      ///< --smooth
  std::optional<DecimateReport> decimate;  ///< --max-error / --reduce
  double extractedVolume = 0;              ///< enclosed volume before smoothing and decimation
  Surface surface;  ///< the mesh written: vertices, oriented triangles, surfels
  MeshStats stats;
  std::vector<StageTiming> timings;
  double totalSeconds = 0;

  // The output file.
  std::string output;
  std::string format;  ///< "ply", "obj", "off", "stl"
  bool binary = false;
  std::uintmax_t bytes = 0;
};

/// The progress stages extractSurface reports: values, the core's stages, smooth and decimate
/// when asked, mesh.
int extractionStages(const SurfaceOptions& options);

/// Runs the pipeline on `volume` (already read; `extraction` holds the input fields and the
/// "read" timing) up to the mesh and its statistics, through the front door (Extract.h);
/// reports progress stages stage .. stage + extractionStages(options) - 1 of stageCount. Throws std::runtime_error with a one-line
/// message for an iso-value outside the data range, a label absent from the image, a seed
/// outside the domain or on no boundary, an empty selection.
void extractSurface(const VolumeView& volume, const SurfaceOptions& options,
                    Extraction& extraction, StageClock& clock, Progress& progress,
                    int stageOffset, int stageCount);
/// The same through any source; `whole` the view of every voxel, or null for a source read
/// lazily (a chunked store): then only seeded extractions with --iso or --label.
void extractSurface(const VoxelSource& source, const VolumeView* whole, const SurfaceOptions& options,
                    Extraction& extraction, StageClock& clock, Progress& progress,
                    int stageOffset, int stageCount);

/// Whether the input is a chunked store (zarr, OME-Zarr, N5); --level and --time are refused
/// for any other input.
bool isChunkedInput(const InputOptions& input);
/// Why a chunked store is not decoded whole (its voxels take more than half the machine's
/// memory; the message names what reads it in parts instead), or nothing when it may be.
std::optional<std::string> wholeReadRefusal(const io::ChunkedStore& store, const std::string& path);
/// The level, channel and time to read in a chunked store.
io::ChunkedStoreOptions chunkedStoreOptions(const InputOptions& input);
/// Applies --frame ras, --spacing and --origin to `geometry`; returns the frame.
std::string applyGeometryOptions(const InputOptions& input, ImageGeometry& geometry, const std::string& frame);

/// Fills the input fields of `extraction` from `volume`.
void describeInput(const io::LoadedVolume& volume, const std::string& path, Extraction& extraction);

/// Loads the volume of `input` (memory-mapped when it can be, else decoded once; raw files by
/// their stated layout) and applies the geometry overrides.
io::LoadedVolume readInput(const InputOptions& input);

/// A volume in memory (the demo's phantom, the MRI it reads) as a loaded one, without a copy:
/// the result refers to `volume`, which must outlive it.
io::LoadedVolume inMemory(const io::AnyVolume& volume);

}  // namespace surftrack::cli
