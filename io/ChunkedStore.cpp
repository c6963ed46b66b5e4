// A directory recognised by its metadata files, its level and leading axes chosen, and the
// format's reader opened on the array chosen.
#include "ChunkedStore.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "ChunkGrid.h"
#include "N5Dataset.h"
#include "OmeZarr.h"
#include "ReadVolume.h"
#include "ZarrArray.h"

namespace surftrack::io {

using detail::quotedPath;

namespace {

bool isFile(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool isDirectory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

/// "'g/a', 'g/b'": the subdirectories of `dir` holding `marker`, for the message naming a
/// group's arrays (at most 5 named).
std::string childrenWith(const std::string& dir, const char* marker) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (isFile(entry.path().string() + "/" + marker)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  if (names.empty()) return "it holds none";
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < 5; ++i) s += (i ? ", " : "") + quotedPath(dir + "/" + names[i]);
  return s + (names.size() > 5 ? ", ..." : "");
}

/// The index of each leading axis: `kinds` says which is "channel", "time" or another.
std::vector<std::int64_t> chooseLeading(const std::vector<std::string>& names, const std::vector<std::string>& kinds,
                                        const std::vector<std::int64_t>& shape, const ChunkedStoreOptions& options,
                                        const std::string& path, std::vector<AxisChoice>& chosen) {
  std::vector<std::int64_t> fixed;
  bool usedChannel = false, usedTime = false;
  for (std::size_t a = 0; a < names.size(); ++a) {
    std::int64_t index = 0;
    if (kinds[a] == "channel" && options.channel) index = *options.channel, usedChannel = true;
    if (kinds[a] == "time" && options.time) index = *options.time, usedTime = true;
    if (index < 0 || index >= shape[a])
      throw ReadError("cannot read " + quotedPath(path) + ": " + detail::escapedText(kinds[a]) + " " + std::to_string(index) + " is outside its axis " +
                      quotedPath(names[a]) + " of " + std::to_string(shape[a]) + " (0 to " + std::to_string(shape[a] - 1) + ")");
    fixed.push_back(index);
    chosen.push_back({names[a], kinds[a], index, shape[a]});
  }
  if (options.channel && !usedChannel)
    throw ReadError("cannot read " + quotedPath(path) + ": a channel is chosen (" + std::to_string(*options.channel) + ") but the array has no channel axis");
  if (options.time && !usedTime)
    throw ReadError("cannot read " + quotedPath(path) + ": a time is chosen (" + std::to_string(*options.time) + ") but the array has no time axis");
  return fixed;
}

/// A zarr array or N5 dataset on its own: 2 or 3 spatial axes, before them a channel axis
/// (4 dimensions) or a time and a channel axis (5).
template <class Open>
void openPlain(ChunkedStore& store, const std::vector<std::int64_t>& shape, const ChunkedStoreOptions& options, Open open) {
  const int rank = int(shape.size());
  if (rank < 2 || rank > 5)
    throw ReadError("cannot read " + quotedPath(store.arrayPath) + ": the array has " + std::to_string(rank) +
                    " dimensions; a volume has 3 (or 2: one slice), and 4 or 5 with the leading time and channel axes chosen by index");
  if (options.level != 0)
    throw ReadError("cannot read " + quotedPath(store.arrayPath) + ": level " + std::to_string(options.level) + " is chosen but a " +
                    store.format + " array has one level (0)");
  const int spatial = std::min(rank, 3);
  std::vector<std::string> names, kinds;
  if (rank - spatial == 2) names = {"t", "c"}, kinds = {"time", "channel"};
  if (rank - spatial == 1) names = {"c"}, kinds = {"channel"};
  const std::vector<std::int64_t> fixed = chooseLeading(names, kinds, shape, options, store.arrayPath, store.chosen);
  store.provider = open(spatial, fixed, ImageGeometry{});
}

std::string trimmed(std::string path) {
  while (path.size() > 1 && path.back() == '/') path.pop_back();
  return path;
}

}  // namespace

std::string ChunkedStore::choiceText() const {
  std::string s;
  if (levels > 1) s = "level " + std::to_string(level) + " of " + std::to_string(levels);
  for (const AxisChoice& c : chosen)
    s += (s.empty() ? "" : ", ") + c.name + " " + std::to_string(c.index) + " of " + std::to_string(c.size);
  return s;
}

bool isChunkedStore(const std::string& path) {
  const std::string dir = trimmed(path);
  if (!isDirectory(dir)) return false;
  try {
    // Groups too: openChunkedStore names their arrays.
    return isFile(dir + "/.zarray") || isFile(dir + "/.zgroup") || isFile(dir + "/attributes.json") || isOmeZarr(dir);
  } catch (const ReadError&) {
    return true;  // a store's metadata, damaged: openChunkedStore says how
  }
}

namespace {

ChunkedStore openStore(const std::string& path, const ChunkedStoreOptions& options) {
  if (!isDirectory(path))
    throw ReadError("cannot read " + quotedPath(path) + ": " + (isFile(path) ? "a file" : "no such directory") +
                    "; a chunked store is a directory (a zarr array, an OME-Zarr image or an N5 dataset)");
  ChunkedStore store;
  store.arrayPath = path;
  if (isFile(path + "/.zarray")) {
    const ZarrHeader h = readZarrHeader(path);
    store.format = "zarr";
    store.dtype = h.dtype;
    store.compressor = h.codec.description;
    openPlain(store, h.shape, options, [&](int spatial, const std::vector<std::int64_t>& fixed, const ImageGeometry& g) {
      return openZarrArray(path, h, spatial, fixed, g);
    });
    return store;
  }
  if (isOmeZarr(path)) {
    const OmeMultiscale m = readOmeMultiscale(path);
    store.format = "ome-zarr";
    store.levels = int(m.paths.size());
    if (options.level < 0 || options.level >= store.levels)
      throw ReadError("cannot read " + quotedPath(path) + ": level " + std::to_string(options.level) + " is outside its " +
                      std::to_string(store.levels) + " levels (0 to " + std::to_string(store.levels - 1) + ")");
    store.level = options.level;
    store.arrayPath = path + "/" + m.paths[store.level];
    const ZarrHeader h = readZarrHeader(store.arrayPath);
    const int rank = int(m.axes.size());
    if (int(h.shape.size()) != rank)
      throw ReadError("cannot read " + quotedPath(store.arrayPath) + ": the array has " + std::to_string(h.shape.size()) +
                      " dimensions where the OME-Zarr image names " + std::to_string(rank) + " axes");
    store.dtype = h.dtype;
    store.compressor = h.codec.description;
    store.unit = m.unit;
    std::vector<std::string> names, kinds;
    for (int a = 0; a < rank - m.spatialAxes; ++a) {
      names.push_back(m.axes[a].name);
      kinds.push_back(m.axes[a].type.empty() ? "index" : m.axes[a].type);
    }
    const std::vector<std::int64_t> fixed = chooseLeading(names, kinds, h.shape, options, store.arrayPath, store.chosen);
    ImageGeometry geometry;  // the engine's axes: the array's reversed; direction the identity
    for (int e = 0; e < m.spatialAxes; ++e) {
      geometry.spacing[e] = m.scale[store.level][rank - 1 - e];
      geometry.origin[e] = m.translation[store.level][rank - 1 - e];
    }
    store.provider = openZarrArray(store.arrayPath, h, m.spatialAxes, fixed, geometry);
    return store;
  }
  if (isN5Dataset(path)) {
    const N5Header h = readN5Header(path);
    store.format = "n5";
    store.dtype = h.dataType;
    store.compressor = h.codec.description;
    std::vector<std::int64_t> shape(h.dimensions.rbegin(), h.dimensions.rend());
    openPlain(store, shape, options, [&](int spatial, const std::vector<std::int64_t>& fixed, const ImageGeometry& g) {
      return openN5Dataset(path, h, spatial, fixed, g);
    });
    return store;
  }
  if (isFile(path + "/.zgroup"))
    throw ReadError("cannot read " + quotedPath(path) + ": a zarr group without OME-Zarr multiscales; name one of its arrays (" +
                    childrenWith(path, ".zarray") + ")");
  if (isFile(path + "/attributes.json"))
    throw ReadError("cannot read " + quotedPath(path) + ": an N5 group; name one of its datasets (" + childrenWith(path, "attributes.json") + ")");
  throw ReadError("cannot read " + quotedPath(path) + ": not a zarr array (.zarray), an OME-Zarr image (.zattrs with multiscales) or an N5 dataset (attributes.json)");
}

}  // namespace

ChunkedStore openChunkedStore(const std::string& rawPath, const ChunkedStoreOptions& options) {
  const std::string path = trimmed(rawPath);
  try {
    return openStore(path, options);
  } catch (const nlohmann::json::exception& e) {
    // The readers check each field they read; a JSON library error here is one they missed,
    // still one line naming the store.
    throw ReadError("cannot read " + quotedPath(path) + ": malformed metadata (" + e.what() + ")");
  }
}

}  // namespace surftrack::io
