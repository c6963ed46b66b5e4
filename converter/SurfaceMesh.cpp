#include "SurfaceMesh.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "HugePages.h"

namespace surftrack {

OpenMesh::VPropHandleT<Surfel> surfelProperty(const SurfaceMesh& mesh) {
  OpenMesh::VPropHandleT<Surfel> handle;
  if (!mesh.get_property_handle(handle, kSurfelPropertyName))
    throw std::invalid_argument(std::string("mesh has no '") + kSurfelPropertyName +
                                "' vertex property");
  return handle;
}

Surfel surfelOf(const SurfaceMesh& mesh, SurfaceMesh::VertexHandle vh) {
  return mesh.property(surfelProperty(mesh), vh);
}

namespace {

void checkSizes(const char* who, const TriangleMesh& mesh,
                const std::vector<std::array<double, 3>>& positions) {
  if (positions.size() != mesh.surfels.size())
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(positions.size()) +
                                " positions for " + std::to_string(mesh.surfels.size()) +
                                " vertices");
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (std::uint32_t v : mesh.triangles[f])
      if (v >= positions.size())
        throw std::invalid_argument(std::string(who) + ": triangle " + std::to_string(f) +
                                    " uses vertex " + std::to_string(v) + " out of range");
}

[[noreturn]] void notAManifold(const std::string& what) {
  throw std::logic_error("toSurfaceMesh: " + what +
                         ": the triangles are not a closed oriented manifold");
}

/// Why the two directed copies of edge {u, v} do not pair (a slow scan, on the error path
/// only): the triangles through the edge, in each direction.
[[noreturn]] void badEdge(const std::vector<std::array<std::uint32_t, 3>>& T, std::uint32_t u,
                          std::uint32_t v) {
  std::size_t forward = 0, backward = 0;
  for (const auto& t : T)
    for (int j = 0; j < 3; ++j) {
      forward += t[j] == u && t[j == 2 ? 0 : j + 1] == v;
      backward += t[j] == v && t[j == 2 ? 0 : j + 1] == u;
    }
  std::string edge = "edge (" + std::to_string(u) + ", " + std::to_string(v) + ")";
  if (forward + backward == 1) notAManifold(edge + " is in one triangle only");
  if (forward + backward > 2)
    notAManifold(edge + " is in " + std::to_string(forward + backward) + " triangles");
  notAManifold(edge + " runs twice in the same direction in its two triangles");
}

}  // namespace

// Corner (f, j) is vertex t[j] of triangle f = T[f]; its outgoing directed edge t[j] -> t[j+1]
// (indices mod 3) is the halfedge of face f leaving t[j], numbered h = 3f + j; its incoming one,
// t[j-1] -> t[j], is 3f + (j+2) % 3.
//
// Everything is checked and paired vertex by vertex, from the corners of each vertex u alone,
// (u, a_i, b_i) with a_i = t[j+1], b_i = t[j-1]: the triangles of u form one fan, turning
// around u, iff "corner k follows corner i when a_k = b_i" is a bijection of u's corners with a
// single cycle. Corner k then shares edge {u, b_i} with corner i: u's outgoing u -> a_k of k is
// the opposite of the incoming b_i -> u of i. Over all vertices, this is also the test that
// every edge is in exactly two triangles, in opposite directions: a directed edge u -> v
// present twice, or without its reverse, leaves the follower relation at u short of a
// bijection. (Paper §5.2 and docs/theory.md: the converter's triangles always pass.)
namespace {

constexpr std::uint32_t kNextCorner[4] = {1, 2, 0, 0}, kPrevCorner[4] = {2, 0, 1, 0};
/// From corner j of a triangle to the next and previous corner, within the triangle's three.
constexpr std::int32_t kToNext[4] = {1, 1, -2, 0}, kToPrev[4] = {2, -1, -1, 0};

/// follower[i] for a long fan: the first k with a_k = b_i (by a binary search among the
/// sorted a_k), or d if there is none; follower[d] = d.
void longFanFollowers(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b,
                      std::vector<std::uint32_t>& follower) {
  const std::uint32_t d = std::uint32_t(a.size());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sorted(d);
  for (std::uint32_t k = 0; k < d; ++k) sorted[k] = {a[k], k};
  std::sort(sorted.begin(), sorted.end());
  follower.assign(d + 1, d);
  for (std::uint32_t i = 0; i < d; ++i) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(),
                                     std::pair<std::uint32_t, std::uint32_t>{b[i], 0});
    if (it != sorted.end() && it->first == b[i]) follower[i] = it->second;
  }
}

