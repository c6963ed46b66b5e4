// The configuration tables of §5.1, as computed from Definition 9 at build time: the
// initialiser data is generated into ConfigurationTables.inc by surftrack_generate_tables
// (see ConfigurationTables.cmake); nothing here is typed in.
#include "ConfigurationTable.h"

namespace surftrack {
namespace {

// Indexed by the value of AdjacencyPair, then by configuration.
constexpr std::array<std::array<CubeTriangulation, 256>, 4> kTables = {{
#include "ConfigurationTables.inc"
}};

}  // namespace

const CubeTriangulation& configurationTable(AdjacencyPair pair, std::uint8_t config) {
  return kTables[static_cast<int>(pair)][config];
}

std::span<const CubeTriangulation, 256> configurationTables(AdjacencyPair pair) {
  return kTables[static_cast<int>(pair)];
}

}  // namespace surftrack
