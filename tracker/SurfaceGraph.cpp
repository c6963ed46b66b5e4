#include "SurfaceGraph.h"

#include <utility>

namespace surftrack {

SurfelGraph makeSurfelGraph(std::vector<std::uint32_t>&& rowStart,
                            std::vector<std::uint32_t>&& targets) {
  // The traversal already produced the graph in compressed sparse row form (arcs grouped by
  // source, in vertex order), which is exactly Boost's CSR storage: hand the arrays over
  // instead of copying 2 x arcs pairs through the edge-list constructor. m_forward is a public
  // member of boost::compressed_sparse_row_graph (Boost 1.74, Debian 12).
  SurfelGraph graph;
  graph.m_forward.m_rowstart = std::move(rowStart);
  graph.m_forward.m_column = std::move(targets);
  return graph;
}

}  // namespace surftrack
