// Where the engine gets its voxels (docs/api.md, "Voxel sources"). The tracker reads a volume
// only near the surface it follows, one 8x8x8 brick (with a one-voxel apron) at a time, so a
// source answers one virtual call per brick, not per voxel; the scanning method reads whole
// rows; the iso-value mapping reads the gray values of the surfels' two voxels. A view over
// memory, a memory-mapped file, an implicit function or a chunked store is a VoxelSource.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <sstream>
#include <string>

#include "Geometry.h"
#include "LabelValue.h"
#include "ScalarType.h"
#include "VolumeView.h"
#include "Voxel.h"

namespace surftrack {

/// Which voxels are 1-voxels (paper §3.1): f > s (a threshold) or f = L (a label).
struct Selection {
  enum class Kind { Threshold, Label };
  Kind kind = Kind::Threshold;
  double value = 0;   ///< Threshold: s
  LabelValue labelValue;  ///< Label: L, exact (64-bit segment ids included)

  static Selection threshold(double s) { return {Kind::Threshold, s, {}}; }
  static Selection label(LabelValue L) { return {Kind::Label, 0, L}; }
  bool isLabel() const { return kind == Kind::Label; }
  /// "f > s" or "f = L", for messages (s with 10 significant digits, L exactly).
  std::string text() const {
    if (isLabel()) return "f = " + labelValue.text();
    std::ostringstream s;
    s.precision(10);
    s << "f > " << value;
    return s.str();
  }
};

/// Every member is const and may be called from several threads at once (the scanning method
/// reads planes in parallel).
class VoxelSource {
 public:
  virtual ~VoxelSource() = default;

  virtual Dims dims() const = 0;
  virtual ImageGeometry geometry() const = 0;
  /// The type of the gray values (a label selection needs an integer type).
  virtual ScalarType type() const = 0;

  /// Binarises a block of `width` <= 16 by ny by nz voxels from `origin`: bit i of
  /// out[k * ny + j] is 1 iff voxel origin + (i, j, k) is selected. Voxels outside the domain
  /// are 0-voxels. One call per brick of the tracker.
  virtual void binaryBlock(const Selection& selection, Voxel origin, int width, int ny, int nz,
                           std::uint16_t* out) const = 0;
  /// Voxels start + (i, 0, 0), i < count <= 64, as bits i (0 outside the domain): the scanner.
  virtual std::uint64_t binaryRow(const Selection& selection, Voxel start, int count) const = 0;
  /// The gray values of n voxels of the domain, as doubles: the iso-value mapping.
  virtual void values(const Voxel* voxels, std::size_t n, double* out) const = 0;
};

/// A source over a view; the memory it points to must outlive the source. Throws InvalidInput
/// for a null pointer, empty or oversized dimensions.
std::unique_ptr<VoxelSource> makeViewSource(const VolumeView& view);

/// A source whose gray values come from a function f(x, y, z) on a domain, with no storage:
/// it can describe volumes far too large to hold (a 4096^3 ball, say). f is called once per
/// voxel read, only near the surface on a seeded extraction; it must be safe to call from
/// several threads at once (or extract with threads = 1).
std::unique_ptr<VoxelSource> makeFunctionSource(Dims dims, std::function<double(int, int, int)> f,
                                                const ImageGeometry& geometry = {});

}  // namespace surftrack
