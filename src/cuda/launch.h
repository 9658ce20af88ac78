#pragma once
// The CUDA backend's entry points in plain data (no Eigen, no C++20 headers), so that the .cu
// files need neither: nvcc builds them as C++17 (src/CMakeLists.txt) while focal's public
// headers use C++20, and Eigen in nvcc code is slow to compile and warns. The public functions
// (estimate_image_curvature_cuda, triangle_curvature_cuda) validate their input on the host in
// C++ and call these; the .cu files beside them define them, the *_cpu_only.cpp stand-ins throw
// DeviceError.

#include <cstdint>
#include <vector>

#include "focal/cuda/image_state.h"
#include "kernels/pixel.h"

namespace focal::detail {

/// Runs the image-space kernels on `device`: host G-buffer in, host fields out (every pixel
/// written), through a state of its own with pageable transfers. `image` must have width,
/// height >= 1; window >= 0.
/// \throw DeviceError on any CUDA error, or in a build without the CUDA backend.
void image_curvature_on_device(const image_kernel::ImageView& image, float discontinuity_ratio,
                               int window, const image_kernel::ImageFields& out, int device);

/// A state (ImageDeviceState, focal/cuda/image_state.h) for width x height frames on
/// `device`: the G-buffer's and the fields' device buffers, the window's operators (window > 0),
/// a stream and, where `pinned`, page-locked host buffers the transfers go through. Every call
/// below makes the state's device current and restores the caller's.
/// \throw DeviceError on any CUDA error (out of memory), or in a build without the CUDA backend.
[[nodiscard]] ImageDeviceStatePtr make_image_device_state(int width, int height, int window,
                                                          bool pinned, int device);
/// Queues the copy of a frame of the state's size to the device.
void upload_frame(ImageDeviceState& state, const image_kernel::ImageView& image);
/// Runs the kernels on the frame on the device and waits for them.
void run_frame(ImageDeviceState& state, float discontinuity_ratio, int window);
/// Copies the fields of the last run to `out` (host arrays of the state's size) and waits.
void download_frame(ImageDeviceState& state, const image_kernel::ImageFields& out);

/// A mesh packed for kernels/triangle.h: contiguous V, N (double) and F, classification
/// thresholds in float.
struct TriangleInput {
  std::vector<double> V, N;
  std::vector<std::int32_t> F;
  int faces = 0;
  float zero_tolerance = 0.0f;
  float umbilic_tolerance = 0.0f;
};

/// Runs triangle_kernel::triangle_face for every face on `device` (faces >= 1); `values` gets
/// field::count x faces floats, `classes` faces codes.
/// \throw DeviceError on any CUDA error, or in a build without the CUDA backend.
void triangle_faces_on_device(const TriangleInput& in, std::vector<float>& values,
                              std::vector<std::uint8_t>& classes, int device);

}  // namespace focal::detail
