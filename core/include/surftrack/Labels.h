// Label maps (docs/api.md, "Label maps"; docs/theory.md, "Label maps"): the surfaces of every
// label of an integer label image in one call.
//
//   surftrack::LabelOptions options;                       // every label but 0, every boundary
//   std::vector<surftrack::LabelSurface> surfaces =
//       surftrack::extractLabels(surftrack::VolumeView::of(labels, dims, geometry), options);
//
// For label L the 1-voxels are f = L (paper §3.1). One scan of the rows finds, for every label,
// its voxel count and seeds on each of its boundaries (tracker/LabelSeeds.h); then each
// label's boundaries are tracked (§4.3, §5.2) and converted, labels in parallel. Vertices are
// placed by the midpoint mapping, so where label A touches label B the surfel between an
// A-voxel and a B-voxel is a vertex of both meshes at the same point.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "AdjacencyPair.h"
#include "Extract.h"
#include "LabelValue.h"
#include "Refine.h"
#include "VolumeView.h"
#include "Voxel.h"

namespace surftrack {

/// Which labels to extract. The background label is never extracted.
struct LabelSelection {
  enum class Kind {
    All,    ///< every label of the image
    List,   ///< these labels; each must occur in the image
    Range   ///< the labels of the image in [first, last]; at least one must occur
  };
  Kind kind = Kind::All;
  std::vector<LabelValue> labels;  ///< List
  LabelValue first, last;          ///< Range, inclusive

