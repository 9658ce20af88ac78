// The device API of a build with the CUDA backend: device queries through the CUDA runtime.
// FOCAL_CUDA_ARCHITECTURES (src/CMakeLists.txt) lists the compute capabilities compiled in, e.g.
// "80,90"; CMake builds each as SASS plus PTX, so a device of at least the lowest one can run
// the kernels (newer ones through the driver's JIT), and an older one cannot.
#include <cuda_runtime.h>

#include <algorithm>
#include <cctype>
#include <sstream>
#include <string>

#include "focal/core/error.h"
#include "focal/cuda/device.h"

#ifndef FOCAL_CUDA_ARCHITECTURES
#error "FOCAL_CUDA_ARCHITECTURES must name the compiled compute capabilities"
#endif

namespace focal {
namespace {

/// The compiled architectures as numbers (major * 10 + minor), from "80,90" or "80-real,90".
std::vector<int> compiled_architectures() {
  std::vector<int> out;
  std::stringstream list(FOCAL_CUDA_ARCHITECTURES);
  for (std::string item; std::getline(list, item, ',');) {
    if (!item.empty() && std::isdigit(static_cast<unsigned char>(item[0]))) {
      out.push_back(std::stoi(item));
    }
  }
  return out;
}

std::string capability(int major, int minor) {
  return std::to_string(major) + "." + std::to_string(minor);
}

/// Empty when the build has code for compute capability major.minor, else why not.
std::string unsupported_reason(int major, int minor) {
  const std::vector<int> built = compiled_architectures();
  if (built.empty()) return {};
  const int lowest = *std::min_element(built.begin(), built.end());
  if (major * 10 + minor >= lowest) return {};
  return "compute capability " + capability(major, minor) +
         " is below every architecture this build has code for (" + FOCAL_CUDA_ARCHITECTURES +
         "); reconfigure with -DCMAKE_CUDA_ARCHITECTURES=" + std::to_string(major) +
         std::to_string(minor);
}

/// Devices visible to the runtime; no driver or no GPU is not an error here, just none, with
/// the runtime's status kept for cuda_status().
int device_count(cudaError_t& status) {
  int count = 0;
  status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    cudaGetLastError();  // clear the error so later calls start clean
    return 0;
  }
  return count;
}

CudaDevice describe(int index) {
  cudaDeviceProp p{};
  if (const cudaError_t e = cudaGetDeviceProperties(&p, index); e != cudaSuccess) {
    throw DeviceError("CUDA device " + std::to_string(index) + ": " + cudaGetErrorString(e));
  }
  CudaDevice d;
  d.index = index;
  d.name = p.name;
  d.compute_major = p.major;
  d.compute_minor = p.minor;
  d.memory_bytes = p.totalGlobalMem;
  d.multiprocessors = p.multiProcessorCount;
  d.unsupported_reason = unsupported_reason(p.major, p.minor);
  d.supported = d.unsupported_reason.empty();
  return d;
}

/// "12.4" from the runtime's and driver's encoding 12040.
std::string cuda_version(int v) {
  return std::to_string(v / 1000) + "." + std::to_string(v % 1000 / 10);
}

/// Why cudaGetDeviceCount failed, in words a user can act on. The static runtime needs a driver
/// at least as new as itself; an older one reports "insufficient driver", not "no device".
std::string why_no_device(cudaError_t status, int runtime, int driver) {
  const std::string error = cudaGetErrorString(status);
  if (status == cudaErrorNoDevice) {
    return "no CUDA device is visible (no NVIDIA GPU, or CUDA_VISIBLE_DEVICES hides them)";
  }
  if (driver == 0) return "no NVIDIA driver is loaded, so no GPU can be used (" + error + ")";
  if (status == cudaErrorInsufficientDriver) {
    return "the NVIDIA driver supports CUDA up to " + cuda_version(driver) +
           " but this build's runtime is CUDA " + cuda_version(runtime) + ": update the driver";
  }
  return "the CUDA runtime cannot use a device: " + error;
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

CudaStatus cuda_status() {
  CudaStatus s;
  s.built = true;
  s.architectures = FOCAL_CUDA_ARCHITECTURES;
  cudaRuntimeGetVersion(&s.runtime_version);
  if (cudaDriverGetVersion(&s.driver_version) != cudaSuccess) s.driver_version = 0;
  cudaError_t status;
  const int n = device_count(status);
  for (int i = 0; i < n; ++i) s.devices.push_back(describe(i));
  if (status != cudaSuccess) {
    s.why_none = why_no_device(status, s.runtime_version, s.driver_version);
  } else if (n == 0) {
    s.why_none = "no CUDA device is visible";
  } else if (std::none_of(s.devices.begin(), s.devices.end(),
                          [](const CudaDevice& d) { return d.supported; })) {
    s.why_none = "no visible device can run this build: " + s.devices[0].unsupported_reason;
  }
  return s;
}

CudaDevice require_cuda_device(int index) {
  cudaError_t status;
  const int n = device_count(status);
  if (status != cudaSuccess) {
    int runtime = 0, driver = 0;
    cudaRuntimeGetVersion(&runtime);
    cudaDriverGetVersion(&driver);
    throw DeviceError("no usable CUDA device: " + why_no_device(status, runtime, driver));
  }
  if (index < 0 || index >= n) {
    throw DeviceError("CUDA device " + std::to_string(index) + " requested, but " +
                      std::to_string(n) + " device(s) are present");
  }
  CudaDevice d = describe(index);
  if (!d.supported) {
    throw DeviceError("CUDA device " + std::to_string(index) + " (" + d.name +
                      "): " + d.unsupported_reason);
  }
  return d;
}

}  // namespace focal
