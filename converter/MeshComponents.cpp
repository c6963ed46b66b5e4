#include "MeshComponents.h"

namespace surftrack {

std::vector<std::uint32_t> triangleComponents(std::size_t vertexCount,
                                              const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                              std::size_t& count) {
  // Disjoint sets linked by the smaller root, with path halving: parent[v] <= v always, and a
  // set's root is its smallest vertex.
  std::vector<std::uint32_t> parent(vertexCount);
  for (std::uint32_t v = 0; v < vertexCount; ++v) parent[v] = v;
  std::uint32_t* p = parent.data();
  auto find = [p](std::uint32_t v) {
    while (p[v] != v) {
      p[v] = p[p[v]];
      v = p[v];
    }
    return v;
  };
  auto link = [p](std::uint32_t a, std::uint32_t b) {  // two roots; the smaller one stays
    if (a < b) {
      p[b] = a;
      return a;
    }
    p[a] = b;
    return b;
  };
  for (const auto& t : triangles) {
    const std::uint32_t a = find(t[0]), b = find(t[1]);
    const std::uint32_t r = a == b ? a : link(a, b);
    const std::uint32_t c = find(t[2]);
    if (c != r) link(r, c);
  }
  // Numbers in the order of the smallest vertices, in place: when v is reached, parent[v] = u
  // <= v is v itself (a root, a new number) or a vertex of the same set already numbered.
  count = 0;
  for (std::uint32_t v = 0; v < vertexCount; ++v) p[v] = p[v] == v ? std::uint32_t(count++) : p[p[v]];
  return parent;
}

}  // namespace surftrack
