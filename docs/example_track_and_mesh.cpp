// The example of docs/api.md: a gray sphere, thresholded, tracked from one seed surfel and
// converted to a closed triangle mesh with the iso-value boundary mapping, written as PLY.
//
//   example_track_and_mesh [output.ply]
//
// Built with the project (target example_track_and_mesh) and run by ctest.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>

#include "FindSeed.h"       // seedAlongRay
#include "MeshIO.h"         // writeMesh
#include "SurfaceMesh.h"    // toMesh, IsoValueMapping, SurfaceMesh
#include "TrackComponent.h" // trackComponent

int main(int argc, char** argv) {
  using namespace surftrack;
  const std::string output = argc > 1 ? argv[1] : "sphere.ply";

  // 1. A gray image: a sphere of radius R = 0.4 q, f = 128 + 20 (R - |x - c|) clamped to 0..255,
  //    with voxels of 0.5 mm.
  const int q = 48;
  const double c = (q - 1) / 2.0, R = 0.4 * q;
  ImageGeometry geometry;
  geometry.spacing = {0.5, 0.5, 0.5};
  DenseImage<std::uint8_t> gray({q, q, q}, 0, geometry);
  for (int z = 0; z < q; ++z)
    for (int y = 0; y < q; ++y)
      for (int x = 0; x < q; ++x) {
        const double r = std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
        gray.at(x, y, z) = std::uint8_t(std::clamp(std::round(128 + 20 * (R - r)), 0.0, 255.0));
      }

  // 2. The binary image f > s (paper §3.1); nothing is copied.
  const double isoValue = 127.5;
  const ThresholdImage<std::uint8_t> image(gray, isoValue);

  // 3. A seed: the first boundary surfel on the +x ray from the centre.
  const std::optional<Surfel> seed = seedAlongRay(image, Voxel{q / 2, q / 2, q / 2}, directionOf(0, +1));
  if (!seed) {
    std::cerr << "no boundary surfel on the ray\n";
    return 1;
  }

  // 4. Track the 26-6-boundary through the seed: its surface graph G(Sigma, beta) (§5.2).
  const SurfaceGraph graph = trackComponent(image, *seed, AdjacencyPair::k26_6);

  // 5. Loops -> triangles (§5.2), vertices placed by the iso-value mapping (§3.1), then in
  //    physical coordinates.
  const SurfaceMesh mesh = toMesh(graph, image, IsoValueMapping(image), gray.geometry());

  // 6. Write a binary PLY (the format follows the extension).
  writeMesh(mesh, output);

  // The result is a closed surface of genus 0: V - E + F = 2, no boundary half-edge.
  const long euler = long(mesh.n_vertices()) - long(mesh.n_edges()) + long(mesh.n_faces());
  bool closed = true;
  for (auto heh : mesh.halfedges()) closed = closed && !mesh.is_boundary(heh);
  std::cout << graph.surfelCount() << " surfels, " << mesh.n_faces() << " triangles, Euler "
            << euler << " -> " << output << '\n';
  return closed && euler == 2 ? 0 : 1;
}