/// The error of a vertex u among whose corners c[0 .. d) one is followed by u again.
[[noreturn]] void degenerate(const std::vector<std::array<std::uint32_t, 3>>& T,
                             std::uint32_t u, const std::uint32_t* c, std::uint32_t d) {
  for (std::uint32_t i = 0; i < d; ++i) {
    const std::uint32_t f = c[i] >> 2;
    const auto& t = T[f];
    if (t[kNextCorner[c[i] & 3]] == u)
      notAManifold("triangle " + std::to_string(f) + " (" + std::to_string(t[0]) + ", " +
                   std::to_string(t[1]) + ", " + std::to_string(t[2]) + ") is degenerate");
  }
  throw std::logic_error("toSurfaceMesh: internal error: no degenerate triangle at a vertex");
}

/// The error of a vertex u whose corners c[0 .. d) failed the fan test: an edge {u, v} whose
/// two directed copies do not pair, else triangles that form several fans.
[[noreturn]] void slowFanCheck(const std::vector<std::array<std::uint32_t, 3>>& T,
                               std::uint32_t u, const std::uint32_t* c, std::uint32_t d) {
  std::vector<std::uint32_t> a(d), b(d);
  for (std::uint32_t i = 0; i < d; ++i) {
    const auto& t = T[c[i] >> 2];
    a[i] = t[kNextCorner[c[i] & 3]];
    b[i] = t[kPrevCorner[c[i] & 3]];
  }
  // Every directed edge u -> v once (a), v -> u once (b), and each v in both.
  std::vector<std::uint32_t> sa = a, sb = b;
  std::sort(sa.begin(), sa.end());
  std::sort(sb.begin(), sb.end());
  for (std::uint32_t i = 0; i < d; ++i) {
    if (i + 1 < d && sa[i] == sa[i + 1]) badEdge(T, u, sa[i]);
    if (i + 1 < d && sb[i] == sb[i + 1]) badEdge(T, u, sb[i]);
    if (!std::binary_search(sb.begin(), sb.end(), sa[i])) badEdge(T, u, sa[i]);
    if (!std::binary_search(sa.begin(), sa.end(), sb[i])) badEdge(T, u, sb[i]);
  }
  // The edges pair: the follower map is a permutation, of several cycles.
  std::uint32_t i = 0, steps = 0;
  do {
    i = std::uint32_t(std::find(a.begin(), a.end(), b[i]) - a.begin());
    ++steps;
  } while (i != 0);
  notAManifold("the " + std::to_string(d) + " triangles of vertex " + std::to_string(u) +
               " do not form one fan (one fan has " + std::to_string(steps) + ")");
}

