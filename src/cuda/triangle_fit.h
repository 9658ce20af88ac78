#pragma once
// Host side of the float per-triangle estimator, shared by triangle_curvature_cuda (defined in
// cuda/triangle_fit.cpp, its kernel in src/cuda/triangle_fit.cu) and its CPU emulation: inputs
// checked and packed for kernels/triangle.h, outputs unpacked into a TriangleCurvatureResult.

#include <cstdint>
#include <vector>

#include "cuda/launch.h"
#include "focal/curvature/triangle_curvature.h"
#include "kernels/triangle.h"

namespace focal::detail {

/// \throw InvalidInput as triangle_curvature (N rows differ from V's, F indexes outside V),
///        naming `what`.
[[nodiscard]] TriangleInput triangle_input(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options, const char* what);

/// The result from triangle_kernel's outputs (field::count x faces floats, faces classes).
[[nodiscard]] TriangleCurvatureResult triangle_result(const std::vector<float>& values,
                                                      const std::vector<std::uint8_t>& classes,
                                                      int faces);

/// triangle_curvature_cuda's computation on the CPU, serially: the same per-face code in float.
/// For tests, and as the reference the device is compared with.
[[nodiscard]] TriangleCurvatureResult triangle_curvature_float(
    PositionsRef V, FacesRef F, NormalsRef N, const CurvatureOptions& options = {});

}  // namespace focal::detail
