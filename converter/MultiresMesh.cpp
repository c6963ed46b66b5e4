// Neuroglancer's multi-resolution precomputed meshes (MultiresMesh.h).
#include "MultiresMesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "DracoFragment.h"
#include "PrecomputedDirectory.h"

namespace surftrack {

namespace {

using Cell = std::array<std::int64_t, 3>;

/// The node's position on the Z-order curve (x in the lowest bit), the order the manifest
/// lists the nodes of a level in.
std::uint64_t zOrder(const Cell& c) {
  std::uint64_t key = 0;
  for (int bit = 0; bit < 21; ++bit)
    for (int axis = 0; axis < 3; ++axis) key |= ((std::uint64_t(c[axis]) >> bit) & 1) << (3 * bit + axis);
  return key;
}

class SegmentEncoder {
 public:
  SegmentEncoder(const MultiresSegment& s, int bits, bool reverse) : s_(s), bits_(bits), reverse_(reverse) {}

  EncodedMultiresSegment encode() {
    const OctreeGrid& g = s_.grid;
    const int lods = g.lods;
    // The nodes of each level: the cells its triangles lie in, and the parents of the nodes
    // of the level below (Neuroglancer reaches a node only through its parent).
    std::vector<std::map<std::uint64_t, std::pair<Cell, std::vector<std::uint32_t>>>> nodes(static_cast<std::size_t>(lods));
    for (int k = 0; k < lods; ++k) {
      const MultiresLevel& level = s_.levels[std::size_t(k)];
      for (std::uint32_t t = 0; t < level.triangles.size(); ++t) {
        const Cell c = cellOf(level, level.triangles[t], k);
        if (k > 0) cellOf(level, level.triangles[t], k - 1);  // the octants: checked only
        auto& node = nodes[std::size_t(k)][zOrder(c)];
        node.first = c;
        node.second.push_back(t);
      }
      if (k > 0)
        for (const auto& [key, child] : nodes[std::size_t(k - 1)]) {
          const Cell parent = {child.first[0] >> 1, child.first[1] >> 1, child.first[2] >> 1};
          nodes[std::size_t(k)][zOrder(parent)].first = parent;
        }
    }
    EncodedMultiresSegment out;
    std::string& m = out.manifest;
    for (int a = 0; a < 3; ++a) appendLittleEndian(m, float(g.chunk[std::size_t(a)]));
    for (int a = 0; a < 3; ++a) appendLittleEndian(m, float(g.origin[std::size_t(a)]));
    appendLittleEndian(m, std::uint32_t(lods));
    for (double scale : s_.lodScales) appendLittleEndian(m, float(scale));
    for (int i = 0; i < 3 * lods; ++i) appendLittleEndian(m, 0.0f);  // vertex_offsets
    for (const auto& level : nodes) appendLittleEndian(m, std::uint32_t(level.size()));
    for (int k = 0; k < lods; ++k) {
      const auto& level = nodes[std::size_t(k)];
      for (int a = 0; a < 3; ++a)
        for (const auto& [key, node] : level) appendLittleEndian(m, std::uint32_t(node.first[std::size_t(a)]));
      for (const auto& [key, node] : level) {
        const std::string bytes = node.second.empty() ? std::string() : fragment(k, node.first, node.second);
        if (bytes.size() > std::numeric_limits<std::uint32_t>::max())
          throw std::invalid_argument("segment " + s_.id.text() + " has a fragment beyond 4 GiB");
        appendLittleEndian(m, std::uint32_t(bytes.size()));
        out.data += bytes;
      }
    }
    return out;
  }

