// Connected components of a triangle mesh through shared vertices, with Boost's disjoint sets:
// the one union-find of the project. On the mesh of a whole image (the scanning method) the
// components are exactly the kappa-lambda-boundaries (Proposition 39).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace surftrack {

/// The component of each of `vertexCount` vertices joined through `triangles`, numbered 0, 1,
/// ... in the order of their smallest vertex; `count` receives the number of components.
std::vector<std::uint32_t> triangleComponents(std::size_t vertexCount,
                                              const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                              std::size_t& count);

}  // namespace surftrack

namespace surftrack {

/// The same union-find over `elementCount` elements joined in pairs: the component of each,
/// numbered in the order of their smallest element (the partial components of a label joined
/// through shared border keys, docs/theory.md "A label larger than one merge").
std::vector<std::uint32_t> joinedComponents(std::size_t elementCount,
                                            const std::vector<std::array<std::uint32_t, 2>>& joins,
                                            std::size_t& count);

}  // namespace surftrack