  static LabelSelection all() { return {}; }
  static LabelSelection list(std::vector<LabelValue> labels) { return {Kind::List, std::move(labels), {}, {}}; }
  static LabelSelection range(LabelValue first, LabelValue last) { return {Kind::Range, {}, first, last}; }
};

/// Which boundaries of each label to extract, when LabelOptions::seeds is empty (seeds select
/// their own boundaries).
enum class LabelBoundaries {
  All,     ///< every boundary of the label
  Largest  ///< the boundary with the most surfels (ties: the first met by the scan)
};

/// How touching labels' surfaces relate (docs/theory.md, "Shared walls").
enum class LabelWalls {
  /// Each label against everything else with the pair's rule: touching labels share their wall
  /// vertices but not their triangles, and may overlap or leave gaps where three labels meet or
  /// two touch diagonally.
  Independent,
  /// One conforming complex: the labels in priority order (the background lowest, then by
  /// increasing label), each wall one set of triangles used by the two labels it separates with
  /// opposite orientations, the regions a partition of space, vertices the surfels between
  /// differing labels. Where a label touches itself at a vertex or along an edge (a pinch) its
  /// surface gets a copy of the vertex per sheet (LabelSurface::pinchCopies), where a copy can
  /// separate them. Every boundary of
  /// every label: no seeds, not LabelBoundaries::Largest; pairs 26-6 and 6-26 only.
  Shared
};

struct LabelOptions {
  LabelSelection labels;
  /// The label of no surface: its voxels are 0-voxels of every label.
  LabelValue background = 0;
  LabelBoundaries boundaries = LabelBoundaries::All;
  /// If not empty, only the boundaries these voxels select, and only their labels: each voxel,
  /// of label L, selects the boundary of L through the surfel (c, c + x) where c is the last
  /// voxel of L met walking from the seed along +x (SeedRule::ray's first ray). A seed's label
  /// must be selected and not the background; `boundaries` must be All.
  std::vector<Voxel> seeds;
  AdjacencyPair pair = AdjacencyPair::k26_6;
  /// Independent: each label's own (kappa, lambda) surfaces. Shared: the conforming complex,
  /// each level of the priority order's analog with this pair.
  LabelWalls walls = LabelWalls::Independent;
  /// Shared walls only: if set, the smoothing of the complex (docs/theory.md §12, "Smoothing the
  /// complex"): smooth()'s Taubin lambda|mu passes and fold check over all the labels' walls at
  /// once, every vertex moved once to the same point in every label that has it, on its surfel's
  /// segment, so that the walls stay shared triangle for triangle, the regions a partition, and
  /// each label keeps its voxels and its topology. With independent walls: refused
  /// (InvalidInput), as each label smoothed on its own would pull the vertices it shares apart.
  std::optional<SmoothOptions> smooth;
  /// Shared walls only: if set (a maxError, a reduction or both), the decimation of the complex,
  /// after the smoothing if both are asked (docs/theory.md §12, "Decimating the complex"): each
  /// wall (the triangles between one pair of labels, the background included) decimated once by
  /// decimate()'s halfedge collapses and guards, its junction lines and pinches locked, the link
  /// condition and the embedding checked over the whole complex; then the junction lines, each
  /// collapse along one done in all its walls at once; the triangles then go to both their
  /// labels, so that the walls stay shared triangle for triangle and each label keeps its
  /// components and genus; each wall within maxError of its undecimated self, both ways, for
  /// every point. The reduction applies to each wall and each label, as far as the guards allow.
  /// With independent walls: refused (InvalidInput), as smooth.
  std::optional<DecimateOptions> decimate;
  /// Threads for the scan and for the labels: 0 for all cores. The surfaces are the same for any
  /// number.
  int threads = 0;
  /// Per-component figures of each surface (Surface::components, euler): off for callers that
  /// need only the meshes.
  bool figures = true;
  /// If set and raised, the extraction stops at the next label and throws Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

/// The surface of one label: its boundaries wanted, one component each.
struct LabelSurface {
  LabelValue label;  ///< exact, as every label here (LabelValue.h)
  std::uint64_t voxels = 0;  ///< voxels of the label in the image
  /// selection = Selection::label(label), mapping Midpoint; boundariesInImage: every boundary
  /// of the label for LabelBoundaries::All and Largest, 0 (not counted) with seeds.
  Surface surface;
  /// LabelWalls::Shared: vertex copies made where the label touches itself (pinches), each at the
  /// same point and surfel as its original; the edges of more than two of its triangles; those
  /// of them where the region is taken as joined along the edge, since no copy separates its
  /// sheets otherwise (docs/theory.md §12, "The exception"); and the edges still of four or more
  /// triangles after that (the surface a closed oriented 2-cycle but not a 2-manifold there).
  std::size_t pinchCopies = 0, pinchedEdges = 0, joinedEdges = 0, unsplitEdges = 0;
  /// LabelOptions::smooth: this label's enclosed volume before and after the smoothing and its
  /// largest vertex move (physical units); cubes, unguardedCubes, checkedCubes and stepsBack
  /// are the whole complex's, the same in every label. Nothing without smoothing.
  std::optional<SmoothReport> smooth;
  /// LabelOptions::decimate: this label's triangles and enclosed volume before and after the
  /// decimation (after the smoothing), its target (1 - reduction) x trianglesBefore (0: no
  /// reduction). A halfedge collapse moves no vertex: the surviving vertices keep their points.
  std::optional<DecimateReport> decimate;
};

/// The surfaces of the selected labels of `view`, by increasing label. Labels are exact over
/// the whole range of every integer type (uint64 ids above 2^53 included).
/// \throw InvalidInput for a float volume, a selected label that is not a value of the type,
///        does not occur or is the background, a range or an image with no label to extract,
///        a seed outside the domain or on the background or an unselected label, seeds with
///        LabelBoundaries::Largest.
/// \throw Cancelled when options.cancel is raised.
/// \throw InternalError when an engine invariant fails (a bug).
std::vector<LabelSurface> extractLabels(const VolumeView& view, const LabelOptions& options);

/// The walls a label map gets when its caller asks for none (the CLI's `labels`, the binding's
/// label_surfaces; docs/theory.md §12): shared wherever they are made — every boundary of every
/// label, the whole image in one pass (not by blocks), with a pair of 26-6 or 6-26 — or where a
/// smoothing or a decimation (`refined`) needs them; independent elsewhere. LabelOptions keeps
/// Independent as its own default, for the C++ callers that name what they want.
LabelWalls defaultLabelWalls(bool everyBoundaryInOnePass, AdjacencyPair pair, bool refined);

/// One label's part of the mesh of one block of a volume (docs/api.md, "Label maps by
/// blocks"; docs/theory.md, "Label maps by blocks"): the triangles of the cubes the block owns.
struct LabelFragment {
  LabelValue label;          ///< exact over the whole range of every integer type
  std::uint64_t voxels = 0;  ///< voxels of the label in the block's core
  /// The vertices: their surfels' keys (Surfel::key, volume coordinates), increasing, each
  /// used by a triangle.
  std::vector<std::uint64_t> keys;
  /// Indices into keys, in the table's orientation (geometry not applied), in the order of the
  /// single pass: by owned cube (z, y, x), then the configuration table's order.
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The fragments of every selected label of one block of a volume of `volume` voxels, by
/// increasing label: those with triangles in the block's cubes or voxels in its core. The block's
/// core is the box [lo, hi) of the volume; it owns the cubes whose min corner lies in [lo, hi)
/// on every axis, and also at -1 on an axis where lo = 0. `view` holds the voxels
/// [origin, origin + view.dims) of the volume, which must contain [lo, min(hi + 1, volume))
/// (a one-voxel apron on the high sides) and lie in the volume; view.geometry is not used.
/// The options' pair, labels, background and threads apply; a listed label need not occur in
/// the block. For each label, mergeLabelFragments over the fragments of all blocks of any
/// partition of the volume gives extractLabels' surface of that label.
/// \throw InvalidInput for a float view, a view or core that does not fit as above, volume
///        dimensions beyond the surfel keys' range, seeds, LabelBoundaries::Largest, a
///        selection as extractLabels refuses it (but a listed label that does not occur).
std::vector<LabelFragment> scanLabelBlock(const VolumeView& view, Voxel origin, Dims volume, Voxel lo, Voxel hi,
                                          const LabelOptions& options);

/// The surface of one label from its fragments of every block of a partition of the volume
/// (any order): the same LabelSurface extractLabels gives for that label over the whole
/// volume with `geometry` and options' pair and figures, field for field, vertices bit-equal.
/// \throw InvalidInput for no fragment, fragments of several labels, keys not increasing or
///        out of the key range, a triangle index beyond its fragment's keys, more than 2^32 - 1
///        vertices, vertices beyond the float range.
LabelSurface mergeLabelFragments(const std::vector<LabelFragment>& fragments, const ImageGeometry& geometry,
                                 const LabelOptions& options);

/// Writes every surface into one PLY file (binary little-endian, or text): the vertices of each
/// label in turn (float x, y, z; a vertex on an interface once per label it bounds), the faces
/// (int indices), with the label on every vertex and every face, exactly: an int property
/// `label` when every label fits int32, else `label_high` and `uint label_low` with
/// label = label_high * 2^32 + label_low (label_high an int if a label is negative, else a uint).
/// Through a temporary file renamed over `path`.
/// \throw InvalidInput for more than 2^31 - 1 vertices;
///        std::runtime_error naming the path when it cannot be written.
void writeLabelSurfaces(const std::vector<LabelSurface>& surfaces, const std::string& path, bool binary = true);

}  // namespace surftrack
