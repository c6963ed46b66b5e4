// The front-door example of docs/api.md: a gray volume the caller owns (here a std::vector),
// seen without a copy, one boundary extracted from a physical seed point, its figures printed
// and the mesh written as PLY. Only <surftrack/...> headers: it builds in the source tree and
// against the installed package (docs/example_project, run by ctest).
//
//   example_extract [output.ply]
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <vector>

#include <surftrack/Extract.h>

int main(int argc, char** argv) try {
  const std::string output = argc > 1 ? argv[1] : "ball.ply";

  // A 64^3 uint16 volume with 0.5 mm voxels: a ball of radius 12 voxels, f = 1000 inside.
  const int n = 64;
  std::vector<std::uint16_t> voxels(std::size_t(n) * n * n, 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r = std::sqrt((x - 31.5) * (x - 31.5) + (y - 31.5) * (y - 31.5) + (z - 31.5) * (z - 31.5));
        voxels[(std::size_t(z) * n + y) * n + x] = std::uint16_t(std::clamp(1000.0 * (12.5 - r), 0.0, 1000.0));
      }
  surftrack::ImageGeometry geometry;
  geometry.spacing = {0.5, 0.5, 0.5};
  geometry.origin = {-16, -16, -16};

  surftrack::ExtractOptions options;
  options.selection = surftrack::Selection::threshold(500);  // f > 500
  options.seed = surftrack::SeedRule::point({0, 0, 0});      // the ball's centre, in mm
  options.pair = surftrack::AdjacencyPair::k26_6;
  const surftrack::Surface surface =
      surftrack::extract(surftrack::VolumeView::of(voxels.data(), {n, n, n}, geometry), options);

  const surftrack::ComponentFigures& ball = surface.components.at(0);
  std::cout << surface.vertexCount() << " vertices, " << surface.triangleCount() << " triangles, Euler "
            << ball.euler << ", genus " << ball.genus() << ", area " << ball.area << " mm2, volume "
            << ball.volume << " mm3\n";
  surftrack::writeSurface(surface, output);
  // A closed sphere: Euler characteristic 2; the volume is within 5 % of (4/3) pi (6 mm)^3.
  const double expected = 4.0 / 3.0 * M_PI * 6.0 * 6.0 * 6.0;
  return ball.euler == 2 && std::abs(ball.volume - expected) < 0.05 * expected ? 0 : 1;
} catch (const surftrack::InvalidInput& e) {
  std::cerr << "bad input: " << e.what() << "\n";
  return 2;
}