 private:
  /// The cell of level g holding triangle t (OctreeGrid::cellOfSpan), checked to hold it.
  Cell cellOf(const MultiresLevel& level, const std::array<std::uint32_t, 3>& t, int g) const {
    Cell c{};
    for (int a = 0; a < 3; ++a) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (std::uint32_t v : t) {
        if (v >= level.vertices.size())
          throw std::invalid_argument("segment " + s_.id.text() + " has a triangle corner beyond its vertices");
        const double u = s_.grid.cells(a, level.vertices[v][std::size_t(a)], g);
        lo = std::min(lo, u), hi = std::max(hi, u);
      }
      if (!std::isfinite(lo) || !std::isfinite(hi))
        throw std::invalid_argument("segment " + s_.id.text() + " has a vertex that is not finite");
      const std::int64_t n = OctreeGrid::cellOfSpan(hi);
      if (lo < double(n))
        throw std::invalid_argument("segment " + s_.id.text() + ": a triangle crosses a plane of the grid's level " +
                                    std::to_string(g) + " (the levels are not cut on the grid)");
      if (n < 0 || n >= (std::int64_t(1) << 21))
        throw std::invalid_argument("segment " + s_.id.text() + " lies outside its grid's 2^21 cells");
      c[std::size_t(a)] = n;
    }
    return c;
  }

  /// The Draco bytes of the triangles `ts` of level k in cell c.
  std::string fragment(int k, const Cell& c, const std::vector<std::uint32_t>& ts) const {
    const MultiresLevel& level = s_.levels[std::size_t(k)];
    const double top = std::ldexp(1.0, bits_) - 1;  // 2^b - 1
    const std::int64_t middle = std::int64_t(1) << (bits_ - 1);
    std::map<std::uint32_t, std::uint32_t> local;
    std::vector<std::array<std::int32_t, 3>> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (std::uint32_t t : ts) {
      std::array<std::uint32_t, 3> tri{};
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t v = level.triangles[t][std::size_t(i)];
        auto [it, fresh] = local.emplace(v, std::uint32_t(positions.size()));
        if (fresh) positions.push_back(quantize(level.vertices[v], k, c, top, middle));
        tri[std::size_t(i)] = it->second;
      }
      if (reverse_) std::swap(tri[1], tri[2]);
      triangles.push_back(tri);
    }
    return encodeDracoFragment(positions, triangles);
  }

  std::array<std::int32_t, 3> quantize(const std::array<double, 3>& p, int k, const Cell& c, double top,
                                       std::int64_t middle) const {
    std::array<std::int32_t, 3> q{};
    for (int a = 0; a < 3; ++a) {
      // On the lattice of level k as a whole, so that two fragments of one level sharing a
      // vertex give it the same point.
      const double u = s_.grid.cells(a, p[std::size_t(a)], k);
      std::int64_t x = std::llround(u * top) - c[std::size_t(a)] * std::int64_t(top);
      x = std::clamp<std::int64_t>(x, 0, std::int64_t(top));
      if (k > 0) {  // Neuroglancer's octants split at 2^(b-1) (docs/cli.md)
        const double half = s_.grid.cells(a, p[std::size_t(a)], k - 1);
        const double mid = double(2 * c[std::size_t(a)] + 1);
        if (half == mid) x = middle;
        else if (half < mid) x = std::min(x, middle - 1);
        else x = std::max(x, middle + 1);
      }
      q[std::size_t(a)] = std::int32_t(x);
    }
    return q;
  }

  const MultiresSegment& s_;
  int bits_;
  bool reverse_;
};

void checkSegment(const MultiresSegment& s) {
  const OctreeGrid& g = s.grid;
  const std::string what = "segment " + s.id.text();
  if (g.lods < 1 || g.lods > 20) throw std::invalid_argument(what + ": the levels of detail must be 1 to 20");
  if (s.levels.size() != std::size_t(g.lods) || s.lodScales.size() != std::size_t(g.lods))
    throw std::invalid_argument(what + ": " + std::to_string(s.levels.size()) + " levels and " +
                                std::to_string(s.lodScales.size()) + " scales for a grid of " + std::to_string(g.lods));
  for (int a = 0; a < 3; ++a) {
    const double c = g.chunk[std::size_t(a)], o = g.origin[std::size_t(a)];
    if (!(c > 0) || !std::isfinite(c) || double(float(c)) != c || !std::isfinite(o) || double(float(o)) != o)
      throw std::invalid_argument(what + ": the grid's chunk and origin must be exact float32 values, the chunk positive");
  }
  for (std::size_t k = 0; k < s.lodScales.size(); ++k)
    if (!(s.lodScales[k] > 0) || !std::isfinite(s.lodScales[k]) || (k > 0 && s.lodScales[k] < s.lodScales[k - 1]))
      throw std::invalid_argument(what + ": the lod scales must be positive and nondecreasing");
}

}  // namespace

