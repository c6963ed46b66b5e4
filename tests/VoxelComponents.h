// Independent reference for the tests: kappa-lambda-boundaries computed from voxel components
// (paper §2.1.4) with Boost's disjoint sets on the voxel grid, never from surfel adjacencies nor
// from the engine's own code. The grid is the image domain padded by one voxel: outside voxels
// are 0-voxels, all 6-connected through the padding frame, so the padding represents the whole
// outside.
#pragma once

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <vector>

#include <boost/pending/disjoint_sets.hpp>

#include "AdjacencyPair.h"
#include "Image.h"
#include "Surfel.h"

namespace surftrack::testing {

/// Voxel components of the padded domain: 1-voxels under kappa, 0-voxels under lambda.
class VoxelComponents {
 public:
  template <class BinaryImage>
  VoxelComponents(const BinaryImage& image, AdjacencyPair pair)
      : dims_(image.dims()), px_(dims_.nx + 2), py_(dims_.ny + 2), pz_(dims_.nz + 2) {
    const int n = px_ * py_ * pz_;
    value_.resize(n);
    for (int z = -1; z <= dims_.nz; ++z)
      for (int y = -1; y <= dims_.ny; ++y)
        for (int x = -1; x <= dims_.nx; ++x) value_[id({x, y, z})] = image(x, y, z);
    // Iterator property maps, not pointers (nor disjoint_sets_with_storage, which uses them):
    // where Boost's CSR graph is included, its boost::detail::get hides the boost::get of
    // pointers.
    std::vector<int> rank(n), parent(n);
    const boost::typed_identity_property_map<int> index;
    boost::disjoint_sets sets(boost::make_iterator_property_map(rank.begin(), index),
                              boost::make_iterator_property_map(parent.begin(), index));
    for (int i = 0; i < n; ++i) sets.make_set(i);
    for (int z = -1; z <= dims_.nz; ++z)
      for (int y = -1; y <= dims_.ny; ++y)
        for (int x = -1; x <= dims_.nx; ++x) {
          const Voxel v{x, y, z};
          for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const Voxel w = v + Voxel{dx, dy, dz};
                if (!inPadded(w) || id(w) <= id(v) || value_[id(w)] != value_[id(v)]) continue;
                const int adjacency = value_[id(v)] ? kappa(pair) : lambda(pair);
                if (areAdjacent(adjacency, v, w)) sets.union_set(id(v), id(w));
              }
        }
    component_.resize(n);
    for (int i = 0; i < n; ++i) component_[i] = sets.find_set(i);
  }

  /// The same number for exactly the voxels of v's component (that of one of its voxels).
  int component(Voxel v) const { return component_[id(v)]; }
  bool value(Voxel v) const { return value_[id(v)]; }

  /// Every kappa-lambda-boundary d(O, Q), as a sorted set of surfel keys, keyed by (O, Q).
  std::map<std::pair<int, int>, std::vector<std::uint64_t>> boundaries() const {
    std::map<std::pair<int, int>, std::vector<std::uint64_t>> out;
    for (int z = -1; z <= dims_.nz; ++z)
      for (int y = -1; y <= dims_.ny; ++y)
        for (int x = -1; x <= dims_.nx; ++x) {
          const Voxel c{x, y, z};
          if (!value(c)) continue;
          for (Direction n = 0; n < 6; ++n) {
            const Voxel d = c + unitVector(n);
            if (inPadded(d) && !value(d))
              out[{component(c), component(d)}].push_back(Surfel{c, n}.key());
          }
        }
    for (auto& [k, v] : out) std::sort(v.begin(), v.end());
    return out;
  }

  /// Near-Jordan (§2.1.5): with the surfels of sigma removed from the 6-grid, no voxel of the
  /// immediate interior reaches a voxel of the immediate exterior.
  bool separates(const std::vector<Surfel>& sigma) const {
    std::set<std::uint64_t> cut;
    for (const Surfel& s : sigma) cut.insert(s.key());
    auto isCut = [&](Voxel a, Voxel b) {
      for (Direction n = 0; n < 6; ++n) {
        if (a + unitVector(n) == b && cut.count(Surfel{a, n}.key())) return true;
        if (b + unitVector(n) == a && cut.count(Surfel{b, n}.key())) return true;
      }
      return false;
    };
    std::vector<int> seen(value_.size(), 0);
    std::vector<Voxel> stack;
    for (const Surfel& s : sigma) {
      if (seen[id(s.inside())]) continue;
      seen[id(s.inside())] = 1;
      stack.push_back(s.inside());
    }
    std::set<std::uint64_t> exterior;
    for (const Surfel& s : sigma) exterior.insert(Surfel{s.outside(), 0}.key());
    while (!stack.empty()) {
      const Voxel v = stack.back();
      stack.pop_back();
      if (exterior.count(Surfel{v, 0}.key())) return false;
      for (Direction n = 0; n < 6; ++n) {
        const Voxel w = v + unitVector(n);
        if (!inPadded(w) || seen[id(w)] || isCut(v, w)) continue;
        seen[id(w)] = 1;
        stack.push_back(w);
      }
    }
    return true;
  }

 private:
  bool inPadded(Voxel v) const {
    return v.x >= -1 && v.y >= -1 && v.z >= -1 && v.x <= dims_.nx && v.y <= dims_.ny &&
           v.z <= dims_.nz;
  }
  int id(Voxel v) const { return ((v.z + 1) * py_ + (v.y + 1)) * px_ + (v.x + 1); }

  Dims dims_;
  int px_, py_, pz_;
  std::vector<char> value_;
  std::vector<int> component_;
};

/// A random 0/1 volume with the given density, from a fixed seed.
inline BinaryVolume randomVolume(Dims dims, double density, std::uint32_t seed) {
  BinaryVolume v(dims);
  std::mt19937 rng(seed);
  std::bernoulli_distribution bit(density);
  for (auto& x : v.data()) x = bit(rng);
  return v;
}

/// The volume whose voxel i (x fastest) is bit i of `bits`.
inline BinaryVolume volumeFromBits(Dims dims, std::uint64_t bits) {
  BinaryVolume v(dims);
  for (std::size_t i = 0; i < v.data().size(); ++i) v.data()[i] = (bits >> i) & 1;
  return v;
}

/// Sorted surfel keys.
inline std::vector<std::uint64_t> sortedKeys(const std::vector<Surfel>& surfels) {
  std::vector<std::uint64_t> k;
  for (const Surfel& s : surfels) k.push_back(s.key());
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace surftrack::testing
