// `surftrack info INPUT`.
#include <iostream>

#include "Commands.h"
#include "Extraction.h"
#include "Report.h"
#include "VolumeStats.h"

namespace surftrack::cli {

int runInfo(const std::vector<std::string>& args) {
  const InfoOptions o = parseInfoOptions(args);
  const io::AnyVolume volume = readInput(o.input);
  const VolumeStats stats = computeStats(volume);
  if (o.out.json) {
    JsonWriter json;
    writeVolumeJson(json, o.input.path, volume, stats);
    std::cout << json.str() << std::endl;
  } else if (!o.out.quiet) {
    printVolumeInfo(std::cout, o.input.path, volume, stats);
  }
  return 0;
}

}  // namespace surftrack::cli
