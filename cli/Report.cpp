#include "Report.h"

#include <cmath>
#include <cstdint>
#include <iomanip>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

namespace surftrack::cli {

using json = nlohmann::ordered_json;

std::string num(double v, int precision) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

json labelJson(const LabelValue& label) {
  if (label.negative()) return json(label.as<std::int64_t>());
  return json(label.magnitude());
}

json number(double v) {
  if (!std::isfinite(v)) return nullptr;
  if (v == std::floor(v) && std::abs(v) < 1e15) return static_cast<std::int64_t>(v);
  return v;
}

namespace {

std::string voxelText(Voxel v) {
  std::ostringstream s;
  s << '(' << v.x << ',' << v.y << ',' << v.z << ')';
  return s.str();
}

std::string tripleText(const std::array<double, 3>& p, int precision = 6) {
  // (Built with a stream: GCC 12 warns falsely, -Wrestrict, on "(" + std::string.)
  std::ostringstream s;
  s.precision(precision);
  s << '(' << p[0] << ", " << p[1] << ", " << p[2] << ')';
  return s.str();
}

std::string bytesText(std::uintmax_t bytes) {
  std::ostringstream s;
  s.precision(3);
  if (bytes >= 1000000) s << double(bytes) / 1e6 << " MB";
  else if (bytes >= 1000) s << double(bytes) / 1e3 << " kB";
  else s << bytes << " B";
  return s.str();
}

std::string secondsText(double s) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(s < 10 ? 3 : 1) << s << " s";
  return out.str();
}

bool isIdentity(const ImageGeometry& g) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (std::abs(g.direction[r][c] - (r == c ? 1.0 : 0.0)) > 1e-9) return false;
  return true;
}

std::string directionText(const ImageGeometry& g) {
  if (isIdentity(g)) return "identity";
  std::string s = "[";
  for (int r = 0; r < 3; ++r) {
    s += r ? ", [" : "[";
    for (int c = 0; c < 3; ++c) s += (c ? ", " : "") + num(g.direction[r][c], 4);
    s += "]";
  }
  return s + "]";
}

std::string imageLine(const Dims& d, io::ScalarType type, const ImageGeometry& g) {
  std::ostringstream s;
  s << d.nx << " x " << d.ny << " x " << d.nz << " " << io::toString(type) << ", spacing "
    << num(g.spacing[0]) << " x " << num(g.spacing[1]) << " x " << num(g.spacing[2]) << ", origin "
    << tripleText(g.origin);
  if (!isIdentity(g)) s << ", direction " << directionText(g);
  return s.str();
}

void row(std::ostream& out, const std::string& label, const std::string& text) {
  out << "  " << std::left << std::setw(10) << label << "  " << text << "\n";
}

std::string seedText(const Extraction& x) {
  std::ostringstream s;
  switch (x.seedMode) {
    case SeedMode::Largest:
      s << "the largest of " << x.boundaries << " boundar" << (x.boundaries == 1 ? "y" : "ies");
      if (x.seedSurfel) s << ", tracked from surfel " << surfelText(*x.seedSurfel);
      break;
    case SeedMode::All:
      s << "all " << x.boundaries << " boundar" << (x.boundaries == 1 ? "y" : "ies") << " (scanned)";
      break;
    case SeedMode::Surfel:
      s << "surfel " << surfelText(*x.seedSurfel) << " (given)";
      break;
    case SeedMode::Voxel:
    case SeedMode::Point:
      if (x.seedPoint) s << "point " << tripleText(*x.seedPoint);
      if (x.seedVoxel)
        s << "voxel " << voxelText(*x.seedVoxel) << " (" << (x.seedVoxelInside ? "inside" : "outside") << ")";
      s << " -> nearest surfel " << surfelText(*x.seedSurfel);
      if (x.seedDistance) s << ", at " << num(*x.seedDistance) << " (physical units)";
      break;
    case SeedMode::Ray:
      if (x.seedVoxel)
        s << "voxel " << voxelText(*x.seedVoxel) << " (" << (x.seedVoxelInside ? "inside" : "outside")
          << "), ";
      if (x.walkDirection)
        s << x.walkSteps << " voxel" << (x.walkSteps == 1 ? "" : "s") << " along "
          << directionName(*x.walkDirection) << " to surfel " << surfelText(*x.seedSurfel);
      break;
  }
  return s.str();
}