/// The fan of a vertex u with D <= 8 corners c[0 .. D) (most vertices), as in step 2 of
/// toSurfaceMesh with every loop unrolled and no branch: vertexAt is the triangles as one
/// array, deadEnd a slot of link[] for the writes of a corner with no follower. Returns false
/// if a triangle at u is degenerate or the fan is not one cycle (link[] is then partly written).
template <std::uint32_t D>
bool shortFan(const std::uint32_t* c, const std::uint32_t* vertexAt, std::uint32_t u,
              std::uint32_t* link, std::uint32_t deadEnd) {
  static_assert(D >= 1 && D <= 8);
  constexpr std::uint32_t kNone = ~std::uint32_t(0), kDead = 8;
  alignas(16) std::uint32_t a[8] = {kNone, kNone, kNone, kNone, kNone, kNone, kNone, kNone};
  // The walk may reach the dead end (a corner with no follower): it has an entry in each array
  // it indexes, so that a fan that is not one cycle reads and writes only its own slots.
  std::uint32_t b[D], out[kDead + 1], in[kDead + 1], follower[kDead + 1];
  out[kDead] = deadEnd, in[kDead] = deadEnd, follower[kDead] = kDead;
  for (std::uint32_t i = 0; i < D; ++i) {
    // Directed edge o = 3f + j is also where t[j] is in the triangles seen as one array.
    const std::uint32_t j = c[i] & 3, o = 3 * (c[i] >> 2) + j;
    a[i] = vertexAt[o + kToNext[j]];
    b[i] = vertexAt[o + kToPrev[j]];
    out[i] = o;
    in[i] = o + kToPrev[j];
  }
  std::uint32_t self = 0;  // lanes where a_k = u: a degenerate triangle
#if defined(__SSE2__)
  const auto lanes = [](__m128i x, __m128i y) {
    return std::uint32_t(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(x, y))));
  };
  const __m128i a0 = _mm_load_si128(reinterpret_cast<const __m128i*>(a));
  const __m128i a1 = _mm_load_si128(reinterpret_cast<const __m128i*>(a + 4));
  const __m128i uu = _mm_set1_epi32(int(u));
  self = lanes(a0, uu) | (D > 4 ? lanes(a1, uu) << 4 : 0);
  for (std::uint32_t i = 0; i < D; ++i) {
    const __m128i bi = _mm_set1_epi32(int(b[i]));
    const std::uint32_t match = lanes(a0, bi) | (D > 4 ? lanes(a1, bi) << 4 : 0);
    follower[i] = std::uint32_t(std::countr_zero(match | (1u << kDead)));
  }
#else
  for (std::uint32_t k = 0; k < D; ++k) self |= std::uint32_t(a[k] == u) << k;
  for (std::uint32_t i = 0; i < D; ++i) {
    std::uint32_t match = 0;
    for (std::uint32_t k = 0; k < D; ++k) match |= std::uint32_t(a[k] == b[i]) << k;
    follower[i] = std::uint32_t(std::countr_zero(match | (1u << kDead)));
  }
#endif
  // The walk: D steps from corner 0, pairing on the way the incoming edge of each corner with
  // the outgoing one of its follower; one cycle iff it first returns to 0 at the last step.
  std::uint32_t i = 0, returns = 0;
  for (std::uint32_t step = 0; step < D; ++step) {
    const std::uint32_t k = follower[i];
    link[out[k]] = in[i];
    returns += k == 0;
    i = k;
  }
  return self == 0 && i == 0 && returns == 1;
}

