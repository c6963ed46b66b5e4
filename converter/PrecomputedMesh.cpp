// Neuroglancer's legacy precomputed meshes (PrecomputedMesh.h).
#include "PrecomputedMesh.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "MeshIO.h"
#include "PrecomputedDirectory.h"

namespace surftrack {

namespace {

namespace fs = std::filesystem;

}  // namespace

/// The fragment file of one segment: vertex count, float32 x y z in nanometres, triangles.
std::string legacyFragmentBytes(const PrecomputedSegment& s, const ToNanometres& m) {
  if (!s.vertices || !s.triangles) throw std::invalid_argument("segment " + s.id.text() + " has no mesh");
  const auto& vertices = *s.vertices;
  const auto& triangles = *s.triangles;
  if (vertices.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("segment " + s.id.text() + " has more than 2^32 - 1 vertices: the format counts them in 32 bits");
  std::string out;
  out.reserve(4 + 12 * vertices.size() + 12 * triangles.size());
  appendLittleEndian(out, std::uint32_t(vertices.size()));
  for (const auto& p : vertices) {
    for (int r = 0; r < 3; ++r) {
      const double nm = m.linear[r][0] * p[0] + m.linear[r][1] * p[1] + m.linear[r][2] * p[2] + m.offset[r];
      if (!std::isfinite(nm) || std::abs(nm) > double(std::numeric_limits<float>::max()))
        throw std::invalid_argument("segment " + s.id.text() + " has a vertex at " + std::to_string(nm) +
                                    " nm, beyond a float32: the format stores float32 nanometres");
      appendLittleEndian(out, float(nm));
    }
  }
  // A map that mirrors (negative determinant, e.g. array columns z, y, x read as x, y, z) would
  // turn the triangles inwards: they are written reversed, still facing out of the label.
  const double det = m.determinant();
  for (std::array<std::uint32_t, 3> t : triangles) {
    if (det < 0) std::swap(t[1], t[2]);
    for (std::uint32_t v : t) {
      if (v >= vertices.size())
        throw std::invalid_argument("segment " + s.id.text() + " has a triangle corner " + std::to_string(v) +
                                    " beyond its " + std::to_string(vertices.size()) + " vertices");
      appendLittleEndian(out, v);
    }
  }
  return out;
}

std::string legacyManifestBytes(const LabelValue& id) {
  return nlohmann::ordered_json{{"fragments", {id.text() + ".mesh"}}}.dump() + "\n";
}

std::string legacyInfoBytes(bool named) {
  nlohmann::ordered_json info = {{"@type", "neuroglancer_legacy_mesh"}};
  if (named) info["segment_properties"] = "segment_properties";
  return info.dump() + "\n";
}

void writePrecomputedMeshes(const std::vector<PrecomputedSegment>& segments, const std::string& directory,
                            const ToNanometres& toNanometres) {
  const fs::path target = precomputedTarget(directory);
  const double det = toNanometres.determinant();
  if (!std::isfinite(det) || det == 0)
    throw std::invalid_argument("the map of the meshes to nanometres is singular or not finite");
  std::vector<std::pair<LabelValue, const std::string*>> ids;
  for (const PrecomputedSegment& s : segments) {
    if (!s.vertices || !s.triangles) throw std::invalid_argument("segment " + s.id.text() + " has no mesh");
    ids.emplace_back(s.id, &s.name);
  }
  const bool named = checkSegmentIds(ids);

  StagingDirectory staging(target, directory);
  staging.write("info", legacyInfoBytes(named));
  for (const PrecomputedSegment& s : segments) {
    const std::string id = s.id.text();
    staging.write(id + ".mesh", legacyFragmentBytes(s, toNanometres));
    staging.write(id + ":0", legacyManifestBytes(s.id));
  }
  if (named) {
    std::vector<std::pair<LabelValue, std::string>> names;
    for (const PrecomputedSegment& s : segments) names.emplace_back(s.id, s.name);
    staging.writeSegmentProperties(names);
  }
  staging.commit();
}

}  // namespace surftrack
