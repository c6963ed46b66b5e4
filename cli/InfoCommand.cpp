// `surftrack info INPUT`.
#include <iostream>

#include <nlohmann/json.hpp>

#include "Commands.h"
#include "Extraction.h"
#include "Report.h"
#include "VolumeStats.h"

namespace surftrack::cli {

int runInfo(const std::vector<std::string>& args) {
  const InfoOptions o = parseInfoOptions(args);
  const io::LoadedVolume volume = readInput(o.input);
  if (!o.out.quiet)
    for (const std::string& w : volume.warnings) std::cerr << "surftrack: warning: " << w << "\n";
  VolumeStats stats = computeStats(volume.view);
  addQuantiles(volume.view, stats, {0.01, 0.25, 0.5, 0.75, 0.99});
  if (o.out.json) {
    std::cout << jsonText(volumeJson(o.input.path, volume, stats)) << std::endl;
  } else if (!o.out.quiet) {
    printVolumeInfo(std::cout, o.input.path, volume, stats);
  }
  return 0;
}

}  // namespace surftrack::cli