/// Steps 1 and 2 of the direct construction: the corners sorted by vertex, then each vertex's
/// fan checked to be one cycle, which pairs every directed edge h of the triangles (3f + j, from
/// corner j of triangle f) with its opposite link[h]. link has 3F + 1 entries (the last a dead
/// end). Checking every vertex's fan is what makes the triangles a closed, consistently oriented
/// 2-manifold: each directed edge is then used once and its opposite once, and each vertex's
/// triangles form one disc. \pre the sizes fit OpenMesh's int handles.
/// \throw std::invalid_argument for a vertex index out of range, std::logic_error (naming the
///        vertex and the reason) when the triangles are not a closed oriented manifold.
FreshArray<std::uint32_t> pairDirectedEdges(const std::vector<std::array<std::uint32_t, 3>>& T,
                                            std::size_t V) {
  const std::size_t F = T.size(), H = 3 * F;
  // 1. Counting sort of the corners by vertex (CSR): count (noting each corner's rank among
  //    its vertex's), prefix sum, fill; the corners of u are then corners[start[u] ..
  //    start[u+1]). The ranks, kept in link[] until step 2 needs the array, spare the fill a
  //    read-modify-write of start[] per corner, which consecutive triangles sharing vertices
  //    would chain.
  const FreshArray<std::uint32_t> start = freshArray<std::uint32_t>(V + 1);
  std::fill(start.get(), start.get() + V + 1, 0u);
  FreshArray<std::uint32_t> link = freshArray<std::uint32_t>(H + 1);  // + a dead end
  for (std::size_t f = 0; f < F; ++f) {
    const auto& t = T[f];
    if (std::max({t[0], t[1], t[2]}) >= V)
      throw std::invalid_argument("toSurfaceMesh: triangle " + std::to_string(f) +
                                  " uses vertex " + std::to_string(std::max({t[0], t[1], t[2]})) +
                                  " out of range");
    std::uint32_t* const rank = link.get() + 3 * f;
    rank[0] = start[t[0] + 1]++;
    rank[1] = start[t[1] + 1]++;
    rank[2] = start[t[2] + 1]++;
  }
  for (std::size_t v = 0; v < V; ++v) start[v + 1] += start[v];
  const FreshArray<std::uint32_t> corners = freshArray<std::uint32_t>(H);
  for (std::size_t f = 0; f < F; ++f) {
    const auto& t = T[f];
    const std::uint32_t* const rank = link.get() + 3 * f;
    const std::uint32_t c = std::uint32_t(f << 2);
    corners[start[t[0]] + rank[0]] = c;
    corners[start[t[1]] + rank[1]] = c | 1;
    corners[start[t[2]] + rank[2]] = c | 2;
  }

  // 2. Each vertex's fan (see above); link[h] is set to the opposite of each directed edge h.
  //    Fans of 3 to 8 corners go through shortFan<d>, the others through the same steps here:
  //    fans of up to kShort corners find a follower by comparing b_i with all the a_k at once
  //    (SSE2; the padding, ~0, is no vertex), the first a_k = b_i, or kShort if there is none
  //    (follower[kShort] = kShort: a dead end). The fan is then one cycle iff walking d
  //    steps from corner 0 first returns to it at step d: that also rules out a b_i matching
  //    no a_k, two corners with the same follower, and two equal a_k (the second is never a
  //    follower). Longer fans (a vertex of high degree) find followers by a binary search.
  //    On failure, slowFanCheck names the culprit.
  {
    constexpr std::uint32_t kShort = 16, kNone = ~std::uint32_t(0);
    alignas(16) std::uint32_t a[kShort], b[kShort], follower[kShort + 1];
    std::uint32_t out[kShort + 1], in[kShort + 1];
    // The dead end writes link[H] (and reads its own in[] slot, as shortFan's does).
    follower[kShort] = kShort, out[kShort] = in[kShort] = std::uint32_t(H);
    std::vector<std::uint32_t> longA, longB, longOut, longIn, longFollower;
    static_assert(sizeof(T[0]) == 3 * sizeof(std::uint32_t));
    const std::uint32_t* const vertexAt = T.empty() ? nullptr : T[0].data();
    for (std::size_t u = 0; u < V; ++u) {
      const std::uint32_t d = start[u + 1] - start[u];
      const std::uint32_t* const c = corners.get() + start[u];
      const auto fan = [&](auto size) {
        if (!shortFan<decltype(size)::value>(c, vertexAt, std::uint32_t(u), link.get(),
                                             std::uint32_t(H))) {
          for (std::uint32_t i = 0; i < d; ++i)
            if (vertexAt[3 * (c[i] >> 2) + kNextCorner[c[i] & 3]] == u)
              degenerate(T, std::uint32_t(u), c, d);
          slowFanCheck(T, std::uint32_t(u), c, d);
        }
      };
      switch (d) {  // the common fans, unrolled (the others, and errors, below)
        case 3: fan(std::integral_constant<std::uint32_t, 3>{}); continue;
        case 4: fan(std::integral_constant<std::uint32_t, 4>{}); continue;
        case 5: fan(std::integral_constant<std::uint32_t, 5>{}); continue;
        case 6: fan(std::integral_constant<std::uint32_t, 6>{}); continue;
        case 7: fan(std::integral_constant<std::uint32_t, 7>{}); continue;
        case 8: fan(std::integral_constant<std::uint32_t, 8>{}); continue;
        default: break;
      }
      const std::uint32_t *fol = follower, *po = out, *pi = in;
      if (d - 1 < kShort) {  // 1 <= d <= kShort
        std::fill(a, a + kShort, kNone);
        for (std::uint32_t i = 0; i < d; ++i) {
          // Directed edge o = 3f + j is also where t[j] is in the triangles seen as one array.
          const std::uint32_t j = c[i] & 3, o = 3 * (c[i] >> 2) + j;
          a[i] = vertexAt[o + kToNext[j]];
          b[i] = vertexAt[o + kToPrev[j]];
          out[i] = o;
          in[i] = o + kToPrev[j];
        }
#if defined(__SSE2__)
        const auto lanes = [](__m128i x, __m128i y) {
          return std::uint32_t(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(x, y))));
        };
        const __m128i a0 = _mm_load_si128(reinterpret_cast<const __m128i*>(a));
        const __m128i a1 = _mm_load_si128(reinterpret_cast<const __m128i*>(a + 4));
        const __m128i a2 = _mm_load_si128(reinterpret_cast<const __m128i*>(a + 8));
        const __m128i a3 = _mm_load_si128(reinterpret_cast<const __m128i*>(a + 12));
        const __m128i self = _mm_set1_epi32(int(u));
        if (lanes(a0, self) | lanes(a1, self) | lanes(a2, self) | lanes(a3, self))
          degenerate(T, std::uint32_t(u), c, d);
#else
        for (std::uint32_t i = 0; i < d; ++i)
          if (a[i] == u) degenerate(T, std::uint32_t(u), c, d);
#endif
        for (std::uint32_t i = 0; i < d; ++i) {
#if defined(__SSE2__)
          const __m128i bi = _mm_set1_epi32(int(b[i]));
          std::uint32_t match = lanes(a0, bi) | lanes(a1, bi) << 4;
          if (d > 8) match |= lanes(a2, bi) << 8 | lanes(a3, bi) << 12;
#else
          std::uint32_t match = 0;
          for (std::uint32_t k = 0; k < kShort; ++k) match |= std::uint32_t(a[k] == b[i]) << k;
#endif
          follower[i] = std::uint32_t(std::countr_zero(match | (1u << kShort)));
        }
      } else {
        if (d == 0) notAManifold("vertex " + std::to_string(u) + " is in no triangle");
        longA.resize(d), longB.resize(d), longOut.resize(d), longIn.resize(d);
        for (std::uint32_t i = 0; i < d; ++i) {
          const std::uint32_t f = c[i] >> 2, j = c[i] & 3;
          const auto& t = T[f];
          longA[i] = t[kNextCorner[j]];
          longB[i] = t[kPrevCorner[j]];
          longOut[i] = 3 * f + j;
          longIn[i] = 3 * f + kPrevCorner[j];
          if (longA[i] == u) degenerate(T, std::uint32_t(u), c, d);
        }
        longOut.push_back(std::uint32_t(H)), longIn.push_back(std::uint32_t(H));
        longFanFollowers(longA, longB, longFollower);
        fol = longFollower.data(), po = longOut.data(), pi = longIn.data();
      }
      // The walk, pairing on the way the incoming edge of each corner with the outgoing one of
      // its follower.
      std::uint32_t i = 0, steps = 0;
      do {
        const std::uint32_t k = fol[i];
        link[po[k]] = pi[i];
        i = k;
      } while (++steps < d && i != 0);
      if (i != 0 || steps != d) slowFanCheck(T, std::uint32_t(u), c, d);
    }
  }

  return link;
}

