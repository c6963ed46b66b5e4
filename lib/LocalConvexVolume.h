// Definition 9 (paper §3.2.1) in one digital 3-cube, with the midpoint ("trivial") boundary
// mapping of §5.1: the computation behind the configuration tables (ConfigurationTable.h).
// Used at build time by tools/generate_configuration_tables.cpp and by the tests; the
// converter and the scanner use the precomputed configurationTable() instead.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "AdjacencyPair.h"
#include "ConfigurationTable.h"

namespace surftrack {

/// The triangles of the continuous analog in a digital 3-cube with configuration `config`:
///  - kappa in {18, 26}: for every kappa-component P of the cube's 1-voxels, the faces of
///    Conv(P u A(P)) whose vertices are all midpoints (A(P): midpoints of the cube edges from P
///    to 0-voxels), oriented outward; a planar face with more than 3 vertices is split into a
///    fan from its vertex of smallest edge index;
///  - kappa = 6: the triangles of (lambda, 6) for the complemented configuration, orientation
///    reversed (Definition 28).
/// Exact integer arithmetic on doubled coordinates. Throws std::logic_error if a bound of
/// CubeTriangulation is exceeded.
CubeTriangulation computeCubeTriangulation(AdjacencyPair pair, std::uint8_t config);

/// All four tables, indexed by the value of AdjacencyPair, then by configuration.
using ConfigurationTables = std::array<std::array<CubeTriangulation, 256>, 4>;

ConfigurationTables computeConfigurationTables();

/// The C++ initialiser text of `tables` (the content of ConfigurationTables.inc). The
/// formatting is deterministic, so equal tables give identical bytes.
std::string configurationTablesSource(const ConfigurationTables& tables);

}  // namespace surftrack
