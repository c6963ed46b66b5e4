// Figure 9 of Lachaud & Montanvert (paper §5.3), reproduced with the protocol of
// docs/figure9.md, 'Protocol': extracting ONE connected iso-surface of a noisy gray sphere
//   method 1  : scanning the whole q^3 image with the configuration table (scanIsoSurface);
//   method 1b : method 1, then keeping the seed's component (extractComponent) — what a user of
//               a marching-cubes tool must do to get one kappa-lambda-boundary;
//   method 2  : tracking the boundary from the seed surfel (trackComponent) and converting its
//               surface graph by loop extraction (extractLoops).
// All three give the same kind of result, an indexed triangle mesh whose vertices are surfels.
// Building the OpenMesh half-edge mesh of the one component (iso-value vertex placement +
// toSurfaceMesh) is timed as a separate stage, as are the stages of methods 1b and 2.
//
// Before anything is timed, method 2's mesh is checked to be identical to the seed's component
// of method 1's mesh (same surfels, same oriented triangles); the program stops with exit code 3
// otherwise. Times are single-threaded medians of several runs, wall clock (steady_clock) and
// thread CPU time (CLOCK_THREAD_CPUTIME_ID) side by side.
//
//   bench_figure9 [--quick | --sizes 32,64,...] [--noise 0,0.01,0.05] [--pair 26-6]
//                 [--runs N] [--out DIR] [--plot-clock wall|cpu] [--no-plot] [--noise-seed S]
//                 [--no-generic] [--corrupt]
//
// For reference only (the targets use method 1), the scan is also timed through the images'
// generic operator() path (scanIsoSurfaceGeneric: every voxel read one call at a time, the
// way a classical marching-cubes loop reads them); --no-generic skips it.
//
// Output in DIR (default figure9-results/): figure9.csv (one row per q, noise, method/stage),
// figure9-summary.csv (one row per q, noise: times, ratios, throughput), figure9-slopes.csv,
// figure9-table.md, figure9-targets.txt, figure9.gp and figure9.png (gnuplot).
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "BoundaryMapping.h"
#include "LoopExtraction.h"
#include "ScanIsoSurface.h"
#include "BenchSupport.h"
#include "Phantoms.h"
#include "SurfaceMesh.h"
#include "TrackComponent.h"

using namespace surftrack;
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// Options

const std::vector<int> kDefaultSizes{32, 48, 64, 96, 128, 192, 256, 384, 512};
const std::vector<int> kQuickSizes{32, 48, 64, 96, 128, 192, 256};
constexpr int kMaxSide = 1024;
constexpr int kFitMinSide = 64;  // slopes are fitted over q >= 64

struct Options {
  std::vector<int> sides = kDefaultSizes;
  std::vector<double> noises{0.0, 0.01, 0.05};
  AdjacencyPair pair = AdjacencyPair::k26_6;
  int runs = 0;  // 0: 5 runs for q <= 128, 3 above
  fs::path out = "figure9-results";
  bool plotCpu = false;
  bool plot = true;
  bool generic = true;   // also time the per-voxel (generic operator()) scan, for reference
  bool corrupt = false;  // --corrupt: reverse one triangle of method 2 to prove the check works
  std::uint64_t noiseSeed = kDefaultNoiseSeed;
  std::string commandLine;
};

[[noreturn]] void usage(const std::string& error) {
  if (!error.empty()) std::fprintf(stderr, "bench_figure9: %s\n", error.c_str());
  std::fprintf(stderr,
               "usage: bench_figure9 [--quick | --sizes 32,48,64,...] [--noise 0,0.01,0.05]\n"
               "                     [--pair 26-6|18-6|6-18|6-26] [--runs N] [--out DIR]\n"
               "                     [--plot-clock wall|cpu] [--no-plot] [--noise-seed S]\n"
               "                     [--no-generic] [--corrupt]  (reverses one triangle of method 2: the\n"
               "                     equality check must then fail with exit code 3)\n"
               "  default sizes: 32,48,64,96,128,192,256,384,512; --quick: 32..256 (under two\n"
               "  minutes on 2 cores); sizes up to %d. Runs: median of 5 for q <= 128, 3 above.\n",
               kMaxSide);
  std::exit(2);
}

