// Digital surface tracking (paper §4.3, §5.2): from one seed surfel, a breadth-first traversal
// of beta^{kappa lambda}-adjacencies visits exactly the kappa-lambda-boundary that contains the
// seed (Proposition 39) and records its surface graph. The work and memory are proportional to
// the number of surfels: nothing here is sized by the image volume, so it runs on implicit
// images far too large to store.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "AdjacencyPair.h"
#include "BetaAdjacency.h"
#include "BinaryBrickCache.h"
#include "BrickSlot.h"
#include "BrickStepTable.h"
#include "BrickSurfelSet.h"
#include "FrontQueue.h"
#include "HugePages.h"
#include "Image.h"
#include "SurfaceGraph.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace surftrack {

/// Called now and then during long traversals with the number of surfels found so far.
using TrackingProgress = std::function<void(std::size_t surfelsFound)>;

/// Throws std::invalid_argument unless the domain fits the surfel key and the seed lies on it.
template <class BinaryImage>
void requireTrackableSeed(const BinaryImage& image, const Surfel& seed) {
  const Dims& dims = image.dims();
  for (int a = 0; a < 3; ++a)
    if (dims[a] <= 0 || dims[a] >= Surfel::kCoordinateLimit - 2)
      throw std::invalid_argument("image dimensions must be in [1, " +
                                  std::to_string(Surfel::kCoordinateLimit - 3) + "]");
  for (Voxel v : {seed.inside(), seed.outside()})
    for (int a = 0; a < 3; ++a)
      if (v[a] < -1 || v[a] > dims[a]) {
        std::ostringstream msg;
        msg << "seed " << seed << " lies outside the image domain [0," << dims.nx << ")x[0,"
            << dims.ny << ")x[0," << dims.nz << ")";
        throw std::invalid_argument(msg.str());
      }
  requireBoundarySurfel(image, seed);
}

namespace detail {

// The per-arc lambdas of the traversal must be inlined: as calls they double its cost.
#define SURFTRACK_INLINE __attribute__((always_inline))

/// The most bricks forEachBetaNeighbour can create for one surfel: its neighbours lie in the
/// 26 bricks around its own, but only in those that share the corner its voxel is nearest to.
inline constexpr std::size_t kMaxBricksCreatedPerSurfel = 7;

/// Calls f(brick, slot) for each beta-neighbour of the surfel in `slot` of brick b, in the
/// order of betaNeighbours. Neighbours in other bricks come through cache.linkedBrick, which
/// creates (binarises) up to kMaxBricksCreatedPerSurfel bricks on first use.
template <class Cache, class F>
[[gnu::always_inline]] inline void forEachBetaNeighbour(Cache& cache, const BrickStepTable& steps,
                                                        std::uint32_t b, int slot, F&& f) {
  const int voxel = slot & 511;
  const NeighbourhoodSlices slices = cache.neighbourhoodSlices(b, voxel);
  const std::uint8_t border = brickslot::kBorderFlags[voxel];
  const Direction n = Direction(slot >> 9);
  auto follow = [&](const BrickStep& step) SURFTRACK_INLINE {
    if (border & step.crossMask) [[unlikely]] {
      const int x = (voxel & 7) + step.dx, y = ((voxel >> 3) & 7) + step.dy, z = (voxel >> 6) + step.dz;
      const std::uint32_t brick =
          cache.linkedBrick(b, ((x + 8) >> 3) + 3 * ((y + 8) >> 3) + 9 * ((z + 8) >> 3));
      f(brick, brickslot::slotOf(brickslot::voxelOf(x & 7, y & 7, z & 7), step.n));
    } else {
      f(b, slot + step.deltaSlot);
    }
  };
  const int pattern = steps.edgePattern(n, slices.bits);
  const auto& edges = steps.edges(n);
  follow(edges[0].result[pattern & 3]);
  follow(edges[1].result[(pattern >> 2) & 3]);
  follow(edges[2].result[(pattern >> 4) & 3]);
  follow(edges[3].result[pattern >> 6]);
  // Rule (iv); strictOnes / strictZeros never match when the pair has no such links.
  if (unsigned candidates = steps.cubeCandidates(n, pattern)) [[unlikely]] {
    const std::uint32_t bits = slices.bits[0] | slices.bits[1] << 9 | slices.bits[2] << 18;
    for (; candidates; candidates &= candidates - 1) {
      const auto& cube = steps.cubes(n)[std::countr_zero(candidates)];
      const std::uint32_t m = bits & cube.mask;
      if (m == cube.strictOnes || m == cube.strictZeros)
        for (const BrickStep& link : cube.links[m == cube.strictOnes ? 0 : 1]) follow(link);
    }
  }
}

}  // namespace detail

