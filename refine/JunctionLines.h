// Decimation along the junction lines of a conforming complex (docs/theory.md §12,
// "Decimating the complex", the junction lines). The walls' own decimation (ComplexDecimation.h)
// locks every vertex of two walls or more, so where walls are small most triangles hang on the
// junction lines and a reduction stops far from its target. Here a vertex v *inside* a junction
// line — exactly two of its edges are each in three triangles or more (the line's), and every
// region's triangles at v form one closed disc — goes into one of its two neighbours u on the
// line: a halfedge collapse done in every wall at v at once. The triangles on the edge uv (one in
// each wall along the line) go; v is renamed u in the others; no point moves. It is allowed only if
//  1. u is not a pinch (every region's triangles at u are one closed disc);
//  2. the link condition holds in the complex (every common neighbour of u and v is the third
//     vertex of a triangle on uv; no (v, x, y) and (u, x, y) both exist) and in every region
//     that has both u and v (its common neighbours of u and v are exactly the two third vertices
//     of its triangles on uv), so that every region's surface keeps its topology;
//  3. no triangle it changes turns by more than the normal deviation or becomes degenerate, and
//     none meets another triangle of the complex other than in the vertices they share;
//  4. with a distance bound E, every changed triangle lies within E of its wall's original
//     triangles, and every sample its wall's removed and changed triangles answered for is
//     within E of one of that wall's triangles after it, whole (ProvenDistanceGuard.h's two ways);
//  5. every region at v is still above its target (the reduction of its triangles): a wall may go
//     below its own where its regions' other walls could not reach theirs; when balancing
//     (DecimatedComplex::balancing), some region at v is above its target and every other may
//     lose its two triangles above its floor.
// The candidates go cheapest first: by the distance from v to the line's chord that replaces it.
#pragma once

#include <cstddef>

#include "DecimatedComplex.h"
#include "TopologySafeDecimation.h"

namespace surftrack::refine {

/// Collapses the vertices inside the junction lines of `complex` as the conditions above allow
/// (parameters: maxError, maxNormalDeviation, cancel); returns how many went.
/// \throw Cancelled when parameters.cancel is raised.
std::size_t simplifyJunctionLines(DecimatedComplex& complex, const DecimationParameters& parameters);

}  // namespace surftrack::refine
