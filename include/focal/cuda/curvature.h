#pragma once
/// \file cuda_curvature.h
/// The mesh estimators on a CUDA device (float32 on the device, results as on the CPU; the CPU
/// functions of curvature.h and triangle_curvature.h stay the reference). docs/GPU.md.
///
/// Available when the library was built with the CUDA backend (focal::cuda_built()); otherwise
/// every function here throws DeviceError saying so, never falling back to the CPU silently.
/// Calls are synchronous and leave the calling thread's current CUDA device as it was.

#include <memory>

#include "focal/curvature/curvature.h"
#include "focal/curvature/triangle_curvature.h"

namespace focal {

/// estimate_curvature's per-vertex closed-form two-slit fit (paper section 5; Method::vertex,
/// Solver::closed_form, 1-ring or k-ring, uniform or Gaussian weights) with one GPU thread per
/// vertex. Neighbourhoods are built on the host; positions and normals travel as float pairs
/// (hi + lo) and the fit runs in float32.
///
/// Same shapes, conventions, classes, NaN rules and ray counts as estimate_curvature. Accuracy
/// against it (double): |dk| <= 1e-5 max(|k1|, |k2|) at every vertex, and relative error under
/// 1e-4 where |k| x mean edge length >= 1e-2 (measured: below 4e-6). Classes can differ only
/// where the CPU's k1, k2 lie within that error of a class threshold, and where the normal
/// equations are too ill conditioned for float (det / (trace/3)^3 <= 1e-4, against 1e-12 on
/// the CPU): such vertices are `undefined` here rather than given an unreliable number.
/// \param V #V x 3 positions. \param F #F x 3 triangles. \param N #V x 3 outward normals (as
///        estimate_curvature: normalised here; zero or non-finite rows make their vertex
///        `undefined`). \param device index into cuda_devices().
/// \throw DeviceError without the CUDA backend, without a usable device, for an index out of
///        range or when a CUDA call fails (out of memory, launch failure), naming the call.
/// \throw InvalidInput as estimate_curvature, and for Method::triangle (use
///        triangle_curvature_cuda), Solver::levenberg_marquardt (CPU only) or a mean edge length
///        outside 1e-30 .. 1e30 (beyond float32's exponent range).
[[nodiscard]] CurvatureResult estimate_curvature_cuda(PositionsRef V, FacesRef F, NormalsRef N,
                                                      const CurvatureOptions& options = {},
                                                      int device = 0);

/// estimate_curvature_cuda for a mesh whose normals change between estimates (a normal filter
/// or an optimisation in a loop, normals from another tool): the vertex records, the
/// neighbourhoods and the output buffers are built and uploaded once, by the constructor; each
/// set_normals rewrites and uploads only the vertex records (positions and normals, 48 bytes a
/// vertex), and each estimate launches the fit and downloads the fields.
///
/// Each estimate gives the bits of estimate_curvature_cuda(V, F, N, options, device) with the
/// current normals: the same kernel on the same data. Calls are synchronous and leave the
/// calling thread's current CUDA device as it was; a context is not thread-safe.
class CurvatureCudaContext {
 public:
  /// \throw as estimate_curvature_cuda.
  CurvatureCudaContext(PositionsRef V, FacesRef F, NormalsRef N,
                       const CurvatureOptions& options = {}, int device = 0);
  ~CurvatureCudaContext();
  CurvatureCudaContext(CurvatureCudaContext&&) noexcept;
  CurvatureCudaContext& operator=(CurvatureCudaContext&&) noexcept;

  /// New normals, #V x 3 (zero or non-finite rows make their vertex `undefined`).
  /// \throw InvalidInput on a wrong row count; DeviceError on a CUDA error.
  void set_normals(NormalsRef N);
  /// The fit with the current normals. \throw DeviceError on a CUDA error.
  [[nodiscard]] CurvatureResult estimate();
  [[nodiscard]] int vertex_count() const;

 private:
  struct Resident;  ///< the device's copy (src/cuda/vertex_fit.cu)
  std::unique_ptr<Resident> resident_;
};

/// The per-triangle characteristic equation on a device.
/// \throw DeviceError without the CUDA backend or a device; InvalidInput as triangle_curvature.
[[nodiscard]] TriangleCurvatureResult triangle_curvature_cuda(PositionsRef V, FacesRef F,
                                                              NormalsRef N,
                                                              const CurvatureOptions& options = {},
                                                              int device = 0);

}  // namespace focal