/// The surface graph G(Sigma, beta) of the kappa-lambda-boundary Sigma containing `seed`.
/// Vertices are numbered by position: 8x8x8 brick by brick along a Z-order curve, so that
/// neighbours in space are mostly neighbours in memory; the out-arcs of each vertex are in
/// the order of betaNeighbours (see SurfaceGraph.h).
///
/// Two passes over the surface, both local to a brick and its neighbours (BrickStepTable.h):
/// a breadth-first traversal marks the surfels of Sigma in per-brick bitmaps and counts the
/// arcs leaving each brick; then, brick by brick, each marked surfel's beta-neighbours are
/// found again and written as vertex indices, which are ranks in the bitmaps. Recomputing a
/// neighbour costs less than storing and re-reading it. The second pass only reads (the bricks
/// and their links all exist after the first), and each brick's first vertex and first arc are
/// known from the bitmaps' ranks and the prefix sums of the arc counts, so runs of bricks are
/// written on `threads` threads (0: all cores) at once; the graph is the same for any number.
template <class BinaryImage>
SurfaceGraph trackComponent(const BinaryImage& image, const Surfel& seed, AdjacencyPair pair,
                            const TrackingProgress& progress = {}, int threads = 1) {
  requireTrackableSeed(image, seed);
  BinaryBrickCache<BinaryImage> cache(image);
  const BrickStepTable steps(pair);
  BrickSurfelSet visited;
  std::vector<std::uint32_t> arcsOfBrick;  // out-arcs of the surfels of each brick

  // 1. Breadth-first traversal of beta-arcs from the seed; queue entries are brick << 12 | slot.
  std::size_t arcs = 0;
  {
    FrontQueue<std::uint64_t> queue;
    std::size_t nextReport = std::size_t(1) << 20;
    const Voxel c = seed.inside();
    const std::uint32_t b = cache.brickOf(c);
    const int slot = brickslot::slotOf(brickslot::voxelOf(c.x & 7, c.y & 7, c.z & 7), seed.n);
    visited.resize(cache.bricks().size());
    visited.insert(b, slot);
    queue.push(std::uint64_t(b) << 12 | std::uint64_t(slot));
    while (!queue.empty()) {
      queue.reserve(kMaxBetaNeighbours);
      visited.resize(cache.bricks().size() + detail::kMaxBricksCreatedPerSurfel);
      const std::uint64_t entry = queue.pop();
      const std::uint32_t from = std::uint32_t(entry >> 12);
      std::uint32_t out = 0;
      detail::forEachBetaNeighbour(
          cache, steps, from, int(entry & 4095), [&](std::uint32_t to, int toSlot) SURFTRACK_INLINE {
            ++out;
            queue.pushIf(std::uint64_t(to) << 12 | std::uint64_t(toSlot), visited.insert(to, toSlot));
          });
      if (from >= arcsOfBrick.size()) arcsOfBrick.resize(std::size_t(from) + 1, 0);
      arcsOfBrick[from] += out;
      arcs += out;
      if (progress && queue.pushed() >= nextReport) {
        progress(queue.pushed());
        nextReport += std::size_t(1) << 20;
      }
    }
  }

  // 2. Vertices by rank, arcs by recomputing each vertex's neighbours, in runs of bricks.
  const std::uint32_t count = visited.number(cache.bricks().bricksInSpaceOrder());
  const std::vector<std::uint32_t>& order = visited.order();
  arcsOfBrick.resize(cache.bricks().size(), 0);
  SurfaceGraph result;
  result.pair = pair;
  resizeHugePages(result.surfels, count);
  std::vector<std::uint32_t> rowStart, targets;
  resizeHugePages(rowStart, std::size_t(count) + 1);
  resizeHugePages(targets, arcs);
  // firstArc[i]: the first arc of brick order[i]'s surfels.
  std::vector<std::size_t> firstArc(order.size() + 1, 0);
  for (std::size_t i = 0; i < order.size(); ++i) firstArc[i + 1] = firstArc[i] + arcsOfBrick[order[i]];
  // The links and bricks only read from here on: knownLink instead of linkedBrick.
  struct FrozenCache {
    const BinaryBrickCache<BinaryImage>& cache;
    NeighbourhoodSlices neighbourhoodSlices(std::uint32_t b, int voxel) const {
      return cache.neighbourhoodSlices(b, voxel);
    }
    std::uint32_t linkedBrick(std::uint32_t b, int s) const { return cache.knownLink(b, s); }
  };
  const FrozenCache frozen{cache};
  auto writeBricks = [&](std::size_t begin, std::size_t end) {
    if (begin == end) return;
    FrozenCache links = frozen;
    std::uint32_t v = visited.firstIndex(order[begin]);
    std::size_t a = firstArc[begin];
    for (std::size_t i = begin; i < end; ++i)
      visited.forEachIn(order[i], [&](std::uint32_t brick, int slot) SURFTRACK_INLINE {
        const int voxel = slot & 511;
        result.surfels[v] = Surfel{cache.bricks().brickOrigin(brick) + Voxel{voxel & 7, (voxel >> 3) & 7, voxel >> 6},
                                   Direction(slot >> 9)};
        detail::forEachBetaNeighbour(links, steps, brick, slot, [&](std::uint32_t to, int toSlot) SURFTRACK_INLINE {
          targets[a++] = visited.index(to, toSlot);
        });
        rowStart[++v] = std::uint32_t(a);
      });
  };
  // Runs of up to 64 bricks, about 64 runs at least; left to choose (0), small surfaces stay on
  // this thread (waking threads would cost more).
  const std::size_t kRun = std::clamp<std::size_t>(order.size() / 64, 1, 64);
  if (threads == 1 || (threads == 0 && count < (1u << 16))) {
    writeBricks(0, order.size());
  } else {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
      tbb::parallel_for(std::size_t(0), (order.size() + kRun - 1) / kRun, [&](std::size_t r) {
        writeBricks(r * kRun, std::min(order.size(), (r + 1) * kRun));
      });
    });
  }
  result.graph = makeSurfelGraph(std::move(rowStart), std::move(targets));
  result.bricks = std::move(cache).release();
  return result;
}

#undef SURFTRACK_INLINE

}  // namespace surftrack
