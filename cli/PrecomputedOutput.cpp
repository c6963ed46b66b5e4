// The Neuroglancer outputs of the CLI (PrecomputedOutput.h).
#include "PrecomputedOutput.h"

#include <map>

#include "MultiresolutionMeshes.h"
#include "PrecomputedFrame.h"

namespace surftrack::cli {

namespace {

/// Nanometres per unit of a unit name; 0: not a length known here.
double nanometresPer(const std::string& unit) {
  static const std::map<std::string, double> units = {
      {"nm", 1.0},  {"nanometer", 1.0}, {"um", 1e3},         {"µm", 1e3},   {"micrometer", 1e3}, {"mm", 1e6},
      {"millimeter", 1e6}, {"cm", 1e7}, {"centimeter", 1e7}, {"m", 1e9},    {"meter", 1e9},      {"Å", 0.1},
      {"angstrom", 0.1},   {"inch", 2.54e7}};
  const auto it = units.find(unit);
  return it == units.end() ? 0.0 : it->second;
}

}  // namespace

double nanometresOf(const SpacingUnit& u) {
  std::string unit = u.option;
  if (unit.empty()) unit = u.fileUnit;
  if (unit.empty() && u.fileFormat != "raw") unit = "mm";  // ITK's unit for medical formats
  if (unit.empty())
    throw UsageError("the spacing of a raw file has no unit: give --unit (nm, um, mm, cm or m) for a Neuroglancer format");
  const double k = nanometresPer(unit);
  if (k == 0) throw UsageError("the volume's unit '" + unit + "' is not a length: give --unit (nm, um, mm, cm or m)");
  return k;
}

void writePrecomputedOutput(const std::vector<OutputSegment>& segments, const std::string& directory,
                            const std::string& format, const ImageGeometry& g, const SpacingUnit& unit,
                            const PrecomputedOptions& options) {
  const double k = nanometresOf(unit);
  if (format == "precomputed") {
    std::vector<PrecomputedSegment> out;
    for (const OutputSegment& s : segments)
      out.push_back({s.id, &s.surface->vertices, &s.surface->triangles, s.name});
    writePrecomputedMeshes(out, directory, legacyFrame(g, k));
    return;
  }
  std::vector<std::vector<std::array<double, 3>>> vertices(segments.size());
  std::vector<std::vector<std::array<std::uint32_t, 3>>> triangles(segments.size());
  std::vector<PrecomputedSegment> out;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    vertices[i] = segments[i].surface->vertices;
    triangles[i] = segments[i].surface->triangles;
    toVoxelIndices(g, vertices[i], triangles[i]);
    out.push_back({segments[i].id, &vertices[i], &triangles[i], segments[i].name});
  }
  refine::MultiresolutionOptions o;
  o.lods = options.lods;
  o.sharded = options.sharded;
  o.quantizationBits = options.quantizationBits;
  refine::writeMultiresolutionMeshes(out, directory, multiresFrame(g, k), o);
}

}  // namespace surftrack::cli