/// The seed rule's name in the JSON (a switch, not a table indexed by the enum: a new rule is a
/// -Wswitch warning here, not a read past the table).
const char* seedModeName(SeedMode m) {
  switch (m) {
    case SeedMode::Largest: return "largest";
    case SeedMode::All: return "all";
    case SeedMode::Voxel: return "voxel";
    case SeedMode::Ray: return "ray";
    case SeedMode::Surfel: return "surfel";
    case SeedMode::Point: return "point";
  }
  return "?";
}

json numbers(const std::array<double, 3>& p) { return {number(p[0]), number(p[1]), number(p[2])}; }

json voxelJson(Voxel v) { return {v.x, v.y, v.z}; }

json directionJson(const ImageGeometry& g) {
  json rows = json::array();
  for (const auto& r : g.direction) rows.push_back(numbers(r));
  return rows;
}

std::string genusText(double g) {
  if (g == std::floor(g)) return num(g);
  return num(g) + " (not an integer: the surface is not closed and orientable)";
}

}  // namespace

std::string surfelText(const Surfel& s) {
  return "c=" + voxelText(s.inside()) + " d=" + voxelText(s.outside());
}

namespace {

/// "memory-mapped mha (pages read on demand)" / "loaded nii.gz (its voxels are gzip-encoded ...)".
std::string storageText(const io::LoadedVolume& v) {
  if (v.mapped) return "memory-mapped " + v.format + " (pages read on demand)";
  return "loaded " + v.format + (v.decodeReason.empty() ? "" : " (" + v.decodeReason + ")");
}

json storageJson(const io::LoadedVolume& v) {
  json j;
  j["format"] = v.format;
  j["mapped"] = v.mapped;
  if (!v.decodeReason.empty()) j["loaded_because"] = v.decodeReason;
  j["voxel_bytes"] = v.dataBytes;
  return j;
}

}  // namespace

void printSummary(std::ostream& out, const Extraction& x) {
  const MeshStats& m = x.stats;
  out << "surftrack: " << x.input << " -> " << x.output << "\n";
  row(out, "image", imageLine(x.dims, x.type, x.geometry));
  if (x.voxelBytes) {
    std::ostringstream s;
    s << x.storage;
    if (!x.decodeReason.empty()) s << " (" << x.decodeReason << ")";
    s << "; voxels read " << bytesText(x.voxelBytesRead) << " of " << bytesText(x.voxelBytes) << " ("
      << num(100.0 * double(x.voxelBytesRead) / double(x.voxelBytes), 3) << " %)";
    if (x.voxelBytesResident) s << ", " << bytesText(*x.voxelBytesResident) << " of it in memory";
    if (x.chunks)
      s << "; chunks decoded " << x.chunks->chunksDecoded << " of " << x.chunkCount << " ("
        << bytesText(x.chunks->bytesRead) << " read from storage, " << x.chunks->hits << " cache hits)";
    row(out, "input", s.str());
  }
  {
    std::ostringstream s;
    if (x.dataRange) s << "range [" << num((*x.dataRange)[0]) << ", " << num((*x.dataRange)[1]) << "]; ";
    s << "inside: f ";
    if (x.byLabel) s << "= " << x.label.text() << " (label)";
    else s << "> " << num(x.value, 10) << (x.valueFromOtsu ? " (Otsu's threshold; set it with --iso)" : "");
    row(out, "values", s.str());
  }
  row(out, "surface", "adjacency " + toString(x.pair) + " (1-voxels " + std::to_string(kappa(x.pair)) +
                          "-connected, 0-voxels " + std::to_string(lambda(x.pair)) + "), " + x.mapping +
                          " vertex mapping");
  row(out, "seed", seedText(x));
  {
    std::ostringstream s;
    s << x.surfels << " surfels -> " << m.vertices << " vertices, " << m.edges << " edges, "
      << m.triangles << " triangles, " << m.components.size() << " component"
      << (m.components.size() == 1 ? "" : "s");
    row(out, "mesh", s.str());
  }
  {
    std::ostringstream s;
    if (m.components.size() == 1) {
      s << "Euler characteristic " << m.euler << ", genus " << genusText(m.components[0].genus());
    } else {
      s << "Euler characteristic " << m.euler << " in total; by genus:";
      std::map<double, std::size_t> byGenus;
      for (const auto& c : m.components) ++byGenus[c.genus()];
      int shown = 0;
      for (auto [g, n] : byGenus) {
        if (shown++ == 6) {
          s << " ...";
          break;
        }
        s << " " << num(g) << " x" << n;
      }
      if (!m.components.empty())
        s << "; largest: " << m.components[0].surfels << " vertices, genus " << num(m.components[0].genus());
    }
    s << (m.closed && m.manifold ? "; closed 2-manifold" : m.closed ? "; closed, NOT a manifold" : "; NOT closed");
    row(out, "topology", s.str());
  }
  double volume = 0;
  for (const auto& c : m.components) volume += c.volume;
  auto change = [&](double before) {
    return before != 0 ? num(100.0 * (volume - before) / std::abs(before), 3) + " %" : std::string("n/a");
  };
  if (x.smooth) {
    std::ostringstream s;
    s << x.smooth->iterations << " Taubin iterations on the surfels' segments; largest vertex move "
      << num(x.smooth->maxDisplacement, 4) << "; " << x.smooth->stepsBack << " moves stepped back by the fold check";
    if (x.smooth->unguardedCubes) s << "; " << x.smooth->unguardedCubes << " cubes folded already (unchecked)";
    row(out, "smoothing", s.str());
  }
  if (x.decimate) {
    std::ostringstream s;
    s << x.decimate->trianglesBefore << " -> " << x.decimate->trianglesAfter << " triangles";
    if (x.decimate->targetTriangles) s << " (target " << x.decimate->targetTriangles << ")";
    row(out, "decimation", s.str());
  }
  if (x.smooth || x.decimate)
    row(out, "volume", num(volume, 8) + " (physical), " + change(x.extractedVolume) + " from the extracted surface");
  row(out, "bbox", tripleText(m.min) + " .. " + tripleText(m.max) + " (physical)");
  if (!x.output.empty()) {
    std::string fmt = x.format;
    for (char& ch : fmt) ch = char(std::toupper(static_cast<unsigned char>(ch)));
    row(out, "output", x.output + " (" + (x.format == "ply" || x.format == "stl" ? (x.binary ? "binary " : "ASCII ") : "") +
                           fmt + ", " + bytesText(x.bytes) + ")");
  }
  {
    std::string s;
    for (const auto& t : x.timings) s += t.name + " " + secondsText(t.seconds) + ", ";
    s += "total " + secondsText(x.totalSeconds);
    row(out, "timings", s);
  }
}

