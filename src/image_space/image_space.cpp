// The image-space estimator: the CPU reference (the per-pixel functions of kernels/pixel.h in a
// parallel loop over pixels) and the CUDA entry point's host side (validation, allocation; the
// kernels are in src/cuda/image_space.cu).
#include "focal/image_space/image_space.h"

#include <cmath>
#include <cstddef>
#include <string>

#include "core/parallel.h"
#include "cuda/launch.h"
#include "focal/core/error.h"
#include "focal/cuda/device.h"
#include "image_space/host_side.h"

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
  if (pixels > kMaxPixels) {
    throw InvalidInput(std::string(what) + ": G-buffer of " + std::to_string(pixels) +
                       " pixels is too large (at most " + std::to_string(kMaxPixels) + ")");
  }
  check_size(g.position.size(), 3 * pixels, "position", what, g);
  check_size(g.normal.size(), 3 * pixels, "normal", what, g);
  check_size(g.mask.size(), pixels, "mask", what, g);
  validate_image_options(options, what);
}

void validate_image_options(const ImageSpaceOptions& options, const char* what) {
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

bool has_image_size(const ImageCurvature& r, int width, int height) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  bool sized = r.width == width && r.height == height && r.d1.size() == 3 * n &&
               r.d2.size() == 3 * n && r.valid.size() == n;
  for (const std::vector<float>* f : {&r.k1, &r.k2, &r.H, &r.K, &r.focal_depth1, &r.focal_depth2}) {
    sized = sized && f->size() == n;
  }
  return sized;
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
    detail::parallel_for(pixels, 0, [&](std::int64_t i) {
      const int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
      image_kernel::store_pixel(out, static_cast<int>(i),
                                image_kernel::pixel_result(view, x, y, ratio));
    });
    return result;
  }
  std::vector<image_kernel::PixelOperator> ops(static_cast<std::size_t>(pixels));
  detail::parallel_for(pixels, 0, [&](std::int64_t i) {
    ops[static_cast<std::size_t>(i)] = image_kernel::pixel_operator(
        view, static_cast<int>(i % width), static_cast<int>(i / width), ratio);
  });
  detail::parallel_for(pixels, 0, [&](std::int64_t i) {
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

namespace detail {

void image_curvature_on_device(const image_kernel::ImageView& image, float discontinuity_ratio,
                               int window, const image_kernel::ImageFields& out, int device) {
  // Pageable transfers: pinning the caller's arrays for one call costs more than it saves.
  const ImageDeviceStatePtr state =
      make_image_device_state(image.width, image.height, window, false, device);
  upload_frame(*state, image);
  run_frame(*state, discontinuity_ratio, window);
  download_frame(*state, out);
}

}  // namespace detail

namespace {

constexpr const char* kContext = "ImageCurvatureCudaContext";

/// The context's frame size (the size of any G-buffer, and at least one pixel) and options.
void validate_context(int width, int height, const ImageSpaceOptions& options) {
  if (width < 1 || height < 1 ||
      static_cast<std::size_t>(width) * static_cast<std::size_t>(height) > detail::kMaxPixels) {
    throw InvalidInput(std::string(kContext) + ": frame size " + std::to_string(width) + " x " +
                       std::to_string(height) + " must be at least 1 x 1 and at most " +
                       std::to_string(detail::kMaxPixels) + " pixels");
  }
  detail::validate_image_options(options, kContext);
}

}  // namespace

ImageCurvatureCudaContext::ImageCurvatureCudaContext(int width, int height,
                                                     const ImageSpaceOptions& options, int device)
    : width_(width), height_(height), device_(device), options_(options) {
  (void)require_cuda_device(device);  // DeviceError first, as the one-shot call
  validate_context(width, height, options);
  state_ = detail::make_image_device_state(width, height, options.window, true, device);
}

ImageCurvature ImageCurvatureCudaContext::estimate(const GBuffer& gbuffer) {
  ImageCurvature out;
  estimate(gbuffer, out);
  return out;
}

void ImageCurvatureCudaContext::estimate(const GBuffer& gbuffer, ImageCurvature& out) {
  upload(gbuffer);
  compute();
  download(out);
}

void ImageCurvatureCudaContext::upload(const GBuffer& gbuffer) {
  if (gbuffer.width != width_ || gbuffer.height != height_) {
    throw InvalidInput(std::string(kContext) + ": G-buffer of " + std::to_string(gbuffer.width) +
                       " x " + std::to_string(gbuffer.height) + " pixels in a context of " +
                       std::to_string(width_) + " x " + std::to_string(height_));
  }
  detail::validate_image_input(gbuffer, options_, kContext);
  uploaded_ = false;  // a failed copy leaves no frame to compute on
  detail::upload_frame(*state_, detail::view_of(gbuffer));
  uploaded_ = true;
}

void ImageCurvatureCudaContext::compute() {
  if (!uploaded_) throw InvalidInput(std::string(kContext) + ": compute before any upload");
  computed_ = false;
  detail::run_frame(*state_, static_cast<float>(options_.discontinuity_ratio), options_.window);
  computed_ = true;
}

void ImageCurvatureCudaContext::download(ImageCurvature& out) {
  if (!computed_) throw InvalidInput(std::string(kContext) + ": download before any compute");
  if (!detail::has_image_size(out, width_, height_)) {
    out = detail::allocate_image_curvature(width_, height_);
  }
  detail::download_frame(*state_, detail::fields_of(out));
}

}  // namespace focal
