// The beta^{kappa lambda} adjacency between boundary surfels (paper Definition 38, Figure 7),
// in the per-edge form of docs/theory.md, 'The beta-adjacency': across each of the 4 edges of a
// surfel's square there is exactly one neighbour (rules (i)–(iii)); with kappa = 26
// (lambda = 26) each strict 26-configuration of 1-voxels (0-voxels) among the surfel's 4
// digital 3-cubes adds 2 "vertex" links (rule (iv)).
#pragma once

#include <array>
#include <sstream>
#include <stdexcept>

#include "AdjacencyPair.h"
#include "Surfel.h"

namespace surftrack {

/// 4 edge neighbours + at most 2 strict-26 links in each of the 4 cubes.
inline constexpr int kMaxBetaNeighbours = 12;

/// Is (c, d) a boundary surfel of the binary image: c a 1-voxel and d a 0-voxel?
template <class BinaryImage>
inline bool isBoundarySurfel(const BinaryImage& image, const Surfel& s) {
  return image(s.inside()) && !image(s.outside());
}

/// Throws std::invalid_argument naming the offending voxel when s is not a boundary surfel.
template <class BinaryImage>
inline void requireBoundarySurfel(const BinaryImage& image, const Surfel& s) {
  bool c = image(s.inside()), d = image(s.outside());
  if (c && !d) return;
  std::ostringstream msg;
  msg << s << " is not a boundary surfel: ";
  if (!c) msg << "c=" << s.inside() << " is a 0-voxel";
  if (!c && d) msg << " and ";
  if (d) msg << "d=" << s.outside() << " is a 1-voxel";
  throw std::invalid_argument(msg.str());
}

/// The beta-neighbours of boundary surfel t. Writes them to `out` and returns their number.
/// The first 4 are the edge neighbours, in the order of the directions orthogonal to t's
/// normal (increasing Direction code); strict-26 links follow.
template <class BinaryImage>
inline int betaNeighbours(const BinaryImage& image, const Surfel& t, AdjacencyPair pair,
                          Surfel* out) {
  const Voxel u = t.inside();
  const Voxel n = unitVector(t.n);
  const Voxel un = u + n;
  const int normalAxis = axisOf(t.n);
  const bool kappa6 = kappa(pair) == 6;
  int count = 0;
  // Rules (i)–(iii) across the edge towards e: a = I(u+e), b = I(u+n+e).
  bool a[6], b[6];
  for (Direction ed = 0; ed < 6; ++ed) {
    if (axisOf(ed) == normalAxis) continue;
    const Voxel e = unitVector(ed);
    a[ed] = image(u + e);
    b[ed] = image(un + e);
    if (a[ed] && !b[ed])
      out[count++] = Surfel{u + e, t.n};                 // (iii) parallel surfel
    else if (!a[ed] && (!b[ed] || kappa6))
      out[count++] = Surfel{u, ed};                      // (i) same 1-voxel, turns inward
    else
      out[count++] = Surfel{un + e, opposite(ed)};       // (ii) same 0-voxel, turns outward
  }
  const bool kappa26 = kappa(pair) == 26, lambda26 = lambda(pair) == 26;
  if (!kappa26 && !lambda26) return count;
  // Rule (iv): the 4 cubes spanned by n and s1*e1, s2*e2 around t's edge.
  const auto [axis1, axis2] = std::array<int, 2>{normalAxis == 0 ? 1 : 0, normalAxis == 2 ? 1 : 2};
  for (int q = 0; q < 4; ++q) {
    const Direction d1 = directionOf(axis1, (q & 1) ? -1 : 1);
    const Direction d2 = directionOf(axis2, (q & 2) ? -1 : 1);
    const Voxel e1 = unitVector(d1), e2 = unitVector(d2);
    // The 8 corners: u + alpha n + beta e1 + gamma e2. u is 1, u+n is 0; a/b give 4 more.
    const bool ue1 = a[d1], ue2 = a[d2], une1 = b[d1], une2 = b[d2];
    const bool ue12 = image(u + e1 + e2), une12 = image(un + e1 + e2);
    if (kappa26 && !ue1 && !ue2 && !une1 && !une2 && !ue12 && une12) {
      // Strict 26-configuration of 1-voxels p = u, q = u+n+e1+e2: t = A_n links to B_e1, B_e2.
      const Voxel qv = un + e1 + e2;
      out[count++] = Surfel{qv, opposite(d1)};
      out[count++] = Surfel{qv, opposite(d2)};
    } else if (lambda26 && ue1 && ue2 && une1 && une2 && !ue12 && une12) {
      // Strict 26-configuration of 0-voxels p' = u+n, q' = u+e1+e2: links to the surfels
      // (q' - e_j, q') for e_j in {e1, e2}.
      const Voxel qv = u + e1 + e2;
      out[count++] = Surfel{qv - e1, d1};
      out[count++] = Surfel{qv - e2, d2};
    }
  }
  return count;
}

}  // namespace surftrack