json extractionJson(const Extraction& x) {
  const MeshStats& m = x.stats;
  json j;
  j["input"] = x.input;
  j["frame"] = x.frame;
  j["dims"] = {x.dims.nx, x.dims.ny, x.dims.nz};
  j["type"] = io::toString(x.type);
  j["spacing"] = numbers(x.geometry.spacing);
  j["origin"] = numbers(x.geometry.origin);
  j["direction"] = directionJson(x.geometry);
  {
    json storage;
    storage["storage"] = x.storage;
    storage["mapped"] = x.mapped;
    if (!x.decodeReason.empty()) storage["loaded_because"] = x.decodeReason;
    storage["voxel_bytes"] = x.voxelBytes;
    storage["voxel_bytes_read"] = x.voxelBytesRead;
    if (x.voxelBytesResident) storage["voxel_bytes_resident"] = *x.voxelBytesResident;
    if (x.chunks) {
      storage["chunks"] = x.chunkCount;
      storage["chunks_decoded"] = x.chunks->chunksDecoded;
      storage["bytes_read"] = x.chunks->bytesRead;  // (from storage, compressed)
      storage["cache_hits"] = x.chunks->hits;
    }
    j["input_storage"] = std::move(storage);
  }
  if (x.dataRange) j["data_range"] = {number((*x.dataRange)[0]), number((*x.dataRange)[1])};
  json selection;
  selection["mode"] = x.byLabel ? "label" : "iso";
  selection[x.byLabel ? "label" : "iso"] = x.byLabel ? labelJson(x.label) : number(x.value);
  if (!x.byLabel) selection["iso_source"] = x.valueFromOtsu ? "otsu" : "given";
  j["selection"] = std::move(selection);
  j["adjacency"] = toString(x.pair);
  j["mapping"] = x.mapping;
  json seed;
  seed["mode"] = seedModeName(x.seedMode);
  if (x.seedPoint) seed["point"] = numbers(*x.seedPoint);
  if (x.seedVoxel) {
    seed["voxel"] = voxelJson(*x.seedVoxel);
    seed["voxel_inside"] = x.seedVoxelInside;
  }
  if (x.seedDistance) seed["distance"] = number(*x.seedDistance);
  if (x.walkDirection) {
    seed["walk_direction"] = directionName(*x.walkDirection);
    seed["walk_steps"] = x.walkSteps;
  }
  if (x.seedSurfel)
    seed["surfel"] = {{"c", voxelJson(x.seedSurfel->inside())}, {"d", voxelJson(x.seedSurfel->outside())}};
  if (x.seedMode == SeedMode::Largest || x.seedMode == SeedMode::All) seed["boundaries"] = x.boundaries;
  j["seed"] = std::move(seed);
  j["surfels"] = x.surfels;
  j["vertices"] = m.vertices;
  j["edges"] = m.edges;
  j["triangles"] = m.triangles;
  j["components"] = m.components.size();
  j["euler_characteristic"] = m.euler;
  if (m.components.size() == 1) j["genus"] = number(m.components[0].genus());
  j["closed"] = m.closed;
  j["manifold"] = m.manifold;
  j["bbox"] = {{"min", numbers(m.min)}, {"max", numbers(m.max)}};
  constexpr std::size_t kListed = 100;
  json components = json::array();
  for (std::size_t i = 0; i < m.components.size() && i < kListed; ++i) {
    const auto& c = m.components[i];
    json component;
    component["vertices"] = c.surfels;
    component["edges"] = c.edges;
    component["triangles"] = c.triangles;
    component["euler_characteristic"] = c.euler;
    component["genus"] = number(c.genus());
    component["area"] = number(c.area);
    component["enclosed_volume"] = number(c.volume);
    components.push_back(std::move(component));
  }
  j["component_list"] = std::move(components);
  if (x.smooth || x.decimate) {
    double volume = 0;
    for (const auto& c : m.components) volume += c.volume;
    json refine;
    refine["extracted_volume"] = number(x.extractedVolume);
    refine["volume"] = number(volume);
    refine["volume_change"] = x.extractedVolume != 0 ? number((volume - x.extractedVolume) / std::abs(x.extractedVolume)) : json();
    if (x.smooth) {
      json s;
      s["iterations"] = x.smooth->iterations;
      s["max_vertex_displacement"] = number(x.smooth->maxDisplacement);
      s["steps_back"] = x.smooth->stepsBack;
      s["cubes"] = x.smooth->cubes;
      s["unguarded_cubes"] = x.smooth->unguardedCubes;
      refine["smoothing"] = std::move(s);
    }
    if (x.decimate) {
      json d;
      d["triangles_before"] = x.decimate->trianglesBefore;
      d["triangles_after"] = x.decimate->trianglesAfter;
      if (x.decimate->targetTriangles) d["target_triangles"] = x.decimate->targetTriangles;
      refine["decimation"] = std::move(d);
    }
    j["refine"] = std::move(refine);
  }
  if (m.components.size() > kListed) j["component_list_truncated_to"] = kListed;
  if (!x.output.empty()) {
    json output;
    output["path"] = x.output;
    output["format"] = x.format;
    output["binary"] = x.binary;
    output["bytes"] = x.bytes;
    j["output"] = std::move(output);
  }
  json timings = json::object();
  for (const auto& t : x.timings) timings[t.name] = number(t.seconds);
  timings["total"] = number(x.totalSeconds);
  j["timings_s"] = std::move(timings);
  j["warnings"] = x.warnings;
  return j;
}

