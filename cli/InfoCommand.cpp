// `surftrack info INPUT`.
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "Commands.h"
#include "Extraction.h"
#include "Report.h"
#include "VolumeStats.h"

namespace surftrack::cli {

int runInfo(const std::vector<std::string>& args) {
  const InfoOptions o = parseInfoOptions(args);
  // A chunked store too large to decode whole: its metadata only (shape, chunks, codec,
  // levels, physical extent), read without decoding a chunk.
  std::optional<io::ChunkedStore> store;
  if (isChunkedInput(o.input)) {
    store = io::openChunkedStore(o.input.path, chunkedStoreOptions(o.input));
    if (const auto refusal = wholeReadRefusal(*store, o.input.path)) {
      const ChunkLayout& l = store->provider->layout();
      io::LoadedVolume meta;
      meta.view.dims = l.dims;
      meta.view.type = l.type;
      meta.view.geometry = l.geometry;
      meta.format = store->format;
      meta.unit = store->unit;
      meta.frame = applyGeometryOptions(o.input, meta.view.geometry, meta.frame);
      const std::string why = "its voxels take more than half of this machine's memory (`mesh` with a seed "
                              "rule and --iso or --label reads only the chunks a surface crosses)";
      if (o.out.json)
        std::cout << jsonText(volumeJson(o.input.path, meta, nullptr, &*store, why)) << std::endl;
      else if (!o.out.quiet)
        printVolumeInfo(std::cout, o.input.path, meta, nullptr, &*store, why);
      return 0;
    }
  }
  const io::LoadedVolume volume = readInput(o.input);
  if (!o.out.quiet)
    for (const std::string& w : volume.warnings) std::cerr << "surftrack: warning: " << w << "\n";
  VolumeStats stats = computeStats(volume.view);
  addQuantiles(volume.view, stats, {0.01, 0.25, 0.5, 0.75, 0.99});
  if (o.out.json) {
    std::cout << jsonText(volumeJson(o.input.path, volume, &stats, store ? &*store : nullptr)) << std::endl;
  } else if (!o.out.quiet) {
    printVolumeInfo(std::cout, o.input.path, volume, &stats, store ? &*store : nullptr);
  }
  return 0;
}

}  // namespace surftrack::cli