EncodedMultiresSegment encodeMultiresSegment(const MultiresSegment& segment, int quantizationBits, bool reverse) {
  if (quantizationBits != 10 && quantizationBits != 16)
    throw std::invalid_argument("vertex quantization bits must be 10 or 16 (the format allows no other), not " +
                                std::to_string(quantizationBits));
  checkSegment(segment);
  return SegmentEncoder(segment, quantizationBits, reverse).encode();
}

std::string multiresInfoBytes(const ToNanometres& toNanometres, const MultiresFormat& format, bool named) {
  nlohmann::ordered_json info = {{"@type", "neuroglancer_multilod_draco"},
                                 {"vertex_quantization_bits", format.quantizationBits}};
  nlohmann::ordered_json transform = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) transform.push_back(toNanometres.linear[std::size_t(r)][std::size_t(c)]);
    transform.push_back(toNanometres.offset[std::size_t(r)]);
  }
  info["transform"] = transform;
  info["lod_scale_multiplier"] = 1.0;
  if (format.sharding) info["sharding"] = format.sharding->json();
  if (named) info["segment_properties"] = "segment_properties";
  return info.dump() + "\n";
}

void writePrecomputedMultires(const std::vector<MultiresSegment>& segments, const std::string& directory,
                              const ToNanometres& toNanometres, const MultiresFormat& format) {
  const std::filesystem::path target = precomputedTarget(directory);
  if (format.quantizationBits != 10 && format.quantizationBits != 16)
    throw std::invalid_argument("vertex quantization bits must be 10 or 16 (the format allows no other), not " +
                                std::to_string(format.quantizationBits));
  const double det = toNanometres.determinant();
  if (!std::isfinite(det) || det == 0)
    throw std::invalid_argument("the map of the meshes to nanometres is singular or not finite");
  std::vector<std::pair<LabelValue, const std::string*>> ids;
  for (const MultiresSegment& s : segments) ids.emplace_back(s.id, &s.name);
  const bool named = checkSegmentIds(ids);
  for (const MultiresSegment& s : segments) checkSegment(s);

  std::vector<EncodedMultiresSegment> encoded(segments.size());
  tbb::parallel_for(std::size_t(0), segments.size(), [&](std::size_t i) {
    encoded[i] = SegmentEncoder(segments[i], format.quantizationBits, det < 0).encode();
  });

  StagingDirectory staging(target, directory);
  staging.write("info", multiresInfoBytes(toNanometres, format, named));
  if (format.sharding) {
    std::vector<ShardChunk> chunks;
    for (std::size_t i = 0; i < segments.size(); ++i)
      chunks.push_back({segments[i].id.magnitude(), std::move(encoded[i].data), std::move(encoded[i].manifest)});
    for (auto& [name, bytes] : buildShards(*format.sharding, std::move(chunks))) staging.write(name, bytes);
  } else {
    for (std::size_t i = 0; i < segments.size(); ++i) {
      const std::string id = segments[i].id.text();
      staging.write(id + ".index", encoded[i].manifest);
      staging.write(id, encoded[i].data);
    }
  }
  if (named) {
    std::vector<std::pair<LabelValue, std::string>> names;
    for (const MultiresSegment& s : segments) names.emplace_back(s.id, s.name);
    staging.writeSegmentProperties(names);
  }
  staging.commit();
}

}  // namespace surftrack
