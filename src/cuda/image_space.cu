// The image-space estimator's kernels (paper section 5.1): one thread per pixel running the
// per-pixel functions of src/kernels/pixel.h, the code of the CPU reference, and the state that
// keeps a frame's buffers on the device (ImageDeviceState). The public
// estimate_image_curvature_cuda and ImageCurvatureCudaContext (src/image_space/image_space.cpp)
// validate the input on the host and drive the state.
#include <cuda_runtime.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "cuda/cuda_check.h"
#include "cuda/launch.h"
#include "kernels/pixel.h"

namespace focal::detail {
namespace {

/// Everything the kernels read and write, by value (one parameter struct for host and device).
struct ImageKernelParams {
  image_kernel::ImageView view;
  image_kernel::ImageFields out;
  image_kernel::PixelOperator* ops;  ///< the window's first pass; unused without a window
  float ratio;
  int window;
};

// Threads cover the image's columns with the grid's x and stride over its rows with the grid's
// y, whose size is limited to 65,535 blocks (kMaxGridRows): an image taller than 65,535 x 16
// rows is covered in several passes of the same threads.
constexpr unsigned kMaxGridRows = 65535;

__device__ int thread_column() { return static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); }
__device__ int first_row() { return static_cast<int>(blockIdx.y * blockDim.y + threadIdx.y); }
__device__ int row_stride() { return static_cast<int>(gridDim.y * blockDim.y); }

__global__ void triplet_pixels(ImageKernelParams p) {
  const int x = thread_column();
  if (x >= p.view.width) return;
  for (int y = first_row(); y < p.view.height; y += row_stride()) {
    image_kernel::store_pixel(p.out, image_kernel::pixel_index(p.view, x, y),
                              image_kernel::pixel_result(p.view, x, y, p.ratio));
  }
}

__global__ void operator_pixels(ImageKernelParams p) {
  const int x = thread_column();
  if (x >= p.view.width) return;
  for (int y = first_row(); y < p.view.height; y += row_stride()) {
    p.ops[image_kernel::pixel_index(p.view, x, y)] =
        image_kernel::pixel_operator(p.view, x, y, p.ratio);
  }
}

__global__ void window_pixels(ImageKernelParams p) {
  const int x = thread_column();
  if (x >= p.view.width) return;
  for (int y = first_row(); y < p.view.height; y += row_stride()) {
    image_kernel::store_pixel(p.out, image_kernel::pixel_index(p.view, x, y),
                              image_kernel::window_result(p.view, p.ops, x, y, p.window));
  }
}

/// The launch grid for an image: all columns, rows up to the y limit (the kernels stride).
dim3 image_grid(int width, int height, dim3 block) {
  const unsigned rows = (static_cast<unsigned>(height) + block.y - 1) / block.y;
  return {(static_cast<unsigned>(width) + block.x - 1) / block.x, std::min(rows, kMaxGridRows)};
}

/// The result's fields in device memory.
struct DeviceFields {
  std::size_t n;
  cuda::DeviceBuffer<float> k1, k2, H, K, depth1, depth2, d1, d2;
  cuda::DeviceBuffer<std::uint8_t> valid;

  explicit DeviceFields(std::size_t pixels)
      : n(pixels), k1(n), k2(n), H(n), K(n), depth1(n), depth2(n), d1(3 * n), d2(3 * n), valid(n) {}

  [[nodiscard]] image_kernel::ImageFields fields() const {
    return {k1.data(),     k2.data(), H.data(),  K.data(),    depth1.data(),
            depth2.data(), d1.data(), d2.data(), valid.data()};
  }

  /// Queued on `stream`; the caller synchronises it before reading `host`.
  void download(const image_kernel::ImageFields& host, cudaStream_t stream) const {
    k1.download_async(host.k1, n, stream);
    k2.download_async(host.k2, n, stream);
    H.download_async(host.H, n, stream);
    K.download_async(host.K, n, stream);
    depth1.download_async(host.focal_depth1, n, stream);
    depth2.download_async(host.focal_depth2, n, stream);
    d1.download_async(host.d1, 3 * n, stream);
    d2.download_async(host.d2, 3 * n, stream);
    valid.download_async(host.valid, n, stream);
  }
};

/// Page-locked host copies of a frame's G-buffer and fields, the ends of the transfers.
struct PinnedFrame {
  cuda::PinnedBuffer<float> position, normal;
  cuda::PinnedBuffer<std::uint8_t> mask;
  cuda::PinnedBuffer<float> floats;  ///< k1, k2, H, K, depth1, depth2 (n each), d1, d2 (3 n each)
  cuda::PinnedBuffer<std::uint8_t> valid;

  explicit PinnedFrame(std::size_t n)
      : position(3 * n), normal(3 * n), mask(n), floats(12 * n), valid(n) {}