template <class T>
std::vector<T> parseList(const std::string& text, const char* what) {
  try {
    return bench::parseList<T>(text, what);
  } catch (const std::invalid_argument& e) {
    usage(e.what());
  }
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 0; i < argc; ++i) {
    if (i) o.commandLine += ' ';
    o.commandLine += argv[i];
  }
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage("missing value after " + a);
      return argv[++i];
    };
    if (a == "--quick") o.sides = kQuickSizes;
    else if (a == "--sizes") o.sides = parseList<int>(value(), "size");
    else if (a == "--noise") o.noises = parseList<double>(value(), "noise level");
    else if (a == "--pair") {
      try {
        o.pair = parseAdjacencyPair(value());
      } catch (const std::exception& e) {
        usage(e.what());
      }
    } else if (a == "--runs") {
      o.runs = std::atoi(value().c_str());
      if (o.runs < 1) usage("--runs must be at least 1");
    } else if (a == "--out") o.out = value();
    else if (a == "--plot-clock") {
      const std::string c = value();
      if (c != "wall" && c != "cpu") usage("--plot-clock is wall or cpu");
      o.plotCpu = c == "cpu";
    } else if (a == "--no-plot") o.plot = false;
    else if (a == "--corrupt") o.corrupt = true;
    else if (a == "--no-generic") o.generic = false;
    else if (a == "--noise-seed") o.noiseSeed = std::strtoull(value().c_str(), nullptr, 10);
    else if (a == "--help" || a == "-h") usage("");
    else usage("unknown option " + a);
  }
  for (int q : o.sides)
    if (q < 8 || q > kMaxSide) usage("sizes must lie in [8, " + std::to_string(kMaxSide) + "]");
  for (double p : o.noises)
    if (!(p >= 0.0 && p < 0.5)) usage("noise levels must lie in [0, 0.5)");
  std::sort(o.sides.begin(), o.sides.end());
  o.sides.erase(std::unique(o.sides.begin(), o.sides.end()), o.sides.end());
  return o;
}

// ---------------------------------------------------------------------------------------------
// Clocks

struct Instant {
  std::chrono::steady_clock::time_point wall;
  double cpu;  // seconds of this thread's CPU time
};

Instant now() { return {std::chrono::steady_clock::now(), bench::threadCpuSeconds()}; }

/// Milliseconds of wall and CPU time between two instants.
struct Span {
  double wall = 0, cpu = 0;
  Span operator+(const Span& o) const { return {wall + o.wall, cpu + o.cpu}; }
};

Span between(const Instant& a, const Instant& b) {
  return {1e3 * std::chrono::duration<double>(b.wall - a.wall).count(), 1e3 * (b.cpu - a.cpu)};
}

/// Per-run samples of one method or stage; medians taken separately per clock.
struct Samples {
  std::vector<double> wall, cpu;
  void add(const Span& s) {
    wall.push_back(s.wall);
    cpu.push_back(s.cpu);
  }
  double wallMs() const { return bench::median(wall); }
  double cpuMs() const { return bench::median(cpu); }
};

// ---------------------------------------------------------------------------------------------
// The equality check: same surfels, same oriented triangles (as cyclic triples of surfels).

using KeyTriangle = std::array<std::uint64_t, 3>;

std::vector<std::uint64_t> sortedSurfelKeys(const TriangleMesh& m) {
  std::vector<std::uint64_t> keys;
  keys.reserve(m.surfels.size());
  for (const Surfel& s : m.surfels) keys.push_back(s.key());
  std::sort(keys.begin(), keys.end());
  return keys;
}

/// Triangles as surfel keys, each rotated (orientation kept) so that its smallest key is first.
std::vector<KeyTriangle> sortedKeyTriangles(const TriangleMesh& m) {
  std::vector<KeyTriangle> out;
  out.reserve(m.triangles.size());
  for (const auto& t : m.triangles) {
    KeyTriangle k{m.surfels[t[0]].key(), m.surfels[t[1]].key(), m.surfels[t[2]].key()};
    const int first = int(std::min_element(k.begin(), k.end()) - k.begin());
    std::rotate(k.begin(), k.begin() + first, k.end());
    out.push_back(k);
  }
  std::sort(out.begin(), out.end());
  return out;
}

template <class T>
std::size_t countNotIn(const std::vector<T>& a, const std::vector<T>& b, T* example) {
  std::vector<T> diff;
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(diff));
  if (!diff.empty() && example) *example = diff.front();
  return diff.size();
}

std::string describeTriangle(const KeyTriangle& t) {
  std::ostringstream s;
  s << '(' << Surfel::fromKey(t[0]) << ", " << Surfel::fromKey(t[1]) << ", "
    << Surfel::fromKey(t[2]) << ')';
  return s.str();
}

/// Empty when method 2's mesh equals the seed component of method 1's; else what differs.
std::string compareMeshes(const TriangleMesh& tracked, const TriangleMesh& scanned) {
  std::ostringstream why;
  const auto vt = sortedSurfelKeys(tracked), vs = sortedSurfelKeys(scanned);
  if (std::adjacent_find(vt.begin(), vt.end()) != vt.end()) why << "  method 2 repeats a surfel\n";
  std::uint64_t ex = 0;
  if (std::size_t n = countNotIn(vt, vs, &ex))
    why << "  " << n << " surfels only in method 2's mesh, e.g. " << Surfel::fromKey(ex) << "\n";
  if (std::size_t n = countNotIn(vs, vt, &ex))
    why << "  " << n << " surfels only in method 1's component, e.g. " << Surfel::fromKey(ex) << "\n";
  const auto tt = sortedKeyTriangles(tracked), ts = sortedKeyTriangles(scanned);
  KeyTriangle et{};
  if (std::size_t n = countNotIn(tt, ts, &et))
    why << "  " << n << " triangles only in method 2's mesh, e.g. " << describeTriangle(et) << "\n";
  if (std::size_t n = countNotIn(ts, tt, &et))
    why << "  " << n << " triangles only in method 1's component, e.g. " << describeTriangle(et) << "\n";
  if (why.str().empty() && tt != ts) why << "  the triangle multisets differ (repeated triangles)\n";
  return why.str();
}