void printVolumeInfo(std::ostream& out, const std::string& path, const io::LoadedVolume& volume,
                     const VolumeStats* stats, const io::ChunkedStore* store, const std::string& notRead) {
  const Dims& d = volume.view.dims;
  const ImageGeometry& g = volume.view.geometry;
  out << "surftrack: " << path << "\n";
  row(out, "size", std::to_string(d.nx) + " x " + std::to_string(d.ny) + " x " + std::to_string(d.nz) +
                       " = " + std::to_string(d.count()) + " voxels of " + io::toString(volume.view.type));
  row(out, "spacing", tripleText(g.spacing) + (volume.unit.empty() ? "" : " " + volume.unit));
  row(out, "origin", tripleText(g.origin) + " (" + volume.frame + " frame)");
  row(out, "direction", directionText(g));
  if (volume.channels > 1)
    row(out, "channel", std::to_string(volume.channel) + " of channels 0 to " + std::to_string(volume.channels - 1));
  std::array<double, 3> far = g.toPhysical({double(d.nx - 1), double(d.ny - 1), double(d.nz - 1)});
  row(out, "extent", "voxel centres from " + tripleText(g.origin) + " to " + tripleText(far));
  if (store) {
    const ChunkLayout& l = store->provider->layout();
    const Dims n = l.chunkCounts();
    std::string c = std::to_string(l.chunk.nx) + " x " + std::to_string(l.chunk.ny) + " x " +
                    std::to_string(l.chunk.nz) + " voxels, " + std::to_string(n.nx) + " x " + std::to_string(n.ny) +
                    " x " + std::to_string(n.nz) + " = " + std::to_string(n.count()) + " chunks, " + store->dtype +
                    ", compressor " + store->compressor;
    row(out, "chunks", c);
    if (!store->choiceText().empty()) row(out, "chosen", store->choiceText());
  }
  if (!stats) {
    row(out, "storage", volume.format + ", its values not read: " + notRead);
    return;
  }
  const VolumeStats& s = *stats;
  row(out, "storage", storageText(volume));
  {
    std::ostringstream v;
    v << '[' << num(s.min) << ", " << num(s.max) << "], mean " << num(s.mean);
    if (s.nonFinite) v << ", " << s.nonFinite << " non-finite voxels";
    row(out, "values", v.str());
  }
  if (!s.quantiles.empty()) {
    std::ostringstream q;
    for (std::size_t i = 0; i < s.quantiles.size(); ++i)
      q << (i ? ", " : "") << num(100 * s.quantiles[i].first) << "% " << num(s.quantiles[i].second);
    q << " (numpy.quantile's linear definition)";
    row(out, "quantiles", q.str());
  }
  row(out, "otsu", num(s.otsu, 10) + " (the default --iso of 'surftrack mesh')");
  if (!s.labels.empty()) {
    std::ostringstream l;
    l << s.labels.size() << " distinct values:";
    std::size_t shown = 0;
    for (auto [value, count] : s.labels) {
      if (shown++ == 20) {
        l << " ...";
        break;
      }
      l << " " << value.text();
    }
    row(out, "labels", l.str());
  }
}

