// writeSurface: a Surface through the converter's manifold check and OpenMesh's writers;
// writeLabelSurfaces: label surfaces as one PLY with label properties, through the same writer.
#include <bit>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "Errors.h"
#include "Extract.h"
#include "Labels.h"
#include "MeshIO.h"
#include "SelectionValue.h"
#include "SurfaceMesh.h"

namespace surftrack {

void writeSurface(const Surface& surface, const std::string& path, bool binary) {
  // No half-edge mesh is needed to write a file: the triangles are checked as toSurfaceMesh
  // would check them, then written from the list (converter/MeshIO.h).
  try {
    requireClosedOrientedManifold(surface.vertices.size(), surface.triangles);
  } catch (const std::invalid_argument& e) {  // a vertex index out of range
    throw InvalidInput(e.what());
  } catch (const std::logic_error& e) {  // not a closed oriented manifold: an engine bug
    throw InternalError(e.what());
  }
  try {
    writeTriangles(surface.vertices, surface.triangles, path, binary);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  }
}

namespace {

template <class T>
void put(std::ofstream& out, T value) {
  static_assert(std::endian::native == std::endian::little, "the PLY writer assumes a little-endian host");
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

/// A label as the PLY int property (labels beyond int32 do not fit it).
std::int32_t plyLabel(double label) {
  if (!(label >= std::numeric_limits<std::int32_t>::min() && label <= std::numeric_limits<std::int32_t>::max()))
    throw InvalidInput("label " + numberText(label) + " does not fit the PLY int label property");
  return std::int32_t(label);
}

}  // namespace

void writeLabelSurfaces(const std::vector<LabelSurface>& surfaces, const std::string& path, bool binary) {
  std::size_t vertices = 0, faces = 0;
  for (const LabelSurface& ls : surfaces) {
    plyLabel(ls.label);
    vertices += ls.surface.vertices.size();
    faces += ls.surface.triangles.size();
  }
  if (vertices > std::numeric_limits<std::uint32_t>::max())
    throw InvalidInput("cannot write '" + path + "': more than 2^32 - 1 vertices in one PLY");
  writeFileAtomically(path, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
        << "comment surftrack label surfaces: one closed surface per label\n"
        << "element vertex " << vertices << "\nproperty double x\nproperty double y\nproperty double z\n"
        << "property int label\nelement face " << faces << "\nproperty list uchar uint vertex_indices\n"
        << "property int label\nend_header\n";
    out.precision(17);
    for (const LabelSurface& ls : surfaces) {
      const std::int32_t label = plyLabel(ls.label);
      for (const auto& p : ls.surface.vertices) {
        if (binary) {
          put(out, p[0]), put(out, p[1]), put(out, p[2]), put(out, label);
        } else {
          out << p[0] << ' ' << p[1] << ' ' << p[2] << ' ' << label << '\n';
        }
      }
    }
    std::uint32_t offset = 0;
    for (const LabelSurface& ls : surfaces) {
      const std::int32_t label = plyLabel(ls.label);
      for (const auto& t : ls.surface.triangles) {
        if (binary) {
          put(out, std::uint8_t(3)), put(out, t[0] + offset), put(out, t[1] + offset), put(out, t[2] + offset);
          put(out, label);
        } else {
          out << "3 " << t[0] + offset << ' ' << t[1] + offset << ' ' << t[2] + offset << ' ' << label << '\n';
        }
      }
      offset += std::uint32_t(ls.surface.vertices.size());
    }
    out.close();
    return bool(out);
  });
}

}  // namespace surftrack
