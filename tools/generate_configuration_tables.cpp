// Build-time generator of the configuration tables (paper §5.1): computes the four tables from
// Definition 9 (lib/LocalConvexVolume.cpp) and writes them as C++ initialiser data to the file
// named on the command line (ConfigurationTables.inc, #included by lib/ConfigurationTable.cpp).
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>

#include "LocalConvexVolume.h"

int main(int argc, char** argv) {
  using namespace surftrack;
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " <output.inc>\n";
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  ConfigurationTables tables;
  try {
    tables = computeConfigurationTables();
  } catch (const std::exception& e) {
    std::cerr << "generate_configuration_tables: " << e.what() << "\n";
    return 1;
  }
  // The bounds of CubeTriangulation must be tight, so that the table stays small.
  int maxTriangles = 0, maxPatches = 0;
  for (const auto& table : tables)
    for (const CubeTriangulation& t : table) {
      maxTriangles = std::max(maxTriangles, int(t.triangleCount));
      maxPatches = std::max(maxPatches, int(t.patchCount));
    }
  if (maxTriangles != CubeTriangulation::kMaxTriangles || maxPatches != CubeTriangulation::kMaxPatches) {
    std::cerr << "generate_configuration_tables: found at most " << maxTriangles << " triangles and "
              << maxPatches << " patches per configuration; update CubeTriangulation::kMaxTriangles ("
              << CubeTriangulation::kMaxTriangles << ") and kMaxPatches (" << CubeTriangulation::kMaxPatches
              << ")\n";
    return 1;
  }
  std::ofstream out(argv[1], std::ios::binary);
  out << configurationTablesSource(tables);
  out.close();
  if (!out) {
    std::cerr << "generate_configuration_tables: cannot write " << argv[1] << "\n";
    return 1;
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "configuration tables: 4 x 256 configurations, <= " << maxTriangles << " triangles, <= "
            << maxPatches << " patches, " << ms << " ms -> " << argv[1] << "\n";
  return 0;
}
