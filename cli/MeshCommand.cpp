// `surftrack mesh INPUT -o OUTPUT [options]`.
#include <iostream>

#include <nlohmann/json.hpp>

#include "Commands.h"
#include "Extraction.h"
#include "OutputFile.h"
#include "Report.h"

namespace surftrack::cli {

int runMesh(const std::vector<std::string>& args) {
  const MeshOptions o = parseMeshOptions(args);
  Extraction x;
  x.output = o.output;
  x.format = meshFormat(o.output);  // a usage error, before any work
  x.binary = !o.ascii && (x.format == "ply" || x.format == "stl");
  requireWritable(o.output);        // fail now rather than after the work
  requireNotInput(o.output, o.input.path);

  Progress progress(Progress::wanted(o.out.quiet));
  StageClock clock;
  const int stages = extractionStages(o.surface) + 2;  // + read, write
  progress.stage(0, stages, "reading " + o.input.path);
  const io::LoadedVolume volume = readInput(o.input);
  clock.lap(x.timings, "read");
  describeInput(volume, o.input.path, x);

  // A seeded extraction reads bricks near one surface; Otsu's default and the scans read all.
  const bool seeded = o.surface.seedMode != SeedMode::Largest && o.surface.seedMode != SeedMode::All;
  if (seeded && (o.surface.iso || o.surface.label)) volume.advise(io::LoadedVolume::Access::Sparse);
  extractSurface(volume.view, o.surface, x, clock, progress, 1, stages);
  if (volume.mapped) x.voxelBytesResident = volume.residentBytes();

  progress.stage(stages - 1, stages, "writing " + o.output);
  x.bytes = writeMeshFile(x.surface, o.output, x.binary);
  clock.lap(x.timings, "write");
  x.totalSeconds = clock.total();
  progress.finish();
  if (!o.out.quiet)
    for (const std::string& w : x.warnings) std::cerr << "surftrack: warning: " << w << "\n";

  if (o.out.json) {
    std::cout << jsonText(extractionJson(x)) << std::endl;
  } else if (!o.out.quiet) {
    printSummary(std::cout, x);
  }
  return 0;
}

}  // namespace surftrack::cli
