// Disjoint sets over 0 .. n-1: the sheets of a pinch (PinchSplit.cpp) and the fans of a wall
// around a vertex (refine/ComplexDecimation.cpp). Boost's disjoint sets, as everywhere else in
// the engine (MeshComponents.cpp, tracker/ScanBoundaries.h), behind the two calls these users
// need; a root only names its set. Boost's header stays in UnionFind.cpp: included after Boost
// Graph's compressed sparse row header, its calls of get() on pointers no longer compile.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace surftrack {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n);
  std::uint32_t find(std::uint32_t x);
  void join(std::uint32_t a, std::uint32_t b);

 private:
  std::vector<std::uint32_t> rank_, parent_;
};

}  // namespace surftrack