json volumeJson(const std::string& path, const io::LoadedVolume& volume, const VolumeStats* stats,
                const io::ChunkedStore* store, const std::string& notRead) {
  const Dims& d = volume.view.dims;
  const ImageGeometry& g = volume.view.geometry;
  json j;
  j["input"] = path;
  j["frame"] = volume.frame;
  j["warnings"] = volume.warnings;
  j["dims"] = {d.nx, d.ny, d.nz};
  j["type"] = io::toString(volume.view.type);
  j["spacing"] = numbers(g.spacing);
  if (!volume.unit.empty()) j["unit"] = volume.unit;
  j["origin"] = numbers(g.origin);
  j["direction"] = directionJson(g);
  j["channel"] = volume.channel;
  j["channels"] = volume.channels;
  if (store) {
    const ChunkLayout& l = store->provider->layout();
    const Dims n = l.chunkCounts();
    j["chunked"] = {{"format", store->format}, {"array", store->arrayPath}, {"dtype", store->dtype},
                    {"compressor", store->compressor}, {"chunk", {l.chunk.nx, l.chunk.ny, l.chunk.nz}},
                    {"chunks", {n.nx, n.ny, n.nz}}, {"level", store->level}, {"levels", store->levels}};
  }
  if (!stats) {
    j["storage"] = {{"format", volume.format}, {"values_read", false}, {"not_read_because", notRead}};
    return j;
  }
  const VolumeStats& s = *stats;
  j["storage"] = storageJson(volume);
  j["min"] = number(s.min);
  j["max"] = number(s.max);
  j["mean"] = number(s.mean);
  j["non_finite"] = s.nonFinite;
  j["otsu"] = number(s.otsu);
  if (!s.quantiles.empty()) {
    json quantiles = json::array();
    for (auto [q, value] : s.quantiles) quantiles.push_back({{"q", number(q)}, {"value", number(value)}});
    j["quantiles"] = std::move(quantiles);
  }
  j["histogram"] = {{"bin_width", number(s.binWidth)}, {"counts", s.histogram}};
  if (!s.labels.empty()) {
    json labels = json::array();
    for (auto [value, count] : s.labels) labels.push_back({{"value", labelJson(value)}, {"voxels", count}});
    j["labels"] = std::move(labels);
  }
  return j;
}

std::string jsonText(const json& j) {
  return j.dump(2, ' ', false, json::error_handler_t::replace);
}

}  // namespace surftrack::cli