/// OpenMesh handles are ints; a corner f << 2 | j and a halfedge index with a flag bit below
/// also fit in 32 bits.
void requireHandleRange(std::size_t F, std::size_t V) {
  const std::size_t H = 3 * F;
  if (H > std::size_t(std::numeric_limits<int>::max()) ||
      V > std::size_t(std::numeric_limits<int>::max()))
    throw std::invalid_argument("toSurfaceMesh: " + std::to_string(F) +
                                " triangles and " + std::to_string(V) +
                                " vertices exceed OpenMesh's handle range");
}

}  // namespace

void requireClosedOrientedManifold(std::size_t vertexCount,
                                   const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  requireHandleRange(triangles.size(), vertexCount);
  pairDirectedEdges(triangles, vertexCount);
}


SurfaceMesh toSurfaceMesh(const TriangleMesh& mesh,
                          const std::vector<std::array<double, 3>>& positions) {
  const auto& T = mesh.triangles;
  const std::size_t V = mesh.surfels.size(), F = T.size(), H = 3 * F;
  if (positions.size() != V)
    throw std::invalid_argument("toSurfaceMesh: " + std::to_string(positions.size()) +
                                " positions for " + std::to_string(V) + " vertices");
  requireHandleRange(F, V);
  const FreshArray<std::uint32_t> link = pairDirectedEdges(T, V);

  // 3. Edges are numbered as add_face numbers them: edge e is the e-th met in face order, its
  //    halfedge 2e runs as in that first face and 2e + 1 opposite (as new_edge(from, to) makes
  //    them). A directed edge h is met first iff link[h] > h: in order, link[h] becomes then
  //    its halfedge index 2e, marked kFirst; one met second keeps its opposite, whose index
  //    (read, never written back) gives its own.
  //    blockEdges[b] counts the edges met before face b * kBlock (for step 4).
  constexpr std::uint32_t kFirst = 0x80000000u;  // halfedge indices are below 2^31
  constexpr std::size_t kBlock = 2048;           // faces, a multiple of 4
  std::vector<std::uint32_t> blockEdges(F / kBlock + 1);
  {
    std::uint32_t next = 0;  // the next even halfedge index
    std::size_t h = 0;
#if defined(__SSE2__)
    // Four at a time: met = link > h (all below 2^31: a signed comparison), then the indices
    // 2 * (the met ones before, among the four) + next.
    const __m128i flag = _mm_set1_epi32(int(kFirst)), two = _mm_set1_epi32(2);
    for (__m128i hv = _mm_setr_epi32(0, 1, 2, 3); h + 4 <= H; h += 4) {
      if (h % (3 * kBlock) == 0) blockEdges[h / (3 * kBlock)] = next / 2;
      __m128i* const p = reinterpret_cast<__m128i*>(link.get() + h);
      const __m128i l = _mm_loadu_si128(p), met = _mm_cmpgt_epi32(l, hv);
      const __m128i x = _mm_and_si128(met, two);
      __m128i sum = _mm_add_epi32(x, _mm_slli_si128(x, 4));
      sum = _mm_add_epi32(sum, _mm_slli_si128(sum, 8));  // inclusive prefix sums of x
      const __m128i index = _mm_or_si128(
          _mm_add_epi32(_mm_set1_epi32(int(next)), _mm_sub_epi32(sum, x)), flag);
      _mm_storeu_si128(p, _mm_or_si128(_mm_and_si128(met, index), _mm_andnot_si128(met, l)));
      next += std::uint32_t(_mm_cvtsi128_si32(_mm_shuffle_epi32(sum, 3)));
      hv = _mm_add_epi32(hv, _mm_set1_epi32(4));
    }
#endif
    for (; h < H; ++h) {
      if (h % (3 * kBlock) == 0) blockEdges[h / (3 * kBlock)] = next / 2;
      const bool met = link[h] > h;
      link[h] = met ? next | kFirst : link[h];
      next += met ? 2 : 0;
    }
  }
  const auto halfedgeOf = [&](std::uint32_t h) {
    const std::uint32_t l = link[h], opposite = link[l & ~kFirst];
    return (l & kFirst) ? l & ~kFirst : (opposite & ~kFirst) + 1;
  };

  // 4. The half-edge structure. Items are allocated with ArrayKernel::resize (creating them
  //    one by one costs a resize of each property per item): vertices and faces at once, edges
  //    block of faces by block (as many as a block can create at most), so that the edges
  //    resize default-constructs are still in cache when they are written. Each halfedge gets,
  //    with its face, its target vertex, face and next (which also sets the next one's prev);
  //    each face its halfedge (its third, as add_face), each vertex an outgoing halfedge.
  using VH = SurfaceMesh::VertexHandle;
  using HH = SurfaceMesh::HalfedgeHandle;
  using EH = SurfaceMesh::EdgeHandle;
  using FH = SurfaceMesh::FaceHandle;
  SurfaceMesh out;
  OpenMesh::VPropHandleT<Surfel> surfel;
  out.add_property(surfel, kSurfelPropertyName);
  const std::size_t E = H / 2;  // every directed edge is paired: H is even
  out.reserve(V, E, F);
  if (F > 0) {
    // Huge pages for the large arrays before their first write: the items (one of each made
    // to reach the buffers), the points and the surfels.
    out.resize(1, 1, 1);
    adviseHugePages(&out.vertex(VH(0)), V * sizeof(out.vertex(VH(0))));
    adviseHugePages(&out.edge(EH(0)), E * sizeof(out.edge(EH(0))));
    adviseHugePages(&out.face(FH(0)), F * sizeof(out.face(FH(0))));
    adviseHugePages(out.property(out.points_pph()).data_vector().data(),
                    V * sizeof(SurfaceMesh::Point));
    adviseHugePages(out.property(surfel).data_vector().data(), V * sizeof(Surfel));
  }
  // The surfels and points first, each written once (a Surfel's default constructor writes
  // zeros, a Point's nothing); resize then finds them at their size.
  out.property(surfel).data_vector().assign(mesh.surfels.begin(), mesh.surfels.end());
  auto& points = out.property(out.points_pph()).data_vector();
  points.resize(V);
  static_assert(sizeof(SurfaceMesh::Point) == sizeof(positions[0]) &&
                std::is_trivially_copyable_v<SurfaceMesh::Point>);
  if (V > 0)
    std::memcpy(static_cast<void*>(points.data()), positions.data(), V * sizeof(points[0]));
  out.resize(V, 0, F);
  for (std::size_t f = 0; f < F; ++f) {
    if (f % kBlock == 0) out.resize(V, std::min(E, blockEdges[f / kBlock] + 3 * kBlock), F);
    const auto& t = T[f];
    const std::uint32_t h = std::uint32_t(3 * f);
    const HH he[3] = {HH(int(halfedgeOf(h))), HH(int(halfedgeOf(h + 1))),
                      HH(int(halfedgeOf(h + 2)))};
    const FH fh{int(f)};
    for (int j = 0; j < 3; ++j) {
      out.set_vertex_handle(he[j], VH(int(t[kNextCorner[j]])));
      out.set_face_handle(he[j], fh);
      out.set_next_halfedge_handle(he[j], he[kNextCorner[j]]);
      out.set_halfedge_handle(VH(int(t[j])), he[j]);
    }
    out.set_halfedge_handle(fh, he[2]);
  }
  return out;
}

