#include "UnionFind.h"

#include <boost/pending/disjoint_sets.hpp>

namespace surftrack {
namespace {

/// Boost's disjoint sets over the two arrays (it holds only the pointers).
boost::disjoint_sets<std::uint32_t*, std::uint32_t*> over(std::vector<std::uint32_t>& rank,
                                                          std::vector<std::uint32_t>& parent) {
  return {rank.data(), parent.data()};
}

}  // namespace

UnionFind::UnionFind(std::size_t n) : rank_(n), parent_(n) {
  auto sets = over(rank_, parent_);
  for (std::uint32_t x = 0; x < n; ++x) sets.make_set(x);
}

std::uint32_t UnionFind::find(std::uint32_t x) { return over(rank_, parent_).find_set(x); }

void UnionFind::join(std::uint32_t a, std::uint32_t b) { over(rank_, parent_).union_set(a, b); }

}  // namespace surftrack