  [[nodiscard]] image_kernel::ImageFields fields(std::size_t n) const {
    float* f = floats.data();
    return {f,         f + n,     f + 2 * n, f + 3 * n,   f + 4 * n,
            f + 5 * n, f + 6 * n, f + 9 * n, valid.data()};
  }
};

/// Copies the fields between two host layouts of n pixels.
void copy_fields(const image_kernel::ImageFields& from, const image_kernel::ImageFields& to,
                 std::size_t n) {
  const auto copy = [](const auto* a, auto* b, std::size_t count) {
    std::memcpy(b, a, count * sizeof(*a));
  };
  copy(from.k1, to.k1, n);
  copy(from.k2, to.k2, n);
  copy(from.H, to.H, n);
  copy(from.K, to.K, n);
  copy(from.focal_depth1, to.focal_depth1, n);
  copy(from.focal_depth2, to.focal_depth2, n);
  copy(from.d1, to.d1, 3 * n);
  copy(from.d2, to.d2, 3 * n);
  copy(from.valid, to.valid, n);
}

}  // namespace

/// Everything a frame needs on the device, allocated once for frames of one size.
struct ImageDeviceState {
  int device, width, height;
  std::size_t n;
  cuda::DeviceBuffer<float> position, normal;
  cuda::DeviceBuffer<std::uint8_t> mask;
  DeviceFields fields;
  cuda::DeviceBuffer<image_kernel::PixelOperator> ops;  ///< the window's first pass
  cuda::Stream stream;
  std::unique_ptr<PinnedFrame> pinned;  ///< null: transfers from and to pageable memory

  ImageDeviceState(int device_, int width_, int height_, int window, bool use_pinned)
      : device(device_),
        width(width_),
        height(height_),
        n(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_)),
        position(3 * n),
        normal(3 * n),
        mask(n),
        fields(n),
        ops(window > 0 ? n : 0),
        pinned(use_pinned ? std::make_unique<PinnedFrame>(n) : nullptr) {}
};

void ImageDeviceStateDeleter::operator()(ImageDeviceState* s) const noexcept {
  // Freed with its device current, and the caller's device restored; no throw from here.
  int previous = 0;
  const bool restore = cudaGetDevice(&previous) == cudaSuccess;
  cudaSetDevice(s->device);
  delete s;
  if (restore) cudaSetDevice(previous);
}

ImageDeviceStatePtr make_image_device_state(int width, int height, int window, bool pinned,
                                            int device) {
  const cuda::DeviceScope scope(device);
  return ImageDeviceStatePtr(new ImageDeviceState(device, width, height, window, pinned));
}

void upload_frame(ImageDeviceState& s, const image_kernel::ImageView& image) {
  const cuda::DeviceScope scope(s.device);
  const float* position = image.position;
  const float* normal = image.normal;
  const std::uint8_t* mask = image.mask;
  if (s.pinned) {
    std::memcpy(s.pinned->position.data(), position, 3 * s.n * sizeof(float));
    std::memcpy(s.pinned->normal.data(), normal, 3 * s.n * sizeof(float));
    std::memcpy(s.pinned->mask.data(), mask, s.n);
    position = s.pinned->position.data();
    normal = s.pinned->normal.data();
    mask = s.pinned->mask.data();
  }
  s.position.upload_async(position, 3 * s.n, s.stream.get());
  s.normal.upload_async(normal, 3 * s.n, s.stream.get());
  s.mask.upload_async(mask, s.n, s.stream.get());
}

void run_frame(ImageDeviceState& s, float discontinuity_ratio, int window) {
  const cuda::DeviceScope scope(s.device);
  const ImageKernelParams params{
      {s.width, s.height, s.position.data(), s.normal.data(), s.mask.data()},
      s.fields.fields(),
      s.ops.data(),
      discontinuity_ratio,
      window};
  const dim3 block(16, 16);
  const dim3 grid = image_grid(s.width, s.height, block);
  const cudaStream_t stream = s.stream.get();
  if (window == 0) {
    triplet_pixels<<<grid, block, 0, stream>>>(params);
    cuda::check_launch("triplet_pixels");
  } else {
    operator_pixels<<<grid, block, 0, stream>>>(params);
    cuda::check_launch("operator_pixels");
    window_pixels<<<grid, block, 0, stream>>>(params);  // same stream: after operator_pixels
    cuda::check_launch("window_pixels");
  }
  s.stream.synchronize("image-space kernels");
}

void download_frame(ImageDeviceState& s, const image_kernel::ImageFields& out) {
  const cuda::DeviceScope scope(s.device);
  if (!s.pinned) {
    s.fields.download(out, s.stream.get());
    s.stream.synchronize("image-space download");
    return;
  }
  const image_kernel::ImageFields staged = s.pinned->fields(s.n);
  s.fields.download(staged, s.stream.get());
  s.stream.synchronize("image-space download");
  copy_fields(staged, out, s.n);
}

}  // namespace focal::detail