// ---------------------------------------------------------------------------------------------
// One (q, p) measurement

struct Row {
  int q = 0;
  double noise = 0;
  std::size_t components = 0;      // components (kappa-lambda-boundaries) found by scanning
  std::size_t allSurfels = 0, allTriangles = 0;  // method 1's whole mesh
  std::size_t surfels = 0, triangles = 0;        // the seed's component
  Surfel seed{};  // protocolSeed
  int runs = 0;
  Samples scan, extract, scanExtract, track, loops, trackLoops, openmesh, generic;
};

template <class T>
void discard(T& value) {  // free the memory now
  T gone = std::move(value);
  value = T{};
}

Row measure(const Options& o, int q, double noise) {
  Row row;
  row.q = q;
  row.noise = noise;
  row.runs = o.runs > 0 ? o.runs : (q <= 128 ? 5 : 3);
  char tag[64];
  std::snprintf(tag, sizeof tag, "q=%d p=%g%%", q, 100 * noise);

  std::fprintf(stderr, "[%s] generating the %d^3 sphere image...\n", tag, q);
  NoisyPhantom sphere = makeNoisySphere(q, noise, o.noiseSeed);
  const Surfel seed = protocolSeed(sphere);
  row.seed = seed;
  if (seed.c.y != q / 2 || seed.c.z != q / 2)
    std::fprintf(stderr, "[%s] noise hit the sphere's surfel on the +x ray through (q/2, q/2): the "
                         "protocol's seed is on the row y = %d\n", tag, seed.c.y);
  discard(sphere.hit);  // only needed to choose the seed
  const auto image = sphere.binary();
  const IsoValueMapping mapping(image);

  // Reference run (also the warm-up): the equality check comes before any timing.
  std::fprintf(stderr, "[%s] checking method 2 against method 1b...\n", tag);
  {
    TriangleMesh whole = scanIsoSurface(image, o.pair, 1);
    row.allSurfels = whole.surfels.size();
    row.allTriangles = whole.triangles.size();
    meshComponents(whole, row.components);
    TriangleMesh component = extractComponent(whole, seed);
    discard(whole);
    const SurfaceGraph graph = trackComponent(image, seed, o.pair);
    TriangleMesh tracked = extractLoops(graph);
    if (o.corrupt && !tracked.triangles.empty())
      std::swap(tracked.triangles[tracked.triangles.size() / 2][0],
                tracked.triangles[tracked.triangles.size() / 2][1]);
    std::string why;
    if (graph.surfels.size() != tracked.surfels.size())
      why += "  the tracked graph and method 2's mesh have different vertex counts\n";
    why += compareMeshes(tracked, component);
    if (!why.empty()) {
      std::fprintf(stderr,
                   "bench_figure9: EQUALITY CHECK FAILED for q=%d, noise=%g, pair %s: method 2's "
                   "mesh (%zu surfels, %zu triangles) is not the seed's component of method 1's "
                   "mesh (%zu surfels, %zu triangles):\n%s"
                   "No timing is reported: a benchmark of a wrong answer is worthless.\n",
                   q, noise, toString(o.pair).c_str(), tracked.surfels.size(),
                   tracked.triangles.size(), component.surfels.size(),
                   component.triangles.size(), why.c_str());
      std::exit(3);
    }
    row.surfels = tracked.surfels.size();
    row.triangles = tracked.triangles.size();
    // The OpenMesh stage must accept the mesh (it refuses non-manifold triangles).
    const SurfaceMesh half = toSurfaceMesh(tracked, mapVertices(tracked, mapping));
    if (half.n_vertices() != row.surfels || half.n_faces() != row.triangles) {
      std::fprintf(stderr, "bench_figure9: the OpenMesh mesh lost vertices or faces (q=%d)\n", q);
      std::exit(3);
    }
  }
  std::fprintf(stderr, "[%s] identical: %zu surfels, %zu triangles (whole image: %zu surfels, %zu "
                       "components); timing %d runs...\n",
               tag, row.surfels, row.triangles, row.allSurfels, row.components, row.runs);

  // Timed runs; the methods alternate inside each run so that any slow period of the machine
  // is spread over all of them. Results are destroyed outside the timed regions.
  std::size_t sink = 0;
  for (int r = 0; r < row.runs; ++r) {
    {
      const Instant t0 = now();
      TriangleMesh whole = scanIsoSurface(image, o.pair, 1);
      const Instant t1 = now();
      TriangleMesh component = extractComponent(whole, seed);
      const Instant t2 = now();
      sink += whole.triangles.size() + component.triangles.size();
      const Span scan = between(t0, t1), extract = between(t1, t2);
      row.scan.add(scan);
      row.extract.add(extract);
      row.scanExtract.add(scan + extract);
    }
    if (o.generic) {
      const Instant t0 = now();
      TriangleMesh whole = scanIsoSurfaceGeneric(image, o.pair, 1);
      const Instant t1 = now();
      sink += whole.triangles.size();
      row.generic.add(between(t0, t1));
    }
    {
      const Instant t0 = now();
      SurfaceGraph graph = trackComponent(image, seed, o.pair);
      const Instant t1 = now();
      TriangleMesh tracked = extractLoops(graph);
      const Instant t2 = now();
      const Span track = between(t0, t1), loops = between(t1, t2);
      row.track.add(track);
      row.loops.add(loops);
      row.trackLoops.add(track + loops);

      const Instant t3 = now();
      SurfaceMesh half = toSurfaceMesh(tracked, mapVertices(tracked, mapping));
      const Instant t4 = now();
      row.openmesh.add(between(t3, t4));
      sink += graph.surfels.size() + tracked.triangles.size() + half.n_faces();
    }
  }
  if (sink == 1) std::fprintf(stderr, " ");  // keep the results observable

  std::fprintf(stderr,
               "[%s] method 1 %.2f ms (%.0f Mvox/s), 1b %.2f ms, 2 %.2f ms (track %.2f + loops "
               "%.2f), openmesh %.2f ms; t2/t1 = %.4f, t2/t1b = %.4f\n",
               tag, row.scan.wallMs(), double(q) * q * q / row.scan.wallMs() / 1e3,
               row.scanExtract.wallMs(), row.trackLoops.wallMs(), row.track.wallMs(),
               row.loops.wallMs(), row.openmesh.wallMs(),
               row.trackLoops.wallMs() / row.scan.wallMs(),
               row.trackLoops.wallMs() / row.scanExtract.wallMs());
  return row;
}

