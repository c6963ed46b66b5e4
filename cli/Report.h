// What the tool prints: the one-screen summary for people and the JSON object for scripts, of
// an extraction (mesh, demo) and of a volume (info).
#pragma once

#include <ostream>
#include <string>

#include "Extraction.h"
#include "Json.h"
#include "ReadVolume.h"
#include "VolumeStats.h"

namespace surftrack::cli {

/// The summary of an extraction, a dozen lines, each "  label   text".
void printSummary(std::ostream& out, const Extraction& x);

/// The extraction as one JSON object (written into `json`, which may be inside an array).
void writeJson(JsonWriter& json, const Extraction& x);

/// `surftrack info`: the description of a volume.
void printVolumeInfo(std::ostream& out, const std::string& path, const io::AnyVolume& volume,
                     const VolumeStats& stats);
void writeVolumeJson(JsonWriter& json, const std::string& path, const io::AnyVolume& volume,
                     const VolumeStats& stats);

/// "c=(x,y,z) d=(x,y,z)".
std::string surfelText(const Surfel& s);

}  // namespace surftrack::cli
