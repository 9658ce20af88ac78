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
#include <nanobind/stl/string.h>

#include <cstdint>
#include <cstring>

#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/io/interrupted_writes.h"

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

/// Raises `type` with `message`, whose bytes need not be UTF-8 (a file name that is not keeps
/// its bytes as \x escapes rather than failing the raise).
void raise(PyObject* type, const char* message) {
  PyObject* text = PyUnicode_DecodeUTF8(message, static_cast<Py_ssize_t>(std::strlen(message)),
                                        "backslashreplace");
  if (text == nullptr) return;  // the decoding error is set instead
  PyErr_SetObject(type, text);
  Py_DECREF(text);
}

void translate_errors(const std::exception_ptr& p, void*) {
  try {
    std::rethrow_exception(p);
  } catch (const focal::InvalidInput& e) {
    raise(invalid_input_error ? invalid_input_error : PyExc_ValueError, e.what());
  } catch (const focal::IoError& e) {
    raise(io_error ? io_error : PyExc_OSError, e.what());
  } catch (const focal::DeviceError& e) {
    raise(device_error ? device_error : PyExc_RuntimeError, e.what());
  } catch (const focal::Error& e) {
    raise(focal_error ? focal_error : PyExc_RuntimeError, e.what());
  } catch (const nb::cast_error&) {
    // An option of the wrong type or out of the C++ type's range that the package let through
    // (it checks every one it knows): a bad input, not an internal error.
    raise(invalid_input_error ? invalid_input_error : PyExc_ValueError,
          "an option's value has the wrong type or does not fit the library's integer type");
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
  // A process killed by SIGTERM or SIGHUP while focal writes a file leaves no temporary file
  // (signals still at their default action only: Python's SIGINT handler, which raises
  // KeyboardInterrupt once the call returns, and a handler of the program's are kept).
  focal::remove_temporary_files_on_signals();
  // The one thread rule (focal/core/execution.h) for every threads= of the package.
  m.def("_resolve_threads", [](std::int64_t requested) {
    const focal::ThreadRequest r = focal::resolve_threads(requested);
    return nb::make_tuple(r.threads, r.warning);
  });

  focal_python::bind_meshes(m);
  focal_python::bind_render(m);
  focal_python::bind_image_space(m);
  focal_python::bind_tiles(m);
  focal_python::bind_smoothing(m);
  focal_python::bind_clouds(m);
  focal_python::bind_streaming(m);
}