// ---------------------------------------------------------------------------------------------
// Fits and reports

struct Fit {
  double slope = NAN, intercept = NAN;  // log(ms) = intercept + slope * log(q)
  int points = 0;
};

/// Least squares of log(ms) against log(q), over q >= kFitMinSide.
Fit fitSlope(const std::vector<std::pair<int, double>>& qms) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (auto [q, ms] : qms) {
    if (q < kFitMinSide || !(ms > 0)) continue;
    const double x = std::log(double(q)), y = std::log(ms);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  Fit f;
  f.points = n;
  if (n < 2) return f;
  const double d = n * sxx - sx * sx;
  if (d <= 0) return f;
  f.slope = (n * sxy - sx * sy) / d;
  f.intercept = (sy - f.slope * sx) / n;
  return f;
}

std::string percent(double p) {
  std::ostringstream s;
  s << 100 * p << "%";
  return s.str();
}

struct MethodRef {
  const char* name;   // CSV name
  const char* label;  // plot label
  Samples Row::*samples;
};

const MethodRef kMethods[] = {
    {"method1_scan", "method 1 (scan)", &Row::scan},
    {"method1b_scan_extract", "method 1b (scan + component)", &Row::scanExtract},
    {"method2_track_loops", "method 2 (track + loops)", &Row::trackLoops},
    {"stage_extract", "stage: extractComponent", &Row::extract},
    {"stage_track", "stage: trackComponent", &Row::track},
    {"stage_loops", "stage: extractLoops", &Row::loops},
    {"stage_openmesh", "stage: OpenMesh half-edge mesh", &Row::openmesh},
    {"reference_scan_generic", "method 1 through operator() (reference)", &Row::generic},
};

double ms(const Samples& s, bool cpu) { return cpu ? s.cpuMs() : s.wallMs(); }

void writeCsv(const fs::path& path, const Options& o, const std::vector<Row>& rows) {
  std::ofstream f(path);
  f << "q,noise,pair,method,runs,ms,cpu_ms,surfels,triangles,scan_components\n";
  f << std::setprecision(6);
  for (const Row& r : rows)
    for (const MethodRef& m : kMethods) {
      if ((r.*m.samples).wall.empty()) continue;
      const bool whole = m.samples == &Row::scan || m.samples == &Row::generic;
      f << r.q << ',' << r.noise << ',' << toString(o.pair) << ',' << m.name << ',' << r.runs << ','
        << (r.*m.samples).wallMs() << ',' << (r.*m.samples).cpuMs() << ','
        << (whole ? r.allSurfels : r.surfels) << ',' << (whole ? r.allTriangles : r.triangles)
        << ',' << r.components << '\n';
    }
}

