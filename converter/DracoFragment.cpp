// Draco encoding of one fragment (DracoFragment.h), with Debian's libdraco.
#include "DracoFragment.h"

#include <stdexcept>

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

namespace surftrack {

std::string encodeDracoFragment(const std::vector<std::array<std::int32_t, 3>>& positions,
                                const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  draco::Mesh mesh;
  mesh.set_num_points(std::uint32_t(positions.size()));
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_INT32, false, sizeof(std::int32_t) * 3, 0);
  const int id = mesh.AddAttribute(position, true, std::uint32_t(positions.size()));
  draco::PointAttribute* attribute = mesh.attribute(id);
  for (std::size_t i = 0; i < positions.size(); ++i)
    attribute->SetAttributeValue(draco::AttributeValueIndex(std::uint32_t(i)), positions[i].data());
  mesh.SetNumFaces(triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    mesh.SetFace(draco::FaceIndex(std::uint32_t(f)),
                 {draco::PointIndex(t[0]), draco::PointIndex(t[1]), draco::PointIndex(t[2])});
  }
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  encoder.SetSpeedOptions(5, 5);  // the default balance of size and speed
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!status.ok()) throw std::runtime_error(std::string("Draco cannot encode a mesh fragment: ") + status.error_msg());
  return std::string(buffer.data(), buffer.size());
}

}  // namespace surftrack
