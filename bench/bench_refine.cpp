// Constrained smoothing and topology-safe decimation on the binary clean sphere (docs/
// performance.md, "Smoothing and decimation"): the Figure 9 sphere without noise, thresholded
// (R = 0.4 q), its midpoint mesh, then smooth() and decimate() of the front door; or, with
// --input, the largest boundary of a volume file at an iso-value (its default mapping). Prints
// one JSON object: triangles, the RMS of |x - c| - R over the vertices (the sphere), enclosed
// volumes, times; writes the three meshes as PLY for bench_refine_vtk.py, which runs VTK on the
// same mesh.
#include <surftrack/Extract.h>
#include <surftrack/Refine.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "BenchSupport.h"
#include "Phantoms.h"
#ifdef BENCH_REFINE_READS_VOLUMES
#include "ReadVolume.h"
#endif

using namespace surftrack;

namespace {

const char* kUsage =
    "usage: bench_refine [--size Q] [--iterations N] [--lambda L] [--mu M] [--max-error E]\n"
    "                    [--reduce F] [--threads T] [--out DIR] [--input FILE --iso V]\n"
    "  The binary clean sphere of Figure 9 (side Q, default 128, R = 0.4 Q), its midpoint mesh,\n"
    "  smoothed with N Taubin iterations (default 50, 0: no smoothing; lambda L, mu M: the\n"
    "  defaults of SmoothOptions) and decimated within E (default 0.5 voxel) removing F of the\n"
    "  triangles (default 0.9); smoothing on T threads (default 0: all cores). With --input,\n"
    "  the largest boundary of FILE at iso-value V (threshold, default mapping) instead, E in\n"
    "  physical units. Writes DIR/sphere-{midpoint,smoothed,decimated}.ply (default DIR: .) and\n"
    "  prints the figures as one JSON object; smoothing's CPU time is the process's (all threads).\n";

struct Figures {
  std::size_t triangles = 0;
  double rms = 0, volume = 0;
};

Figures figuresOf(const Surface& s, double centre, double radius) {
  Figures f;
  f.triangles = s.triangles.size();
  double sum = 0;
  for (const auto& p : s.vertices) {
    const double r = std::sqrt((p[0] - centre) * (p[0] - centre) + (p[1] - centre) * (p[1] - centre) +
                               (p[2] - centre) * (p[2] - centre));
    sum += (r - radius) * (r - radius);
  }
  f.rms = std::sqrt(sum / double(s.vertices.size()));
  for (const auto& c : componentFigures(s.vertices, s.triangles)) f.volume += c.volume;
  return f;
}

std::string json(const char* name, const Figures& f) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "\"%s\": {\"triangles\": %zu, \"rms\": %.6g, \"volume\": %.10g}", name, f.triangles,
                f.rms, f.volume);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int q = 128, iterations = 50;
    double maxError = 0.5, reduce = 0.9;
    SmoothOptions so;
    std::string out = ".", input;
    double iso = 0;
    for (bench::Arguments args(argc, argv); args.next();) {
      if (args.isHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (args.is("--size")) {
        q = std::stoi(args.value());
      } else if (args.is("--iterations")) {
        iterations = std::stoi(args.value());
      } else if (args.is("--max-error")) {
        maxError = std::stod(args.value());
      } else if (args.is("--reduce")) {
        reduce = std::stod(args.value());
      } else if (args.is("--lambda")) {
        so.lambda = std::stod(args.value());
      } else if (args.is("--mu")) {
        so.mu = std::stod(args.value());
      } else if (args.is("--threads")) {
        so.threads = std::stoi(args.value());
      } else if (args.is("--out")) {
        out = args.value();
      } else if (args.is("--input")) {
        input = args.value();
      } else if (args.is("--iso")) {
        iso = std::stod(args.value());
      } else {
        args.unknown();
      }
    }
    const NoisyPhantom sphere = makeNoisySphere(input.empty() ? q : 2, 0.0);
    Surface s;
    ExtractOptions o;
    if (input.empty()) {
      o.selection = Selection::threshold(sphere.iso);
      o.seed = SeedRule::fromSurfel(protocolSeed(sphere));
      o.mapping = Mapping::Midpoint;
      s = extract(VolumeView::of(sphere.image.data().data(), sphere.image.dims()), o);
    } else {
#ifdef BENCH_REFINE_READS_VOLUMES
      o.selection = Selection::threshold(iso);
      o.seed = SeedRule::largest();
      const io::AnyVolume volume = io::readVolume(input);
      s = std::visit(
          [&](const auto& image) {
            return extract(VolumeView::of(image.data().data(), image.dims(), image.geometry()), o);
          },
          volume);
#else
      throw std::runtime_error("--input needs the io library (configure with the CLI)");
#endif
    }
    const Figures midpoint = figuresOf(s, sphere.centre, sphere.radius);
    writeSurface(s, out + "/sphere-midpoint.ply");

    so.iterations = iterations;
    SmoothReport sr;
    // Smoothing may run on several threads: the process's CPU time.
    const double t0 = bench::wallSeconds(), c0 = bench::processCpuSeconds();
    if (iterations > 0) sr = smooth(s, so);
    const double smoothWall = bench::wallSeconds() - t0, smoothCpu = bench::processCpuSeconds() - c0;
    const Figures smoothed = figuresOf(s, sphere.centre, sphere.radius);
    writeSurface(s, out + "/sphere-smoothed.ply");

    DecimateOptions d;
    d.maxError = maxError;
    d.reduction = reduce;
    const double t1 = bench::wallSeconds(), c1 = bench::threadCpuSeconds();
    decimate(s, d);
    const double decimateWall = bench::wallSeconds() - t1, decimateCpu = bench::threadCpuSeconds() - c1;
    const Figures decimated = figuresOf(s, sphere.centre, sphere.radius);
    writeSurface(s, out + "/sphere-decimated.ply");

    std::printf("{\"q\": %d, \"radius\": %.6g, \"centre\": %.6g, \"iterations\": %d, \"max_error\": %g, \"reduce\": %g, \"threads\": %d,\n"
                " %s,\n %s,\n %s,\n \"max_displacement\": %.6g, \"steps_back\": %zu,\n"
                " \"smooth_s\": {\"wall\": %.4f, \"cpu\": %.4f}, \"decimate_s\": {\"wall\": %.4f, \"cpu\": %.4f}}\n",
                q, sphere.radius, sphere.centre, iterations, maxError, reduce, so.threads, json("midpoint", midpoint).c_str(),
                json("smoothed", smoothed).c_str(), json("decimated", decimated).c_str(), sr.maxDisplacement,
                sr.stepsBack, smoothWall, smoothCpu, decimateWall, decimateCpu);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_refine: " << e.what() << "\n";
    return 1;
  }
}
