// `.zattrs`'s "multiscales" checked field by field, the transformations of each level composed
// with the multiscale's own in the order OME-Zarr 0.4 applies them (the dataset's first).
#include "OmeZarr.h"

#include <cmath>
#include <set>

#include "ChunkGrid.h"
#include "JsonFile.h"
#include "ReadVolume.h"

namespace surftrack::io {

using detail::jsonText;
using detail::quotedPath;
using nlohmann::json;

namespace {

std::string stringField(const json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}

/// Applies the transformations `list` (in order) to the map index -> scale * index + translation.
void compose(const json& list, std::size_t rank, std::vector<double>& scale, std::vector<double>& translation,
             const std::string& context, const std::string& where) {
  if (!list.is_array()) throw ReadError(context + ": the coordinateTransformations of " + where + " must be a list, not " + jsonText(list));
  int scales = 0, translations = 0;
  for (const json& t : list) {
    const std::string type = t.is_object() ? stringField(t, "type") : "";
    if (t.is_object() && t.contains("path"))
      throw ReadError(context + ": the coordinateTransformations of " + where + " are stored in a file: surftrack reads them inline");
    if (type == "identity") continue;
    if (type != "scale" && type != "translation")
      throw ReadError(context + ": unsupported coordinateTransformation " + jsonText(t) + " in " + where + ": surftrack reads scale and translation");
    const std::vector<double> v = detail::numberList(t, type.c_str(), context);
    if (v.size() != rank)
      throw ReadError(context + ": the " + type + " " + jsonText(t[type]) + " of " + where + " does not have one value for each of the " +
                      std::to_string(rank) + " axes");
    if (type == "scale") {
      ++scales;
      for (std::size_t a = 0; a < rank; ++a) {
        if (!(v[a] > 0)) throw ReadError(context + ": the scale " + jsonText(t[type]) + " of " + where + " must be positive");
        scale[a] *= v[a];
        translation[a] *= v[a];
      }
    } else {
      ++translations;
      for (std::size_t a = 0; a < rank; ++a) translation[a] += v[a];
    }
  }
  if (scales > 1 || translations > 1)
    throw ReadError(context + ": the coordinateTransformations of " + where + " hold more than one scale or translation");
}

}  // namespace

bool isOmeZarr(const std::string& dir) {
  const std::optional<json> attrs = detail::readJsonFile(dir + "/.zattrs");
  return attrs && attrs->is_object() && attrs->contains("multiscales");
}

OmeMultiscale readOmeMultiscale(const std::string& dir) {
  const std::string file = dir + "/.zattrs";
  const std::optional<json> attrs = detail::readJsonFile(file);
  const std::string context = "cannot read " + quotedPath(file);
  if (!attrs) throw ReadError("cannot read " + quotedPath(dir) + ": not an OME-Zarr image (no .zattrs)");
  if (!attrs->is_object() || !attrs->contains("multiscales")) throw ReadError(context + ": no \"multiscales\": not an OME-Zarr image");
  const json& list = (*attrs)["multiscales"];
  if (!list.is_array() || list.empty() || !list[0].is_object())
    throw ReadError(context + ": \"multiscales\" must be a list of objects, not " + jsonText(list));
  const json& m = list[0];
  OmeMultiscale out;
  out.version = stringField(m, "version");
  if (out.version != "0.4")
    throw ReadError(context + ": OME-Zarr version " + (m.contains("version") ? jsonText(m["version"]) : std::string("not stated")) +
                    ": surftrack reads version 0.4");

  // Axes: [time] [channel] then 2 or 3 space axes (OME-Zarr 0.4 orders them so).
  const json axes = m.value("axes", json());
  if (!axes.is_array() || axes.size() < 2 || axes.size() > 5)
    throw ReadError(context + ": \"axes\" must list 2 to 5 axes, not " + jsonText(axes));
  std::set<std::string> names;
  for (const json& a : axes) {
    if (!a.is_object() || stringField(a, "name").empty()) throw ReadError(context + ": an axis must be an object with a name, not " + jsonText(a));
    out.axes.push_back({stringField(a, "name"), stringField(a, "type"), stringField(a, "unit")});
    if (!names.insert(out.axes.back().name).second) throw ReadError(context + ": the axis name " + quotedPath(out.axes.back().name) + " appears twice");
  }
  const int rank = int(out.axes.size());
  int spatial = 0;
  while (spatial < rank && out.axes[rank - 1 - spatial].type == "space") ++spatial;
  int times = 0, channels = 0, misplaced = 0;
  for (int a = 0; a < rank - spatial; ++a) {
    times += out.axes[a].type == "time";
    channels += out.axes[a].type == "channel";
    misplaced += out.axes[a].type == "space";
  }
  if (spatial < 2 || spatial > 3 || times > 1 || channels > 1 || misplaced > 0)
    throw ReadError(context + ": the axes " + jsonText(axes) + " are not 2 or 3 trailing space axes after at most one time and one channel axis");
  out.spatialAxes = spatial;
  out.unit = out.axes[rank - 1].unit;
  for (int a = rank - spatial; a < rank; ++a)
    if (out.axes[a].unit != out.unit)
      throw ReadError(context + ": the space axes have different units (" + quotedPath(out.axes[a].unit) + ", " + quotedPath(out.unit) +
                      "): surftrack places voxels in one unit");

  const json datasets = m.value("datasets", json());
  if (!datasets.is_array() || datasets.empty()) throw ReadError(context + ": \"datasets\" must list the levels, not " + jsonText(datasets));
  const json global = m.value("coordinateTransformations", json::array());
  for (std::size_t level = 0; level < datasets.size(); ++level) {
    const json& d = datasets[level];
    const std::string where = "level " + std::to_string(level);
    if (!d.is_object() || stringField(d, "path").empty())
      throw ReadError(context + ": dataset " + std::to_string(level) + " must be an object with a path, not " + jsonText(d));
    const std::string path = stringField(d, "path");
    if (path.find("..") != std::string::npos || path[0] == '/')
      throw ReadError(context + ": the path " + quotedPath(path) + " of " + where + " leaves the group");
    std::vector<double> scale(rank, 1.0), translation(rank, 0.0);
    if (!d.contains("coordinateTransformations"))
      throw ReadError(context + ": " + where + " has no coordinateTransformations (OME-Zarr 0.4 requires a scale)");
    compose(d["coordinateTransformations"], rank, scale, translation, context, where);
    compose(global, rank, scale, translation, context, "the multiscale");
    // Each factor is finite and positive, their product need not be (1e200 twice:
    // fuzz/findings/omezarr/); the engine places voxels with it.
    for (int a = 0; a < rank; ++a)
      if (!(std::isfinite(scale[a]) && scale[a] > 0 && std::isfinite(translation[a])))
        throw ReadError(context + ": the coordinateTransformations of " + where + " and the multiscale give axis " +
                        quotedPath(out.axes[a].name) + " the scale " + std::to_string(scale[a]) + " and translation " + std::to_string(translation[a]) +
                        ": not finite and positive");
    out.paths.push_back(path);
    out.scale.push_back(scale);
    out.translation.push_back(translation);
  }
  return out;
}

}  // namespace surftrack::io