SurfaceMesh toSurfaceMeshByAddFace(const TriangleMesh& mesh,
                                   const std::vector<std::array<double, 3>>& positions) {
  checkSizes("toSurfaceMeshByAddFace", mesh, positions);
  SurfaceMesh out;
  out.reserve(mesh.surfels.size(), 3 * mesh.triangles.size() / 2, mesh.triangles.size());
  OpenMesh::VPropHandleT<Surfel> surfel;
  out.add_property(surfel, kSurfelPropertyName);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const auto& p = positions[v];
    const SurfaceMesh::VertexHandle vh = out.add_vertex(SurfaceMesh::Point(p[0], p[1], p[2]));
    out.property(surfel, vh) = mesh.surfels[v];
  }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])  // add_face only asserts it
      throw std::logic_error("toSurfaceMeshByAddFace: triangle " + std::to_string(f) +
                             " is degenerate");
    const SurfaceMesh::FaceHandle fh =
        out.add_face(out.vertex_handle(t[0]), out.vertex_handle(t[1]), out.vertex_handle(t[2]));
    if (!fh.is_valid()) {
      std::ostringstream msg;
      msg << "toSurfaceMeshByAddFace: OpenMesh refused triangle " << f << " (" << t[0] << ", "
          << t[1] << ", " << t[2] << "): the triangles are not an oriented manifold";
      throw std::logic_error(msg.str());
    }
  }
  return out;
}

}  // namespace surftrack
