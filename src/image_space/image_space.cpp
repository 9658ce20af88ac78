// The image-space estimator: the CPU reference (the per-pixel functions of kernels/pixel.h in a
// parallel loop over pixels) and the CUDA entry point's host side (validation, allocation; the
// kernels are in src/cuda/image_space.cu).
#include "focal/image_space/image_space.h"

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "cuda/launch.h"
#include "focal/cuda/device.h"
#include "focal/core/error.h"
#include "image_space/detail.h"
#include "core/parallel.h"

namespace focal {
namespace detail {

namespace {

constexpr int kMaxWindow = 16;

void check_size(std::size_t actual, std::size_t expected, const char* array, const char* what,
                const GBuffer& g) {
  if (actual != expected) {
    throw InvalidInput(std::string(what) + ": G-buffer " + array + " has " +
                       std::to_string(actual) + " values, expected " + std::to_string(expected) +
                       " for " + std::to_string(g.width) + " x " + std::to_string(g.height) +
                       " pixels");
  }
}

}  // namespace

void validate_image_input(const GBuffer& g, const ImageSpaceOptions& options, const char* what) {
  if (g.width < 0 || g.height < 0) {
    throw InvalidInput(std::string(what) + ": G-buffer size " + std::to_string(g.width) + " x " +
                       std::to_string(g.height) + " is negative");
  }
  const std::size_t pixels = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  if (pixels > static_cast<std::size_t>(std::numeric_limits<int>::max() / 3)) {
    throw InvalidInput(std::string(what) + ": G-buffer of " + std::to_string(pixels) +
                       " pixels is too large (at most " +
                       std::to_string(std::numeric_limits<int>::max() / 3) + ")");
  }
  check_size(g.position.size(), 3 * pixels, "position", what, g);
  check_size(g.normal.size(), 3 * pixels, "normal", what, g);
  check_size(g.mask.size(), pixels, "mask", what, g);
  // NaN fails the comparison too.
  if (!(options.discontinuity_ratio > 1.0)) {
    throw InvalidInput(std::string(what) +
                       ": discontinuity_ratio must be > 1 (infinity disables "
                       "the test), got " +
                       std::to_string(options.discontinuity_ratio));
  }
  if (options.window < 0 || options.window > kMaxWindow) {
    throw InvalidInput(std::string(what) + ": window must be in [0, " + std::to_string(kMaxWindow) +
                       "], got " + std::to_string(options.window));
  }
}

ImageCurvature allocate_image_curvature(int width, int height) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  ImageCurvature r;
  r.width = width;
  r.height = height;
  for (std::vector<float>* f : {&r.k1, &r.k2, &r.H, &r.K, &r.focal_depth1, &r.focal_depth2}) {
    f->resize(n);
  }
  r.d1.resize(3 * n);
  r.d2.resize(3 * n);
  r.valid.resize(n);
  return r;
}

}  // namespace detail

ImageCurvature estimate_image_curvature(const GBuffer& gbuffer, const ImageSpaceOptions& options) {
  detail::validate_image_input(gbuffer, options, "estimate_image_curvature");
  ImageCurvature result = detail::allocate_image_curvature(gbuffer.width, gbuffer.height);
  const image_kernel::ImageView view = detail::view_of(gbuffer);
  const image_kernel::ImageFields out = detail::fields_of(result);
  const std::int64_t pixels = static_cast<std::int64_t>(gbuffer.width) * gbuffer.height;
  const int width = gbuffer.width;
  // Converted once, as the CUDA backend does, so that both see the same float ratio.
  const float ratio = static_cast<float>(options.discontinuity_ratio);
  if (options.window == 0) {
    detail::parallel_for(pixels, options.threads, [&](std::int64_t i) {
      const int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
      image_kernel::store_pixel(out, static_cast<int>(i),
                                image_kernel::pixel_result(view, x, y, ratio));
    });
    return result;
  }
  std::vector<image_kernel::PixelOperator> ops(static_cast<std::size_t>(pixels));
  detail::parallel_for(pixels, options.threads, [&](std::int64_t i) {
    ops[static_cast<std::size_t>(i)] = image_kernel::pixel_operator(
        view, static_cast<int>(i % width), static_cast<int>(i / width), ratio);
  });
  detail::parallel_for(pixels, options.threads, [&](std::int64_t i) {
    const int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
    image_kernel::store_pixel(out, static_cast<int>(i),
                              image_kernel::window_result(view, ops.data(), x, y, options.window));
  });
  return result;
}

ImageCurvature estimate_image_curvature_cuda(const GBuffer& gbuffer,
                                             const ImageSpaceOptions& options, int device) {
  (void)require_cuda_device(device);  // DeviceError first: without a device nothing else matters
  detail::validate_image_input(gbuffer, options, "estimate_image_curvature_cuda");
  ImageCurvature result = detail::allocate_image_curvature(gbuffer.width, gbuffer.height);
  if (!result.valid.empty()) {
    detail::image_curvature_on_device(detail::view_of(gbuffer),
                                      static_cast<float>(options.discontinuity_ratio),
                                      options.window, detail::fields_of(result), device);
  }
  return result;
}

}  // namespace focal
