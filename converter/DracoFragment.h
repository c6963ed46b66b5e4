// One fragment of Neuroglancer's multi-resolution mesh format, Draco-encoded (docs/cli.md,
// "Neuroglancer output"): a triangle mesh whose position attribute holds the quantized integer
// coordinates themselves (3 x int32, no Draco quantization: Neuroglancer reads the integers
// as they are stored, the format spec says Draco's own quantization is not supported).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace surftrack {

/// The Draco bytes of the mesh with integer vertex positions `positions` and triangles
/// `triangles` (indices into positions, orientation kept). Edgebreaker connectivity coding.
/// \throw std::runtime_error if Draco refuses the mesh.
std::string encodeDracoFragment(const std::vector<std::array<std::int32_t, 3>>& positions,
                                const std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace surftrack
