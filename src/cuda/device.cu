// The device API of a build with the CUDA backend: device queries through the CUDA runtime.
#include <cuda_runtime.h>

#include <string>

#include "focal/cuda/device.h"
#include "focal/core/error.h"

namespace focal {
namespace {

/// Devices visible to the runtime; no driver or no GPU is not an error here, just none.
int device_count(cudaError_t& status) {
  int count = 0;
  status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    cudaGetLastError();  // clear the sticky-free error so later calls start clean
    return 0;
  }
  return count;
}

CudaDevice describe(int index) {
  cudaDeviceProp p{};
  if (const cudaError_t e = cudaGetDeviceProperties(&p, index); e != cudaSuccess) {
    throw DeviceError("CUDA device " + std::to_string(index) + ": " + cudaGetErrorString(e));
  }
  return {index, p.name, p.major, p.minor, p.totalGlobalMem, p.multiProcessorCount};
}

}  // namespace

bool cuda_built() { return true; }

std::vector<CudaDevice> cuda_devices() {
  cudaError_t status;
  const int n = device_count(status);
  std::vector<CudaDevice> out;
  for (int i = 0; i < n; ++i) out.push_back(describe(i));
  return out;
}

CudaDevice require_cuda_device(int index) {
  cudaError_t status;
  const int n = device_count(status);
  if (status != cudaSuccess) {
    throw DeviceError(std::string("no usable CUDA device: ") + cudaGetErrorString(status));
  }
  if (index < 0 || index >= n) {
    throw DeviceError("CUDA device " + std::to_string(index) + " requested, but " +
                      std::to_string(n) + " device(s) are present");
  }
  return describe(index);
}

}  // namespace focal