void writeSummary(const fs::path& path, const Options& o, const std::vector<Row>& rows) {
  std::ofstream f(path);
  f << "q,noise,pair,t1_ms,t1b_ms,t2_ms,t2_over_t1,t2_over_t1b,scan_mvoxels_per_s,"
       "t1_cpu_ms,t1b_cpu_ms,t2_cpu_ms,t2_over_t1_cpu,t2_over_t1b_cpu,scan_mvoxels_per_s_cpu,"
       "openmesh_ms,generic_scan_ms,surfels,triangles,scan_components,seed_x,seed_y,seed_z,seed_normal\n";
  f << std::setprecision(6);
  for (const Row& r : rows) {
    const double vox = double(r.q) * r.q * r.q;
    f << r.q << ',' << r.noise << ',' << toString(o.pair);
    for (bool cpu : {false, true}) {
      const double t1 = ms(r.scan, cpu), t1b = ms(r.scanExtract, cpu), t2 = ms(r.trackLoops, cpu);
      f << ',' << t1 << ',' << t1b << ',' << t2 << ',' << t2 / t1 << ',' << t2 / t1b << ','
        << vox / t1 / 1e3;
    }
    f << ',' << r.openmesh.wallMs() << ',' << r.generic.wallMs() << ',' << r.surfels << ',' << r.triangles << ','
      << r.components << ',' << r.seed.c.x << ',' << r.seed.c.y << ','
      << r.seed.c.z << ',' << std::string_view("+x-x+y-y+z-z").substr(2 * r.seed.n, 2) << '\n';
  }
}

/// Data for gnuplot: one block per noise level (index i), columns
/// q t1 t1b t2 t2/t1 t2/t1b Mvox/s track loops openmesh.
void writePlotData(const fs::path& path, const Options& o, const std::vector<Row>& rows) {
  std::ofstream f(path);
  f << std::setprecision(6);
  f << "# clock: " << (o.plotCpu ? "thread CPU time" : "wall clock") << "\n";
  for (std::size_t i = 0; i < o.noises.size(); ++i) {
    if (i) f << "\n\n";
    f << "# noise " << o.noises[i] << "\n# q t1_ms t1b_ms t2_ms t2/t1 t2/t1b scan_Mvox_s "
         "track_ms loops_ms openmesh_ms generic_scan_Mvox_s\n";
    for (const Row& r : rows) {
      if (r.noise != o.noises[i]) continue;
      const double t1 = ms(r.scan, o.plotCpu), t1b = ms(r.scanExtract, o.plotCpu),
                   t2 = ms(r.trackLoops, o.plotCpu);
      f << r.q << ' ' << t1 << ' ' << t1b << ' ' << t2 << ' ' << t2 / t1 << ' ' << t2 / t1b << ' '
        << double(r.q) * r.q * r.q / t1 / 1e3 << ' ' << ms(r.track, o.plotCpu) << ' '
        << ms(r.loops, o.plotCpu) << ' ' << ms(r.openmesh, o.plotCpu) << ' '
        << double(r.q) * r.q * r.q / ms(r.generic, o.plotCpu) / 1e3 << '\n';
    }
  }
}

// fits[noise index][0: method 1, 1: method 1b, 2: method 2]
using Fits = std::vector<std::array<Fit, 3>>;

Fits computeFits(const Options& o, const std::vector<Row>& rows, bool cpu) {
  Fits fits(o.noises.size());
  for (std::size_t i = 0; i < o.noises.size(); ++i)
    for (int m = 0; m < 3; ++m) {
      std::vector<std::pair<int, double>> pts;
      for (const Row& r : rows)
        if (r.noise == o.noises[i]) pts.push_back({r.q, ms(r.*kMethods[m].samples, cpu)});
      fits[i][m] = fitSlope(pts);
    }
  return fits;
}

