#include "Report.h"

#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

namespace surftrack::cli {

namespace {

std::string num(double v, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

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
      if (x.seedPoint) s << "point " << tripleText(*x.seedPoint) << " -> ";
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

std::string genusText(double g) {
  if (g == std::floor(g)) return num(g);
  return num(g) + " (not an integer: the surface is not closed and orientable)";
}

}  // namespace

std::string surfelText(const Surfel& s) {
  return "c=" + voxelText(s.inside()) + " d=" + voxelText(s.outside());
}

void printSummary(std::ostream& out, const Extraction& x) {
  const MeshStats& m = x.stats;
  out << "surftrack: " << x.input << " -> " << x.output << "\n";
  row(out, "image", imageLine(x.dims, x.type, x.geometry));
  {
    std::ostringstream s;
    s << "range [" << num(x.dataMin) << ", " << num(x.dataMax) << "]; inside: f ";
    if (x.byLabel) s << "= " << num(x.value, 10) << " (label)";
    else s << "> " << num(x.value, 10) << (x.valueFromOtsu ? " (Otsu's threshold; set it with --iso)" : "");
    s << ", " << x.insideVoxels << " voxels";
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
        s << "; largest: " << m.components[0].vertices << " vertices, genus " << num(m.components[0].genus());
    }
    s << (m.closed && m.manifold ? "; closed 2-manifold" : m.closed ? "; closed, NOT a manifold" : "; NOT closed");
    row(out, "topology", s.str());
  }
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

void writeJson(JsonWriter& j, const Extraction& x) {
  const MeshStats& m = x.stats;
  auto triple = [&](const std::array<double, 3>& p) { j.array(p); };
  auto voxel = [&](Voxel v) { j.array(std::array<int, 3>{v.x, v.y, v.z}); };
  j.beginObject();
  j.key("input").value(x.input);
  j.key("dims").array(std::array<int, 3>{x.dims.nx, x.dims.ny, x.dims.nz});
  j.key("type").value(io::toString(x.type));
  j.key("spacing");
  triple(x.geometry.spacing);
  j.key("origin");
  triple(x.geometry.origin);
  j.key("direction").beginArray();
  for (const auto& r : x.geometry.direction) triple(r);
  j.endArray();
  j.key("data_range").array(std::array<double, 2>{x.dataMin, x.dataMax});
  j.key("selection").beginObject();
  j.key("mode").value(x.byLabel ? "label" : "iso");
  j.key(x.byLabel ? "label" : "iso").value(x.value);
  if (!x.byLabel) j.key("iso_source").value(x.valueFromOtsu ? "otsu" : "given");
  j.key("inside_voxels").value(x.insideVoxels);
  j.endObject();
  j.key("adjacency").value(toString(x.pair));
  j.key("mapping").value(x.mapping);
  j.key("seed").beginObject();
  static const char* modes[] = {"largest", "all", "voxel", "surfel", "point"};
  j.key("mode").value(modes[int(x.seedMode)]);
  if (x.seedPoint) {
    j.key("point");
    triple(*x.seedPoint);
  }
  if (x.seedVoxel) {
    j.key("voxel");
    voxel(*x.seedVoxel);
    j.key("voxel_inside").value(x.seedVoxelInside);
  }
  if (x.walkDirection) {
    j.key("walk_direction").value(directionName(*x.walkDirection));
    j.key("walk_steps").value(x.walkSteps);
  }
  if (x.seedSurfel) {
    j.key("surfel").beginObject();
    j.key("c");
    voxel(x.seedSurfel->inside());
    j.key("d");
    voxel(x.seedSurfel->outside());
    j.endObject();
  }
  if (x.seedMode == SeedMode::Largest || x.seedMode == SeedMode::All) j.key("boundaries").value(x.boundaries);
  j.endObject();
  j.key("surfels").value(x.surfels);
  j.key("vertices").value(m.vertices);
  j.key("edges").value(m.edges);
  j.key("triangles").value(m.triangles);
  j.key("components").value(m.components.size());
  j.key("euler_characteristic").value(m.euler);
  if (m.components.size() == 1) j.key("genus").value(m.components[0].genus());
  j.key("closed").value(m.closed);
  j.key("manifold").value(m.manifold);
  j.key("bbox").beginObject();
  j.key("min");
  triple(m.min);
  j.key("max");
  triple(m.max);
  j.endObject();
  constexpr std::size_t kListed = 100;
  j.key("component_list").beginArray();
  for (std::size_t i = 0; i < m.components.size() && i < kListed; ++i) {
    const auto& c = m.components[i];
    j.beginObject();
    j.key("vertices").value(c.vertices);
    j.key("edges").value(c.edges);
    j.key("triangles").value(c.triangles);
    j.key("euler_characteristic").value(c.euler);
    j.key("genus").value(c.genus());
    j.key("area").value(c.area);
    j.key("enclosed_volume").value(c.volume);
    j.endObject();
  }
  j.endArray();
  if (m.components.size() > kListed) j.key("component_list_truncated_to").value(kListed);
  if (!x.output.empty()) {
    j.key("output").beginObject();
    j.key("path").value(x.output);
    j.key("format").value(x.format);
    j.key("binary").value(x.binary);
    j.key("bytes").value((unsigned long long)x.bytes);
    j.endObject();
  }
  j.key("timings_s").beginObject();
  for (const auto& t : x.timings) j.key(t.name).value(t.seconds);
  j.key("total").value(x.totalSeconds);
  j.endObject();
  j.endObject();
}

void printVolumeInfo(std::ostream& out, const std::string& path, const io::AnyVolume& volume,
                     const VolumeStats& s) {
  const Dims& d = io::dimsOf(volume);
  const ImageGeometry& g = io::geometryOf(volume);
  out << "surftrack: " << path << "\n";
  row(out, "size", std::to_string(d.nx) + " x " + std::to_string(d.ny) + " x " + std::to_string(d.nz) +
                       " = " + std::to_string(d.count()) + " voxels of " + io::toString(io::scalarTypeOf(volume)));
  row(out, "spacing", tripleText(g.spacing));
  row(out, "origin", tripleText(g.origin));
  row(out, "direction", directionText(g));
  std::array<double, 3> far = g.toPhysical({double(d.nx - 1), double(d.ny - 1), double(d.nz - 1)});
  row(out, "extent", "voxel centres from " + tripleText(g.origin) + " to " + tripleText(far));
  {
    std::ostringstream v;
    v << '[' << num(s.min) << ", " << num(s.max) << "], mean " << num(s.mean);
    if (s.nonFinite) v << ", " << s.nonFinite << " non-finite voxels";
    row(out, "values", v.str());
  }
  {
    std::ostringstream q;
    q << "1% " << num(s.quantile(0.01)) << ", 25% " << num(s.quantile(0.25)) << ", 50% "
      << num(s.quantile(0.5)) << ", 75% " << num(s.quantile(0.75)) << ", 99% " << num(s.quantile(0.99))
      << " (histogram bins of " << num(s.binWidth) << ")";
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
      l << " " << value;
    }
    row(out, "labels", l.str());
  }
}

void writeVolumeJson(JsonWriter& j, const std::string& path, const io::AnyVolume& volume,
                     const VolumeStats& s) {
  const Dims& d = io::dimsOf(volume);
  const ImageGeometry& g = io::geometryOf(volume);
  j.beginObject();
  j.key("input").value(path);
  j.key("dims").array(std::array<int, 3>{d.nx, d.ny, d.nz});
  j.key("type").value(io::toString(io::scalarTypeOf(volume)));
  j.key("spacing").array(g.spacing);
  j.key("origin").array(g.origin);
  j.key("direction").beginArray();
  for (const auto& r : g.direction) j.array(r);
  j.endArray();
  j.key("min").value(s.min);
  j.key("max").value(s.max);
  j.key("mean").value(s.mean);
  j.key("non_finite").value(s.nonFinite);
  j.key("otsu").value(s.otsu);
  j.key("histogram").beginObject();
  j.key("bin_width").value(s.binWidth);
  j.key("counts").array(s.histogram);
  j.endObject();
  if (!s.labels.empty()) {
    j.key("labels").beginArray();
    for (auto [value, count] : s.labels) {
      j.beginObject();
      j.key("value").value((long long)value);
      j.key("voxels").value(count);
      j.endObject();
    }
    j.endArray();
  }
  j.endObject();
}

}  // namespace surftrack::cli
