#pragma once
/// \file cuda_curvature.h
/// The mesh estimators on a CUDA device (float32 on the device, results as on the CPU).
///
/// CONTRACT DRAFT (issue 7): the CUDA work finalises the documentation.

#include "focal/curvature.h"
#include "focal/triangle_curvature.h"

namespace focal {

/// The per-vertex closed-form two-slit fit (Method::vertex, Solver::closed_form) on a device.
/// \throw DeviceError without the CUDA backend or a device; InvalidInput as estimate_curvature.
[[nodiscard]] CurvatureResult estimate_curvature_cuda(PositionsRef V, FacesRef F, NormalsRef N,
                                                      const CurvatureOptions& options = {},
                                                      int device = 0);

/// The per-triangle characteristic equation on a device.
/// \throw DeviceError without the CUDA backend or a device; InvalidInput as triangle_curvature.
[[nodiscard]] TriangleCurvatureResult triangle_curvature_cuda(PositionsRef V, FacesRef F,
                                                              NormalsRef N,
                                                              const CurvatureOptions& options = {},
                                                              int device = 0);

}  // namespace focal
