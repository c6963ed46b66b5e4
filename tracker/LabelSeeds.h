// Seeds for every label of a label image in one scan (docs/theory.md, "Label maps"). For a
// label L the 1-voxels are f = L (paper §3.1); a kappa-lambda-boundary of that binary image
// always holds a surfel whose normal is +x or -x (its points of largest x lie on such a surfel,
// since every grid edge borders an even number of its surfels). So the surfels between the two
// ends of each run of equal labels along x — run ends against another label or the domain
// border — contain a seed of every boundary of every label, and a scan of the rows finds them
// all: one comparison per voxel, no cube visited, nothing triangulated.
#pragma once

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "Image.h"
#include "Surfel.h"

namespace surftrack {

/// The x-surfels of each label met by a scan, with its voxel count.
template <class T>
struct LabelSeeds {
  std::vector<T> labels;                          ///< the labels met (background excluded)
  std::vector<std::uint64_t> voxels;              ///< voxels[i]: voxels of labels[i]
  /// surfels[i]: Surfel::key() of every surfel (c, c ± x) with f(c) = labels[i] and f(c ± x)
  /// another label or outside the domain, in increasing key order.
  std::vector<std::vector<std::uint64_t>> surfels;
};

/// The seeds of planes z in [z0, z1) of `image`; labels in order of first meeting.
template <class T>
LabelSeeds<T> scanLabelSeeds(const VolumeRef<T>& image, T background, int z0, int z1) {
  LabelSeeds<T> out;
  std::unordered_map<T, std::uint32_t> indexOf;
  const Dims& dims = image.dims;
  for (int z = z0; z < z1; ++z)
    for (int y = 0; y < dims.ny; ++y) {
      const T* row = &image.at(0, y, z);
      const std::ptrdiff_t sx = image.sx;
      int x = 0;
      while (x < dims.nx) {
        const T value = row[x * sx];
        const int start = x;
        while (++x < dims.nx && row[x * sx] == value) {
        }
        if (value == background) continue;
        auto [it, added] = indexOf.try_emplace(value, std::uint32_t(out.labels.size()));
        if (added) {
          out.labels.push_back(value);
          out.voxels.push_back(0);
          out.surfels.emplace_back();
        }
        const std::uint32_t i = it->second;
        out.voxels[i] += std::uint64_t(x - start);
        // The run [start, x): its -x surfel at start and its +x surfel at x - 1, by key (+x,
        // direction 0, comes first on one voxel).
        const std::uint64_t left = Surfel{Voxel{start, y, z}, 1}.key(),
                            right = Surfel{Voxel{x - 1, y, z}, 0}.key();
        auto& keys = out.surfels[i];
        if (left < right) {
          keys.push_back(left);
          keys.push_back(right);
        } else {
          keys.push_back(right);
          keys.push_back(left);
        }
      }
    }
  return out;
}

/// The seeds of consecutive slabs (parts[k] holds planes before those of parts[k + 1]) as one:
/// labels in increasing order, each label's surfels still in key order.
template <class T>
LabelSeeds<T> mergeLabelSeeds(std::vector<LabelSeeds<T>>&& parts) {
  LabelSeeds<T> out;
  for (const LabelSeeds<T>& p : parts) out.labels.insert(out.labels.end(), p.labels.begin(), p.labels.end());
  std::sort(out.labels.begin(), out.labels.end());
  out.labels.erase(std::unique(out.labels.begin(), out.labels.end()), out.labels.end());
  const std::size_t n = out.labels.size();
  out.voxels.assign(n, 0);
  out.surfels.resize(n);
  std::vector<std::vector<std::uint32_t>> globalOf(parts.size());
  std::vector<std::size_t> sizes(n, 0);
  for (std::size_t k = 0; k < parts.size(); ++k)
    for (std::size_t i = 0; i < parts[k].labels.size(); ++i) {
      const auto g = std::uint32_t(std::lower_bound(out.labels.begin(), out.labels.end(), parts[k].labels[i]) -
                                   out.labels.begin());
      globalOf[k].push_back(g);
      sizes[g] += parts[k].surfels[i].size();
    }
  for (std::size_t g = 0; g < n; ++g) out.surfels[g].reserve(sizes[g]);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    for (std::size_t i = 0; i < parts[k].labels.size(); ++i) {
      const std::uint32_t g = globalOf[k][i];
      out.voxels[g] += parts[k].voxels[i];
      out.surfels[g].insert(out.surfels[g].end(), parts[k].surfels[i].begin(), parts[k].surfels[i].end());
    }
    parts[k] = {};  // free as we go
  }
  return out;
}

}  // namespace surftrack
