// What the tool prints: the one-screen summary for people and the JSON object for scripts, of
// an extraction (mesh, demo) and of a volume (info).
#pragma once

#include <ostream>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "Extraction.h"
#include "LoadVolume.h"
#include "VolumeStats.h"

namespace surftrack::cli {

/// The summary of an extraction, a dozen lines, each "  label   text".
void printSummary(std::ostream& out, const Extraction& x);

/// The extraction as one JSON object (keys in the order written; `demo` puts it in an array).
nlohmann::ordered_json extractionJson(const Extraction& x);

/// `surftrack info`: the description of a volume. `stats` null: its values were not read
/// (`notRead` says why: a chunked store too large to decode whole; dims, type and geometry are
/// then the store's metadata). `store`: the chunked store it came from (its chunks, codec,
/// levels), or null.
void printVolumeInfo(std::ostream& out, const std::string& path, const io::LoadedVolume& volume,
                     const VolumeStats* stats, const io::ChunkedStore* store, const std::string& notRead = {});
nlohmann::ordered_json volumeJson(const std::string& path, const io::LoadedVolume& volume,
                                  const VolumeStats* stats, const io::ChunkedStore* store,
                                  const std::string& notRead = {});

/// The text --json prints: indented by 2, one value per line, invalid UTF-8 in strings (a
/// file name) replaced by U+FFFD.
std::string jsonText(const nlohmann::ordered_json& json);

/// A number for people: `precision` significant digits, no trailing zeros.
std::string num(double v, int precision = 6);

/// A number for JSON: an integer when the value is one (as people write it: 2, not 2.0), null
/// when it is not finite (JSON has no NaN or infinity).
nlohmann::ordered_json number(double v);

/// A label for JSON: an exact integer (uint64 ids above 2^53 included), as JSON allows.
nlohmann::ordered_json labelJson(const LabelValue& label);

/// "c=(x,y,z) d=(x,y,z)".
std::string surfelText(const Surfel& s);

}  // namespace surftrack::cli
