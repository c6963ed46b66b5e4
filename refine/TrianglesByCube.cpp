#include "TrianglesByCube.h"

#include <algorithm>
#include <array>
#include <bit>
#include <tuple>
#include <utility>

#include "HugePages.h"

namespace surftrack::refine {

namespace {

struct Record {
  std::uint64_t key;
  std::uint32_t triangle;
};

/// The records sorted by key, stably (equal keys keep their triangles' increasing order): a
/// least-significant-digit radix sort over the `bits` low bits of the keys.
std::vector<Record> sortByKey(std::vector<Record> in, int bits) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t(1) << kDigit;
  std::vector<Record> out = hugePageVector<Record>(in.size());
  std::array<std::uint32_t, kBuckets> count;
  for (int shift = 0; shift < bits; shift += kDigit) {
    count.fill(0);
    for (const Record& r : in) ++count[(r.key >> shift) & (kBuckets - 1)];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : count) sum += std::exchange(c, sum);
    for (const Record& r : in) out[count[(r.key >> shift) & (kBuckets - 1)]++] = r;
    in.swap(out);
  }
  return in;
}

}  // namespace

Lists groupTrianglesByCube(std::span<const Voxel> cube) {
  const std::size_t n = cube.size();
  if (n == 0) return invert({}, 0);

  // Keys: the corner's offsets from the least corner, packed in as few bits as they need.
  Voxel lo = cube[0], hi = cube[0];
  for (const Voxel& c : cube)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  std::array<int, 3> width{};
  for (int k = 0; k < 3; ++k) width[k] = int(std::bit_width(std::uint64_t(std::int64_t(hi[k]) - lo[k])));
  std::vector<Record> records = hugePageVector<Record>(n);
  std::vector<Record> sorted;
  // (A shift by 64 would be undefined: the keys take 63 bits at most.)
  if (width[0] + width[1] + width[2] < 64) {
    for (std::size_t f = 0; f < n; ++f) {
      const Voxel& c = cube[f];
      records[f] = {std::uint64_t(std::int64_t(c.x) - lo.x) | (std::uint64_t(std::int64_t(c.y) - lo.y) << width[0]) |
                        (std::uint64_t(std::int64_t(c.z) - lo.z) << (width[0] + width[1])),
                    std::uint32_t(f)};
    }
    sorted = sortByKey(std::move(records), width[0] + width[1] + width[2]);
  } else {  // corners too far apart for one 64-bit key: compare them, then number them
    for (std::size_t f = 0; f < n; ++f) records[f] = {0, std::uint32_t(f)};
    std::stable_sort(records.begin(), records.end(), [&](const Record& a, const Record& b) {
      const Voxel &p = cube[a.triangle], &q = cube[b.triangle];
      return std::tie(p.z, p.y, p.x) < std::tie(q.z, q.y, q.x);
    });
    for (std::size_t i = 1; i < n; ++i)
      records[i].key = records[i - 1].key + (cube[records[i].triangle] == cube[records[i - 1].triangle] ? 0 : 1);
    sorted = std::move(records);
  }

  // Groups in key order, then renumbered by their first (least) triangle.
  std::vector<std::uint32_t> groupOf = hugePageVector<std::uint32_t>(n), firstOfGroup;
  for (std::size_t i = 0; i < n; ++i) {
    if (i == 0 || sorted[i].key != sorted[i - 1].key)
      firstOfGroup.push_back(sorted[i].triangle);
    groupOf[sorted[i].triangle] = std::uint32_t(firstOfGroup.size() - 1);
  }
  const std::size_t groups = firstOfGroup.size();
  std::vector<std::uint32_t> number(groups);
  std::uint32_t next = 0;
  for (std::size_t f = 0; f < n; ++f)
    if (firstOfGroup[groupOf[f]] == f) number[groupOf[f]] = next++;
  for (std::uint32_t& g : groupOf) g = number[g];  // each triangle's cube
  return invert(groupOf, groups);
}

}  // namespace surftrack::refine
