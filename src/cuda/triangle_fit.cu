// The per-triangle characteristic equation's kernel: one thread per face running
// triangle_kernel::triangle_face (src/kernels/triangle.h), the code that
// detail::triangle_curvature_float runs on the CPU. The public triangle_curvature_cuda
// (src/cuda/triangle_fit.cpp) validates and packs the mesh on the host and calls
// triangle_faces_on_device.
#include <cuda_runtime.h>

#include <cstdint>
#include <vector>

#include "cuda/cuda_check.h"
#include "cuda/launch.h"
#include "kernels/triangle.h"

namespace focal::detail {
namespace {

__global__ void triangle_faces(triangle_kernel::TriangleKernelParams k) {
  const long long f = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (f < k.faces) triangle_kernel::triangle_face(k, static_cast<int>(f));
}

}  // namespace

void triangle_faces_on_device(const TriangleInput& in, std::vector<float>& values,
                              std::vector<std::uint8_t>& classes, int device) {
  const cuda::DeviceScope scope(device);
  const auto V = cuda::DeviceBuffer<double>::from_host(in.V);
  const auto N = cuda::DeviceBuffer<double>::from_host(in.N);
  const auto F = cuda::DeviceBuffer<std::int32_t>::from_host(in.F);
  const cuda::DeviceBuffer<float> d_values(values.size());
  const cuda::DeviceBuffer<std::uint8_t> d_classes(classes.size());
  const triangle_kernel::TriangleKernelParams k{
      V.data(),        N.data(),        F.data(), in.faces, in.zero_tolerance, in.umbilic_tolerance,
      d_values.data(), d_classes.data()};
  constexpr int kBlock = 256;
  const auto blocks =
      static_cast<unsigned>((static_cast<long long>(in.faces) + kBlock - 1) / kBlock);
  triangle_faces<<<blocks, kBlock>>>(k);
  cuda::check_launch("triangle_faces");
  cuda::check(cudaDeviceSynchronize(), "triangle_faces");
  d_values.download(values.data(), values.size());
  d_classes.download(classes.data(), classes.size());
}

}  // namespace focal::detail
