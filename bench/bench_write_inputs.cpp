// The inputs of the end-to-end benchmark (bench/bench_end_to_end.py), written as a user's
// files: the noisy spheres of the Figure 9 protocol (lib/Phantoms.h) as MetaImage files, and a
// large sparse raw volume holding one digital ball. Prints one JSON object describing them
// (files, dimensions, iso-value, the protocol's seed surfel and its midpoint), so that every
// tool of the benchmark is given the same surface to find.
//
//   bench_write_inputs DIR [--sizes 256,512] [--noise 0,0.01,0.05] [--big 2048,2048,1040]
//                          [--radius 60] [--no-big]
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "BenchSupport.h"
#include "Phantoms.h"
#include "ReadVolume.h"

using namespace surftrack;
namespace fs = std::filesystem;

namespace {

const char* const kUsage =
    "usage: bench_write_inputs DIR [--sizes 256,512] [--noise 0,0.01,0.05] [--big NX,NY,NZ]\n"
    "                          [--radius R] [--no-big]\n"
    "\n"
    "Writes the inputs of bench/bench_end_to_end.py into DIR and prints them as JSON:\n"
    "  sphere_<q>_<p>.mha  the Figure 9 noisy spheres (uint8, iso-value 127.5), with the\n"
    "                      protocol's seed surfel (docs/figure9.md) and its midpoint;\n"
    "  big.raw             a sparse uint8 raw file (default 2048 x 2048 x 1040, 4.4 G voxels)\n"
    "                      of zeros holding one digital ball of 200s (default radius 60);\n"
    "                      only the ball's rows are written, the rest are holes.\n"
    "  --help              this text\n";

std::string seedText(const Surfel& s) {
  static const char* const names[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  const Voxel c = s.inside();
  return std::to_string(c.x) + "," + std::to_string(c.y) + "," + std::to_string(c.z) + "," + names[s.n];
}

std::string pointText(const Surfel& s) {
  const Voxel c = s.inside(), d = s.outside();
  std::ostringstream o;
  o.precision(10);
  o << "[" << (c.x + d.x) / 2.0 << ", " << (c.y + d.y) / 2.0 << ", " << (c.z + d.z) / 2.0 << "]";
  return o.str();
}

/// A file of nx ny nz zero bytes (holes: no disk space) with the ball's voxels set to `value`,
/// row run by row run.
void writeSparseBall(const std::string& path, Dims d, const Ball& ball, int radius, std::uint8_t value) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create '" + path + "': " + std::strerror(errno));
  const off_t size = off_t(d.nx) * d.ny * d.nz;
  if (::ftruncate(fd, size) != 0) throw std::runtime_error("cannot size '" + path + "': " + std::strerror(errno));
  const Voxel c = ball.centre;
  std::vector<std::uint8_t> run(std::size_t(2 * radius + 1), value);
  for (int z = c.z - radius; z <= c.z + radius; ++z)
    for (int y = c.y - radius; y <= c.y + radius; ++y) {
      int x0 = c.x - radius, x1 = c.x + radius;
      while (x0 <= x1 && !ball(x0, y, z)) ++x0;
      while (x1 >= x0 && !ball(x1, y, z)) --x1;
      if (x0 > x1) continue;
      const off_t at = (off_t(z) * d.ny + y) * d.nx + x0;
      if (::pwrite(fd, run.data(), std::size_t(x1 - x0 + 1), at) != ssize_t(x1 - x0 + 1))
        throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
    }
  if (::close(fd) != 0) throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<int> sizes{256, 512};
    std::vector<double> noises{0.0, 0.01, 0.05};
    std::vector<int> big{2048, 2048, 1040};
    int radius = 60;
    bool withBig = true;
    std::string dir;
    for (bench::Arguments args(argc, argv); args.next();) {
      const std::string& a = args.current();
      if (args.isHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (args.is("--sizes")) {
        sizes = bench::parseList<int>(args.value(), "size");
      } else if (args.is("--noise")) {
        noises = bench::parseList<double>(args.value(), "noise");
      } else if (args.is("--big")) {
        big = bench::parseList<int>(args.value(), "dimension");
        if (big.size() != 3) throw std::invalid_argument("--big needs NX,NY,NZ");
      } else if (args.is("--radius")) {
        radius = std::stoi(args.value());
      } else if (args.is("--no-big")) {
        withBig = false;
      } else if (!a.empty() && a[0] != '-' && dir.empty()) {
        dir = a;
      } else {
        args.unknown();
      }
    }
    if (dir.empty()) throw std::invalid_argument("no output directory (see --help)");
    fs::create_directories(dir);

    std::cout << "{\n  \"spheres\": [\n";
    bool first = true;
    for (int q : sizes)
      for (double p : noises) {
        const NoisyPhantom sphere = makeNoisySphere(q, p);
        const Surfel seed = protocolSeed(sphere);
        std::ostringstream name;
        name << "sphere_" << q << "_" << int(std::lround(p * 100)) << ".mha";
        const std::string path = (fs::path(dir) / name.str()).string();
        io::writeVolume(io::AnyVolume(sphere.image), path, false);
        std::cout << (first ? "" : ",\n") << "    {\"file\": \"" << path << "\", \"q\": " << q
                  << ", \"noise\": " << p << ", \"iso\": " << sphere.iso << ", \"seed\": \"" << seedText(seed)
                  << "\", \"seed_point\": " << pointText(seed) << "}";
        first = false;
      }
    std::cout << "\n  ]";
    if (withBig) {
      const Dims d{big[0], big[1], big[2]};
      const Voxel c{d.nx / 3, 2 * d.ny / 3, d.nz / 2};
      const Ball ball = Ball::ofRadius(c, radius);
      const std::string path = (fs::path(dir) / "big.raw").string();
      writeSparseBall(path, d, ball, radius, 200);
      std::cout << ",\n  \"big\": {\"file\": \"" << path << "\", \"dims\": [" << d.nx << ", " << d.ny << ", "
                << d.nz << "], \"iso\": 100, \"centre\": [" << c.x << ", " << c.y << ", " << c.z
                << "], \"radius\": " << radius << "}";
    }
    std::cout << "\n}\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_write_inputs: " << e.what() << "\n";
    return 1;
  }
}
