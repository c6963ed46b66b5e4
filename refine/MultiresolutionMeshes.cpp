// Multi-resolution output with levels of detail (MultiresolutionMeshes.h).
#include "MultiresolutionMeshes.h"

#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "LevelsOfDetail.h"
#include "PrecomputedDirectory.h"

namespace surftrack::refine {

void checkMultiresolutionOptions(const MultiresolutionOptions& o) {
  if (o.lods < 1 || o.lods > 10) throw std::invalid_argument("levels of detail must be 1 to 10, not " + std::to_string(o.lods));
  if (o.quantizationBits != 10 && o.quantizationBits != 16)
    throw std::invalid_argument("vertex quantization bits must be 10 or 16 (the format allows no other), not " +
                                std::to_string(o.quantizationBits));
  if (!(o.firstError > 0) || !std::isfinite(o.firstError))
    throw std::invalid_argument("the first level's error bound must be a positive distance");
}

MultiresSegment multiresolutionSegment(const PrecomputedSegment& s, const MultiresolutionOptions& o) {
  if (!s.vertices || !s.triangles) throw std::invalid_argument("segment " + s.id.text() + " has no mesh");
  LevelsOfDetailOptions lo;
  lo.firstError = o.firstError;
  lo.quantizationBits = o.quantizationBits;
  lo.cancel = o.cancel;
  MultiresSegment m;
  m.id = s.id;
  m.name = s.name;
  for (const auto& t : *s.triangles)
    for (std::uint32_t v : t)
      if (v >= s.vertices->size())
        throw std::invalid_argument("segment " + s.id.text() + " has a triangle corner beyond its vertices");
  m.grid = gridFor(*s.vertices, o.lods);
  std::vector<GridMesh> levels;
  try {
    levels = levelsOfDetail(GridMesh{*s.vertices, *s.triangles}, m.grid, lo);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("segment " + s.id.text() + ": " + e.what());
  }
  for (int k = 0; k < o.lods; ++k) {
    m.levels.push_back({std::move(levels[std::size_t(k)].vertices), std::move(levels[std::size_t(k)].triangles)});
    m.lodScales.push_back(std::ldexp(1.0, k));
  }
  return m;
}

MultiresFormat multiresolutionFormat(std::size_t count, const MultiresolutionOptions& o) {
  MultiresFormat format;
  format.quantizationBits = o.quantizationBits;
  if (o.sharded) format.sharding = shardingFor(count, o.identityHash ? ShardHash::Identity : ShardHash::MurmurHash3_x86_128);
  return format;
}

void writeMultiresolutionMeshes(const std::vector<PrecomputedSegment>& segments, const std::string& directory,
                                const ToNanometres& toNanometres, const MultiresolutionOptions& o) {
  checkMultiresolutionOptions(o);
  precomputedTarget(directory);  // a file, a nonempty directory: refused before the work
  std::vector<std::pair<LabelValue, const std::string*>> ids;
  for (const PrecomputedSegment& s : segments) {
    if (!s.vertices || !s.triangles) throw std::invalid_argument("segment " + s.id.text() + " has no mesh");
    ids.emplace_back(s.id, &s.name);
  }
  checkSegmentIds(ids);

  std::vector<MultiresSegment> out(segments.size());
  tbb::parallel_for(std::size_t(0), segments.size(),
                    [&](std::size_t i) { out[i] = multiresolutionSegment(segments[i], o); });
  writePrecomputedMultires(out, directory, toNanometres, multiresolutionFormat(segments.size(), o));
}

}  // namespace surftrack::refine
