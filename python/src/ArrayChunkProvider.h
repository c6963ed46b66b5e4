// A chunked array that only Python can read (a dask array, an h5py dataset, a zarr array on a
// store that is not a directory, anything with .shape, .dtype and numpy slicing) as the core's
// ChunkProvider (ChunkedSource.h): each chunk is one slice `array[z0:z1, y0:y1, x0:x1]`,
// taken under the GIL. The engine then reads it as it reads a store on disk, through the same
// bounded cache, so a seeded extraction slices only the chunks near its surface
// (docs/python.md, "Chunked stores").
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include "ChunkedSource.h"
#include "ReadVolume.h"  // io/: ReadError

namespace surftrack::python {

namespace py = pybind11;

class ArrayChunkProvider final : public ChunkProvider {
 public:
  /// `array` is indexed [z, y, x] (the engine's x is its last axis); `layout` in engine axes;
  /// `dtype` the native numpy type of layout.type that each slice is converted to.
  ArrayChunkProvider(py::object array, ChunkLayout layout, py::dtype dtype)
      : array_(std::move(array)), layout_(std::move(layout)), dtype_(std::move(dtype)) {}

  ~ArrayChunkProvider() override {
    py::gil_scoped_acquire gil;  // (the last reference may go on an engine thread)
    array_ = py::object();
    dtype_ = py::dtype();
  }

  const ChunkLayout& layout() const override { return layout_; }

  std::uint64_t read(Voxel index, void* out) const override {
    const Dims e = layout_.extentOf(index);
    const Voxel lo{index.x * layout_.chunk.nx, index.y * layout_.chunk.ny, index.z * layout_.chunk.nz};
    const std::string name = "chunk [" + std::to_string(lo.z) + ":" + std::to_string(lo.z + e.nz) + ", " +
                             std::to_string(lo.y) + ":" + std::to_string(lo.y + e.ny) + ", " +
                             std::to_string(lo.x) + ":" + std::to_string(lo.x + e.nx) + "]";
    py::gil_scoped_acquire gil;
    try {
      const py::tuple box = py::make_tuple(py::slice(lo.z, lo.z + e.nz, 1), py::slice(lo.y, lo.y + e.ny, 1),
                                           py::slice(lo.x, lo.x + e.nx, 1));
      // C order [z, y, x] in the engine's dtype (native; bool as uint8): x fastest, as the
      // cache keeps it.
      const py::array got = py::module_::import("numpy").attr("ascontiguousarray")(array_[box], dtype_);
      if (got.ndim() != 3 || got.shape(0) != e.nz || got.shape(1) != e.ny || got.shape(2) != e.nx)
        throw io::ReadError("the array's " + name + " came back with shape " +
                            std::string(py::str(py::tuple(got.attr("shape")))) + ", not (" +
                            std::to_string(e.nz) + ", " + std::to_string(e.ny) + ", " + std::to_string(e.nx) + ")");
      const std::size_t bytes = std::size_t(e.nx) * std::size_t(e.ny) * std::size_t(e.nz) * sizeOf(layout_.type);
      std::memcpy(out, got.data(), bytes);
      return bytes;
    } catch (py::error_already_set& err) {
      // One line, as a store's chunk that cannot be decoded; the Python exception is not kept
      // (it would outlive the GIL on an engine thread).
      const std::string what = err.what();
      throw io::ReadError("reading the array's " + name + ": " + what.substr(0, std::min(what.find('\n'), std::size_t(400))));
    }
  }

 private:
  py::object array_;
  ChunkLayout layout_;
  py::dtype dtype_;
};

}  // namespace surftrack::python
