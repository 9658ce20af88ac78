#pragma once
/// \file device.h
/// The CUDA backend's devices. focal always runs on the CPU; a build configured with
/// FOCAL_WITH_CUDA (on by default where nvcc is found) can also use NVIDIA GPUs. Asking for a
/// device that is not there is a DeviceError, never a silent fallback.

#include <cstddef>
#include <string>
#include <vector>

namespace focal {

/// True when this build of the library contains the CUDA backend.
[[nodiscard]] bool cuda_built();

struct CudaDevice {
  int index = 0;
  std::string name;
  int compute_major = 0;  ///< compute capability, e.g. 9.0 for Hopper
  int compute_minor = 0;
  std::size_t memory_bytes = 0;
  int multiprocessors = 0;
};

/// The CUDA devices this process can use; empty without the backend, a driver or a GPU.
[[nodiscard]] std::vector<CudaDevice> cuda_devices();

/// The device with the given index.
/// \throw DeviceError saying why it cannot be used: no CUDA backend in this build, no driver or
///        no device, or an index out of range.
[[nodiscard]] CudaDevice require_cuda_device(int index = 0);

}  // namespace focal
