// The surface graph G(Sigma, beta) of a kappa-lambda-boundary (paper §5.2, before Prop. 39):
// vertices are the surfels of Sigma, arcs the beta-adjacencies between them.
#pragma once

#include <cstdint>
#include <vector>

#include <boost/graph/compressed_sparse_row_graph.hpp>

#include "AdjacencyPair.h"
#include "BinaryBricks.h"
#include "Surfel.h"

namespace surftrack {

/// A Boost.Graph CSR graph; every beta-arc {s, t} is stored as the two arcs s->t and t->s,
/// so out-edges of a vertex are its beta-neighbours. Their order is that of betaNeighbours:
/// first the 4 edge neighbours, one per direction e orthogonal to the normal, by increasing
/// Direction code; then the strict-26 links. The converter relies on that order.
using SurfelGraph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property,
                                                       boost::no_property, boost::no_property,
                                                       std::uint32_t, std::uint32_t>;

struct SurfaceGraph {
  AdjacencyPair pair = AdjacencyPair::k26_6;
  std::vector<Surfel> surfels;  ///< surfels[v] is the surfel of vertex v
  SurfelGraph graph;
  /// The image near the surface, as the tracker read it: the bricks that hold the surfels'
  /// 1-voxels, with their aprons. The converter takes the cube configurations from here
  /// (extractLoops(graph)), so it need not read the image again. Empty for graphs not made by
  /// trackComponent.
  BinaryBricks bricks;

  std::size_t surfelCount() const { return surfels.size(); }
  /// Number of beta-arcs (each undirected arc counted once).
  std::size_t arcCount() const { return boost::num_edges(graph) / 2; }
};

/// Builds the Boost CSR graph from per-vertex neighbour lists given in vertex order
/// (rowStart has one entry per vertex plus one; targets[rowStart[v]..rowStart[v+1]) are v's).
SurfelGraph makeSurfelGraph(std::vector<std::uint32_t>&& rowStart,
                            std::vector<std::uint32_t>&& targets);

}  // namespace surftrack