void writeSlopes(const fs::path& path, const Options& o, const Fits& wall, const Fits& cpu) {
  std::ofstream f(path);
  f << "method,noise,pair,slope_wall,intercept_wall,slope_cpu,intercept_cpu,points,fit_min_q\n";
  f << std::setprecision(6);
  for (std::size_t i = 0; i < o.noises.size(); ++i)
    for (int m = 0; m < 3; ++m)
      f << kMethods[m].name << ',' << o.noises[i] << ',' << toString(o.pair) << ','
        << wall[i][m].slope << ',' << wall[i][m].intercept << ',' << cpu[i][m].slope << ','
        << cpu[i][m].intercept << ',' << wall[i][m].points << ',' << kFitMinSide << '\n';
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string ratioText(double r) {
  return r < 1 ? fmt("%.3g", r) + " (1/" + fmt("%.3g", 1 / r) + ")" : fmt("%.3g", r);
}

/// Markdown table: one line per (q, p), wall ms with CPU ms in parentheses where they differ.
std::string markdownTable(const std::vector<Row>& rows) {
  std::ostringstream t;
  t << "| q | noise | comps (scan) | surfels (1 comp.) | method 1 ms | Mvox/s | method 1b ms | "
       "track ms | loops ms | method 2 ms | OpenMesh ms | t2/t1 | t2/t1b | generic scan ms |\n"
    << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    auto msText = [](double v) { return fmt(v >= 100 ? "%.0f" : v >= 10 ? "%.1f" : "%.2f", v); };
    auto both = [&](const Samples& s) { return msText(s.wallMs()) + " (" + msText(s.cpuMs()) + ")"; };
    const double t1 = r.scan.wallMs(), t2 = r.trackLoops.wallMs();
    t << "| " << r.q << " | " << percent(r.noise) << " | " << r.components << " | " << r.surfels
      << " | " << both(r.scan) << " | " << fmt("%.0f", double(r.q) * r.q * r.q / t1 / 1e3) << " | "
      << both(r.scanExtract) << " | " << both(r.track) << " | " << both(r.loops) << " | "
      << both(r.trackLoops) << " | " << both(r.openmesh) << " | " << ratioText(t2 / t1) << " | "
      << ratioText(t2 / r.scanExtract.wallMs()) << " | "
      << (r.generic.wall.empty() ? std::string("-") : both(r.generic)) << " |\n";
  }
  for (const Row& r : rows)
    if (r.seed.c.y != r.q / 2 || r.seed.c.z != r.q / 2)
      t << "\nq = " << r.q << ", noise " << percent(r.noise) << ": noise hit the sphere's surfel on "
        << "the row y = z = q/2; the protocol's seed is " << r.seed << ".\n";
  return t.str();
}

/// The targets, evaluated on the largest q = 512 row if present.
std::string targetReport(const Options& o, const std::vector<Row>& rows, const Fits& wall,
                         const Fits& cpu) {
  std::ostringstream t;
  auto find = [&](int q, double p) -> const Row* {
    for (const Row& r : rows)
      if (r.q == q && r.noise == p) return &r;
    return nullptr;
  };
  auto verdict = [](bool ok) { return ok ? "MET" : "NOT MET"; };
  // What method 2 may cost per surfel for the ratio target, against what it costs.
  auto gap = [](const Row& r, bool c, double target) {
    const double t1 = ms(r.scan, c), t2 = ms(r.trackLoops, c), S = double(r.surfels);
    const double budget = target * t1;
    std::ostringstream g;
    g << "    method 2: " << fmt("%.1f", t2) << " ms = " << fmt("%.0f", 1e6 * t2 / S)
      << " ns/surfel (track " << fmt("%.0f", 1e6 * ms(r.track, c) / S) << " + loops "
      << fmt("%.0f", 1e6 * ms(r.loops, c) / S) << "); the target allows " << fmt("%.1f", budget)
      << " ms = " << fmt("%.1f", 1e6 * budget / S) << " ns/surfel";
    if (t2 > budget) g << ": " << fmt("%.1f", t2 / budget) << "x too slow";
    g << "\n";
    return g.str();
  };
  for (bool c : {false, true}) {
    const char* clock = c ? "thread CPU time" : "wall clock";
    const Fits& fits = c ? cpu : wall;
    t << "targets (" << clock << ", pair " << toString(o.pair) << "):\n";
    if (const Row* r = find(512, 0.0)) {
      const double ratio = ms(r->trackLoops, c) / ms(r->scan, c);
      const double thr = 512.0 * 512 * 512 / ms(r->scan, c) / 1e3;
      t << "  q=512 p=0%: t2/t1 = " << fmt("%.4f", ratio) << (ratio < 1 ? " = 1/" + fmt("%.1f", 1 / ratio) : std::string(" (method 2 slower)"))
        << " (target <= 1/10): " << verdict(ratio <= 0.1) << "\n" << gap(*r, c, 0.1);
      t << "  q=512 p=0%: scanning throughput " << fmt("%.1f", thr)
        << " M voxels/s (target >= 150): " << verdict(thr >= 150) << "\n";
    } else {
      t << "  q=512 p=0% not measured\n";
    }
    if (const Row* r = find(512, 0.05)) {
      const double ratio = ms(r->trackLoops, c) / ms(r->scan, c);
      t << "  q=512 p=5%: t2/t1 = " << fmt("%.4f", ratio) << (ratio < 1 ? " = 1/" + fmt("%.1f", 1 / ratio) : std::string(" (method 2 slower)"))
        << " (target <= 1/30): " << verdict(ratio <= 1.0 / 30) << "\n" << gap(*r, c, 1.0 / 30);
    } else {
      t << "  q=512 p=5% not measured\n";
    }
    for (std::size_t i = 0; i < o.noises.size(); ++i) {
      const Fit& f1 = fits[i][0];
      const Fit& f2 = fits[i][2];
      t << "  p=" << percent(o.noises[i]) << ": slope method 2 = " << fmt("%.3f", f2.slope)
        << " (target 2 +- 0.3): " << verdict(std::abs(f2.slope - 2) <= 0.3)
        << "; slope method 1 = " << fmt("%.3f", f1.slope)
        << " (target 3 +- 0.3): " << verdict(std::abs(f1.slope - 3) <= 0.3) << "; method 1b "
        << fmt("%.3f", fits[i][1].slope) << " (" << f1.points << " sizes >= " << kFitMinSide
        << ")\n";
    }
  }
  return t.str();
}

