// JSON files read whole and parsed with nlohmann-json; its exceptions turned into ReadErrors.
#include "JsonFile.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "ChunkGrid.h"
#include "ReadVolume.h"

namespace surftrack::io::detail {

std::optional<nlohmann::json> readJsonFile(const std::string& path) {
  std::optional<std::string> text;
  try {
    text = readChunkFile(path);
  } catch (const ReadError&) {
    throw ReadError("cannot read " + quotedPath(path) + ": not a readable file");
  }
  if (!text) return std::nullopt;
  try {
    // nlohmann-json parses without recursion but copies and prints values recursively: a
    // document of a few ten thousand nested lists overflowed the stack when a reader copied or
    // quoted one (fuzz/findings/zarr/). Metadata nests a few levels (OME-Zarr's transformations
    // sit at depth 6); deeper than kMaxDepth is refused while parsing.
    constexpr int kMaxDepth = 100;
    return nlohmann::json::parse(*text, [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
      if (depth > kMaxDepth)
        throw ReadError("cannot read " + quotedPath(path) + ": JSON nested deeper than " + std::to_string(kMaxDepth) + " levels");
      return true;
    });
  } catch (const nlohmann::json::exception& e) {
    // The library's message may quote the text read: one line kept.
    std::string why = e.what();
    for (char& c : why)
      if (c == '\n' || c == '\r') c = ' ';
    throw ReadError("cannot read " + quotedPath(path) + ": not valid JSON (" + why + ")");
  }
}

std::string jsonText(const nlohmann::json& value) {
  std::string s = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

std::vector<std::int64_t> integerList(const nlohmann::json& object, const char* key, std::int64_t minimum,
                                      const std::string& context) {
  const auto it = object.find(key);
  const auto bad = [&](const std::string& what) -> ReadError {
    return ReadError(context + ": '" + key + "' must be a list of integers >= " + std::to_string(minimum) + ", not " + what);
  };
  if (it == object.end()) throw ReadError(context + ": '" + key + "' is missing");
  if (!it->is_array()) throw bad(jsonText(*it));
  std::vector<std::int64_t> out;
  for (const auto& v : *it) {
    std::int64_t n = 0;
    if (v.is_number_integer() && !(v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<std::int64_t>::max())))
      n = v.get<std::int64_t>();
    else
      throw bad(jsonText(*it));
    if (n < minimum) throw bad(jsonText(*it));
    out.push_back(n);
  }
  return out;
}

std::vector<double> numberList(const nlohmann::json& object, const char* key, const std::string& context) {
  const auto it = object.find(key);
  if (it == object.end()) throw ReadError(context + ": '" + key + "' is missing");
  std::vector<double> out;
  if (it->is_array())
    for (const auto& v : *it) {
      if (!v.is_number() || !std::isfinite(v.get<double>())) {
        out.clear();
        break;
      }
      out.push_back(v.get<double>());
    }
  if (!it->is_array() || out.size() != it->size())
    throw ReadError(context + ": '" + key + "' must be a list of finite numbers, not " + jsonText(*it));
  return out;
}

}  // namespace surftrack::io::detail
