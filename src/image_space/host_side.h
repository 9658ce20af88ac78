#pragma once
// What the CPU reference (image_space.cpp) and the CUDA backend (src/cuda/image_space.cu) share
// on the host: input validation and the result's allocation, so that both reject the same input
// with the same message and return the same shapes.

#include <cstddef>

#include "focal/image_space/image_space.h"
#include "kernels/pixel.h"

namespace focal::detail {

/// \throw InvalidInput naming `what` when sizes disagree or an option is out of range.
void validate_image_input(const GBuffer& gbuffer, const ImageSpaceOptions& options,
                          const char* what);

/// \throw InvalidInput naming `what` when an option is out of range.
void validate_image_options(const ImageSpaceOptions& options, const char* what);

/// The most pixels of a G-buffer: the kernels index 3 floats a pixel with an int.
inline constexpr std::size_t kMaxPixels = static_cast<std::size_t>(2147483647 / 3);

/// Every field sized for width x height, contents unspecified (each pixel is written once).
[[nodiscard]] ImageCurvature allocate_image_curvature(int width, int height);

/// Whether every field of `r` has the size of a width x height result.
[[nodiscard]] bool has_image_size(const ImageCurvature& r, int width, int height);

/// The G-buffer's host arrays as a kernel view.
[[nodiscard]] inline image_kernel::ImageView view_of(const GBuffer& g) {
  return {g.width, g.height, g.position.data(), g.normal.data(), g.mask.data()};
}

/// The result's host arrays as kernel output fields.
[[nodiscard]] inline image_kernel::ImageFields fields_of(ImageCurvature& r) {
  return {r.k1.data(),           r.k2.data(), r.H.data(),  r.K.data(),    r.focal_depth1.data(),
          r.focal_depth2.data(), r.d1.data(), r.d2.data(), r.valid.data()};
}

}  // namespace focal::detail
