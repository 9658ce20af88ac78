// The image-space estimator's kernels (paper section 5.1): one thread per pixel running the
// per-pixel functions of src/kernels/pixel.h, the code of the CPU reference. The
// public estimate_image_curvature_cuda (src/image_space/image_space.cpp) validates the input on
// the host and calls image_curvature_on_device.
#include <cuda_runtime.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

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

template <class T>
cuda::DeviceBuffer<T> upload(const T* host, std::size_t n) {
  cuda::DeviceBuffer<T> b(n);
  b.upload(host, n);
  return b;
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

  void download(const image_kernel::ImageFields& host) const {
    k1.download(host.k1, n);
    k2.download(host.k2, n);
    H.download(host.H, n);
    K.download(host.K, n);
    depth1.download(host.focal_depth1, n);
    depth2.download(host.focal_depth2, n);
    d1.download(host.d1, 3 * n);
    d2.download(host.d2, 3 * n);
    valid.download(host.valid, n);
  }
};

}  // namespace

void image_curvature_on_device(const image_kernel::ImageView& image, float discontinuity_ratio,
                               int window, const image_kernel::ImageFields& out, int device) {
  const cuda::DeviceScope scope(device);
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  const auto position = upload(image.position, 3 * pixels);
  const auto normal = upload(image.normal, 3 * pixels);
  const auto mask = upload(image.mask, pixels);
  const DeviceFields fields(pixels);
  const cuda::DeviceBuffer<image_kernel::PixelOperator> ops(window > 0 ? pixels : 0);
  const ImageKernelParams params{
      {image.width, image.height, position.data(), normal.data(), mask.data()},
      fields.fields(),
      ops.data(),
      discontinuity_ratio,
      window};
  const dim3 block(16, 16);
  const dim3 grid = image_grid(image.width, image.height, block);
  if (window == 0) {
    triplet_pixels<<<grid, block>>>(params);
    cuda::check_launch("triplet_pixels");
  } else {
    operator_pixels<<<grid, block>>>(params);
    cuda::check_launch("operator_pixels");
    window_pixels<<<grid, block>>>(params);  // same stream: runs after operator_pixels
    cuda::check_launch("window_pixels");
  }
  cuda::check(cudaDeviceSynchronize(), "image-space kernels");
  fields.download(out);
}

}  // namespace focal::detail