// ---------------------------------------------------------------------------------------------
// gnuplot

std::string gnuplotScript(const Options& o, const std::vector<Row>& rows, const Fits& fits) {
  // Panel (a)'s range: all ratios, and the 1/10 and 1/30 target lines.
  double lo = 1.0 / 30, hi = 0.1;
  for (const Row& r : rows) {
    const double t2 = ms(r.trackLoops, o.plotCpu);
    for (double t : {ms(r.scan, o.plotCpu), ms(r.scanExtract, o.plotCpu)})
      if (t > 0 && t2 > 0) lo = std::min(lo, t2 / t), hi = std::max(hi, t2 / t);
  }
  std::ostringstream g;
  const char* clock = o.plotCpu ? "thread CPU time" : "wall clock";
  const std::string pair = "(" + std::to_string(kappa(o.pair)) + "," +
                           std::to_string(lambda(o.pair)) + ")";
  g << "# Generated by bench_figure9: " << o.commandLine << "\n"
    << "# Re-run with: gnuplot figure9.gp (in this directory)\n"
    << "set terminal pngcairo size 1600,1200 font 'Sans,11'\n"
    << "set output 'figure9.png'\n"
    << "set datafile commentschars '#'\n"
    << "set key top right\nset grid\nset xlabel 'image side q'\n"
    << "set multiplot layout 2,2 title 'Figure 9 reproduced: one sphere iso-surface, pair "
    << pair << ", single thread, median " << clock << "' font 'Sans,14'\n";
  // Line styles: colour per noise level; point types like the paper (diamond, cross, square).
  const char* colours[] = {"#1f4e99", "#c2410c", "#15803d", "#7e22ce", "#444444"};
  const int points[] = {12, 2, 4, 6, 8};
  const char* dashes[] = {"1", "2", "3", "4", "5"};
  const std::size_t n = o.noises.size();
  for (std::size_t i = 0; i < n; ++i)
    g << "set style line " << i + 1 << " lc rgb '" << colours[i % 5] << "' lw 2 pt " << points[i % 5]
      << " ps 1.3 dt " << dashes[i % 5] << "\n";
  auto noiseLabel = [&](std::size_t i) { return percent(o.noises[i]) + " noise"; };

  // (a) ratios
  g << "set title '(a) time(method 2) / time(method 1): thick, hollow; / time(method 1b): thin, filled'\n"
    << "set logscale y\nset ylabel 'time ratio (log scale)'\nset format y '%g'\n"
    << "set xrange [0:*]\nset yrange [" << lo / 1.5 << ":" << hi * 8 << "]\n"
    << "set arrow 1 from graph 0, first 0.1 to graph 1, first 0.1 nohead lc rgb '#888888' dt 2\n"
    << "set label 1 'target 1/10 (no noise)' at graph 0.01, first 0.115 tc rgb '#666666'\n"
    << "set arrow 2 from graph 0, first (1.0/30) to graph 1, first (1.0/30) nohead lc rgb '#888888' dt 2\n"
    << "set label 2 'target 1/30 (5% noise)' at graph 0.01, first 0.0383 tc rgb '#666666'\n"
    << "plot ";
  for (std::size_t i = 0; i < n; ++i)
    g << (i ? ", \\\n     " : "") << "'figure9-plot.dat' index " << i
      << " using 1:5 with linespoints ls " << i + 1 << " title '2/1, " << noiseLabel(i) << "'";
  for (std::size_t i = 0; i < n; ++i)
    g << ", \\\n     'figure9-plot.dat' index " << i << " using 1:6 with linespoints ls " << i + 1
      << " lw 1 pt " << points[i % 5] + 1 << " title '2/1b, " << noiseLabel(i) << "'";
  g << "\nunset arrow 1\nunset arrow 2\nunset label 1\nunset label 2\nset yrange [*:*]\n";

  // (b) time of method 2, linear axes like the paper
  g << "set title '(b) time of method 2 (tracking + loop extraction)'\n"
    << "unset logscale y\nset ylabel 'time (ms)'\nset key top left\n"
    << "plot ";
  for (std::size_t i = 0; i < n; ++i)
    g << (i ? ", \\\n     " : "") << "'figure9-plot.dat' index " << i
      << " using 1:4 with linespoints ls " << i + 1 << " title '" << noiseLabel(i) << "'";
  g << "\n";

  // (c) log-log, with the fitted lines over q >= 64
  g << "set title '(c) time vs q, log-log; least-squares slopes over q >= " << kFitMinSide
    << "'\nset logscale xy\nset xrange [*:*]\nset ylabel 'time (ms)'\nset key top left Left reverse font 'Sans,9'\n";
  for (std::size_t i = 0; i < n; ++i) {
    for (int m = 0; m < 3; ++m)
      if (fits[i][m].points >= 2)
        g << "f" << i << "_" << m << "(x) = exp(" << fits[i][m].intercept << " + "
          << fits[i][m].slope << " * log(x))\n";
  }
  g << "plot ";
  bool first = true;
  const char* methodShort[] = {"method 1", "method 1b", "method 2"};
  const int methodCol[] = {2, 3, 4};
  const int methodPt[] = {5, 7, 9};
  for (int m : {0, 2}) {
    for (std::size_t i = 0; i < n; ++i) {
      g << (first ? "" : ", \\\n     ") << "'figure9-plot.dat' index " << i << " using 1:"
        << methodCol[m] << " with points lc rgb '" << colours[i % 5] << "' pt " << methodPt[m]
        << " ps 1.2 title '" << methodShort[m] << ", " << noiseLabel(i) << ": slope "
        << fmt("%.2f", fits[i][m].slope) << "'";
      first = false;
      if (fits[i][m].points >= 2)
        g << ", \\\n     [" << kFitMinSide << ":*] f" << i << "_" << m << "(x) with lines lc rgb '"
          << colours[i % 5] << "' dt " << (m == 0 ? 1 : 2) << " notitle";
    }
  }
  g << "\n";

  // (d) scanning throughput
  g << "set title '(d) throughput of method 1 (scanning the whole image)'\n"
    << "set logscale x\nunset logscale y\nset ylabel 'M voxels / s'\nset yrange [0:*]\n"
    << "set xrange [*:*]\n"
    << "set key top left Left reverse font 'Sans,9'\n"
    << "plot 150 with lines lc rgb '#888888' dt 2 title 'target: 150 M voxels/s (q = 512, no noise)', ";
  for (std::size_t i = 0; i < n; ++i)
    g << (i ? ", \\\n     " : "") << "'figure9-plot.dat' index " << i
      << " using 1:7 with linespoints ls " << i + 1 << " title '" << noiseLabel(i) << "'";
  if (o.generic)
    for (std::size_t i = 0; i < n; ++i)
      g << ", \\\n     'figure9-plot.dat' index " << i << " using 1:11 with linespoints ls " << i + 1
        << " lw 1 pt " << points[i % 5] + 1 << " title '" << noiseLabel(i)
        << ", per-voxel operator() scan (reference)'";
  g << "\nunset multiplot\n";
  return g.str();
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) {
    std::fprintf(stderr, "bench_figure9: cannot create %s: %s\n", o.out.c_str(), ec.message().c_str());
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  std::fprintf(stderr, "bench_figure9: pair %s, %zu sizes x %zu noise levels, output in %s\n",
               toString(o.pair).c_str(), o.sides.size(), o.noises.size(), o.out.c_str());

  std::vector<Row> rows;
  try {
    for (int q : o.sides)
      for (double p : o.noises) rows.push_back(measure(o, q, p));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_figure9: %s\n", e.what());
    return 1;
  }

  const Fits wall = computeFits(o, rows, false), cpu = computeFits(o, rows, true);
  writeCsv(o.out / "figure9.csv", o, rows);
  writeSummary(o.out / "figure9-summary.csv", o, rows);
  writeSlopes(o.out / "figure9-slopes.csv", o, wall, cpu);
  writePlotData(o.out / "figure9-plot.dat", o, rows);
  const std::string table = markdownTable(rows);
  const std::string targets = targetReport(o, rows, wall, cpu);
  std::ofstream(o.out / "figure9-table.md") << table;
  std::ofstream(o.out / "figure9-targets.txt") << targets;
  std::ofstream(o.out / "figure9.gp") << gnuplotScript(o, rows, o.plotCpu ? cpu : wall);

  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("Figure 9, pair %s, median wall ms (thread CPU ms); %s\n\n%s\n%s",
              toString(o.pair).c_str(), o.commandLine.c_str(), table.c_str(), targets.c_str());
  std::printf("total run time %.1f s\n", elapsed);

  if (o.plot) {
    const std::string cmd = "cd '" + o.out.string() + "' && gnuplot figure9.gp";
    if (std::system(cmd.c_str()) != 0)
      std::fprintf(stderr, "bench_figure9: gnuplot failed (is it installed?); the data and "
                           "%s/figure9.gp are written, run gnuplot there to draw the PNG\n",
                   o.out.c_str());
    else
      std::fprintf(stderr, "bench_figure9: wrote %s\n", (o.out / "figure9.png").c_str());
  }
  return 0;
}
