// focal._focal_ext: the nanobind layer under the focal Python package (python/focal/).
//
// The package's Python code checks shapes (naming the argument) and converts inputs once into
// the layout of the library's views: C-ordered float64 `n x 3` positions and normals, C-ordered
// int32 `m x 3` faces. This layer only accepts that layout (no implicit conversion here, so a
// second copy cannot happen by accident), maps the buffers into Eigen::Ref views without copying,
// releases the GIL around every computation and hands each result matrix to NumPy with a capsule
// that owns it (moved, never copied).
//
// One file per area, each with one bind_* function called here: meshes.cpp (curvature, focal
// meshes, checks, normals, files, analytic surfaces), render.cpp, image_space.cpp, tiles.cpp
// (focal/tiles for focal.distributed), streaming.cpp (focal.stream's PLY reader and tile grid).
// Nothing in src/ includes these files: the bindings are the top layer.

#include <nanobind/nanobind.h>

#include "focal/core/error.h"

namespace nb = nanobind;

namespace focal_python {
void bind_meshes(nb::module_& m);
void bind_render(nb::module_& m);
void bind_image_space(nb::module_& m);
void bind_tiles(nb::module_& m);
void bind_clouds(nb::module_& m);
void bind_streaming(nb::module_& m);
void bind_smoothing(nb::module_& m);
}  // namespace focal_python

namespace {

// The Python exception types (python/focal/_errors.py), set once by the package at import.
PyObject* invalid_input_error = nullptr;
PyObject* io_error = nullptr;
PyObject* device_error = nullptr;
PyObject* focal_error = nullptr;

void translate_errors(const std::exception_ptr& p, void*) {
  try {
    std::rethrow_exception(p);
  } catch (const focal::InvalidInput& e) {
    PyErr_SetString(invalid_input_error ? invalid_input_error : PyExc_ValueError, e.what());
  } catch (const focal::IoError& e) {
    PyErr_SetString(io_error ? io_error : PyExc_OSError, e.what());
  } catch (const focal::DeviceError& e) {
    PyErr_SetString(device_error ? device_error : PyExc_RuntimeError, e.what());
  } catch (const focal::Error& e) {
    PyErr_SetString(focal_error ? focal_error : PyExc_RuntimeError, e.what());
  }
}

}  // namespace


NB_MODULE(_focal_ext, m) {
  m.doc() = "focal's C++ library (the focal package wraps it; use that).";

  m.def("_set_error_types",
        [](nb::handle invalid, nb::handle io, nb::handle device, nb::handle base) {
          invalid_input_error = invalid.inc_ref().ptr();
          io_error = io.inc_ref().ptr();
          device_error = device.inc_ref().ptr();
          focal_error = base.inc_ref().ptr();
        });
  nb::register_exception_translator(&translate_errors);

  focal_python::bind_meshes(m);
  focal_python::bind_render(m);
  focal_python::bind_image_space(m);
  focal_python::bind_tiles(m);
  focal_python::bind_smoothing(m);
  focal_python::bind_clouds(m);
  focal_python::bind_streaming(m);
}
