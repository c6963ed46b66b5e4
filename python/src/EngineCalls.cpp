// The binding's shared helpers that need no template (EngineCalls.h).
#include "EngineCalls.h"

#include <regex>

namespace surftrack::binding {

/// The ScalarType of a numpy dtype; throws TypeError for anything but the ten types.
ScalarType scalarTypeOfDtype(const py::dtype& dtype) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  if (kind == 'u' || kind == 'b') {
    if (size == 1) return ScalarType::UInt8;
    if (size == 2) return ScalarType::UInt16;
    if (size == 4) return ScalarType::UInt32;
    if (size == 8) return ScalarType::UInt64;
  } else if (kind == 'i') {
    if (size == 1) return ScalarType::Int8;
    if (size == 2) return ScalarType::Int16;
    if (size == 4) return ScalarType::Int32;
    if (size == 8) return ScalarType::Int64;
  } else if (kind == 'f') {
    if (size == 4) return ScalarType::Float32;
    if (size == 8) return ScalarType::Float64;
  }
  throw py::type_error("unsupported volume dtype '" + py::cast<std::string>(py::str(py::handle(dtype))) +
                       "': expected bool, uint8/16/32/64, int8/16/32/64, float32 or float64");
}

/// The view of `volume` whose engine axes x, y, z are the array axes order[0..2], with its
/// geometry given in array axes.
VolumeView viewOfArray(const py::array& volume, std::array<int, 3> order, std::array<double, 3> spacing,
                       std::array<double, 3> origin, std::array<std::array<double, 3>, 3> direction) {
  if (volume.ndim() != 3)
    throw py::value_error("the volume must be 3-D, not " + std::to_string(volume.ndim()) + "-D");
  const ScalarType type = scalarTypeOfDtype(volume.dtype());
  VolumeView view;
  view.data = volume.data();
  view.type = type;
  for (int e = 0; e < 3; ++e) {
    const int a = order[e];
    if (volume.shape(a) == 0) throw py::value_error("the volume is empty (a dimension is 0)");
    if (volume.shape(a) > kMaxDimension)
      throw py::value_error("a volume dimension exceeds " + std::to_string(kMaxDimension));
    if (volume.strides(a) % py::ssize_t(sizeOf(type)) != 0)
      throw py::value_error("the volume's strides are not multiples of its item size");
    (e == 0 ? view.dims.nx : e == 1 ? view.dims.ny : view.dims.nz) = int(volume.shape(a));
    view.strides[e] = volume.strides(a) / py::ssize_t(sizeOf(type));
    view.geometry.spacing[e] = spacing[a];
    for (int k = 0; k < 3; ++k) view.geometry.direction[k][e] = direction[k][a];
  }
  view.geometry.origin = origin;
  return view;
}

namespace {

/// Applies `format` to every match of `re` in `text`.
template <class Format>
std::string replaceMatches(const std::string& text, const std::regex& re, Format&& format) {
  std::string out;
  auto last = text.cbegin();
  for (std::sregex_iterator it(text.begin(), text.end(), re), end; it != end; ++it) {
    out.append(last, (*it)[0].first);
    out += format(*it);
    last = (*it)[0].second;
  }
  out.append(last, text.cend());
  return out;
}

}  // namespace

/// An engine message with its voxel coordinates in the caller's axes: the engine's x, y, z are
/// the array axes order[0..2] (surftrack/__init__.py), and its messages print a voxel as
/// "(x,y,z)" after "voxel ", "voxel index " or, in a surfel, "c=" and "d=", and a domain as
/// "[0,nx)x[0,ny)x[0,nz)" (core/src/Extract.cpp, core/src/Labels.cpp). Physical points are in
/// the caller's frame already and are left alone.
std::string inArrayAxes(const std::string& message, std::array<int, 3> order) {
  static const std::regex voxel(R"re((voxel |voxel index |c=|d=)\(([^,()]+),([^,()]+),([^,()]+)\))re");
  static const std::regex domain(R"re(\[0,(\d+)\)x\[0,(\d+)\)x\[0,(\d+)\))re");
  auto permuted = [&](const std::smatch& m, int first) {
    std::array<std::string, 3> a;
    for (int e = 0; e < 3; ++e) a[std::size_t(order[e])] = m[first + e].str();
    return a;
  };
  const std::string voxels = replaceMatches(message, voxel, [&](const std::smatch& m) {
    const auto a = permuted(m, 2);
    return m[1].str() + "(" + a[0] + "," + a[1] + "," + a[2] + ")";
  });
  return replaceMatches(voxels, domain, [&](const std::smatch& m) {
    const auto a = permuted(m, 1);
    return "[0," + a[0] + ")x[0," + a[1] + ")x[0," + a[2] + ")";
  });
}

}  // namespace surftrack::binding
