// The Neuroglancer outputs of the CLI (PrecomputedOutput.h).
#include "PrecomputedOutput.h"

#include <map>

#include "MultiresolutionMeshes.h"

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

}  // namespace

void writePrecomputedOutput(const std::vector<OutputSegment>& segments, const std::string& directory,
                            const std::string& format, const ImageGeometry& g, const SpacingUnit& unit,
                            const PrecomputedOptions& options) {
  const double k = nanometresOf(unit);
  if (format == "precomputed") {
    // Physical coordinates scaled, plus half a voxel along each voxel axis: Neuroglancer draws
    // voxel i over [i, i + 1) where the physical coordinates put its centre at i.
    ToNanometres m;
    for (int r = 0; r < 3; ++r) {
      m.linear[r] = {r == 0 ? k : 0.0, r == 1 ? k : 0.0, r == 2 ? k : 0.0};
      double shift = 0;
      for (int e = 0; e < 3; ++e) shift += g.direction[r][e] * g.spacing[e] / 2;
      m.offset[r] = k * shift;
    }
    std::vector<PrecomputedSegment> out;
    for (const OutputSegment& s : segments)
      out.push_back({s.id, &s.surface->vertices, &s.surface->triangles, s.name});
    writePrecomputedMeshes(out, directory, m);
    return;
  }
  // Voxel indices: index p is at k * (origin + D diag(s) (p + 1/2)) nanometres.
  ToNanometres m;
  for (int r = 0; r < 3; ++r) {
    double shift = 0;
    for (int c = 0; c < 3; ++c) {
      m.linear[r][c] = k * g.direction[r][c] * g.spacing[c];
      shift += g.direction[r][c] * g.spacing[c] / 2;
    }
    m.offset[r] = k * (g.origin[r] + shift);
  }
  // Triangles face out in physical space; in index space too unless the geometry mirrors.
  const bool mirrors = g.handedness() < 0;
  std::vector<std::vector<std::array<double, 3>>> vertices(segments.size());
  std::vector<std::vector<std::array<std::uint32_t, 3>>> triangles(segments.size());
  std::vector<PrecomputedSegment> out;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Surface& s = *segments[i].surface;
    vertices[i].reserve(s.vertices.size());
    for (const auto& p : s.vertices) vertices[i].push_back(g.toIndex(p));
    triangles[i] = s.triangles;
    if (mirrors)
      for (auto& t : triangles[i]) std::swap(t[1], t[2]);
    out.push_back({segments[i].id, &vertices[i], &triangles[i], segments[i].name});
  }
  refine::MultiresolutionOptions o;
  o.lods = options.lods;
  o.sharded = options.sharded;
  o.identityHash = options.identityHash;
  o.quantizationBits = options.quantizationBits;
  refine::writeMultiresolutionMeshes(out, directory, m, o);
}

}  // namespace surftrack::cli
