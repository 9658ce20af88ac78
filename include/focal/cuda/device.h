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
  /// False when this build has no code the device can run (its compute capability is below
  /// every architecture the backend was compiled for); `unsupported_reason` then says so.
  bool supported = true;
  std::string unsupported_reason;
};

/// What the CUDA runtime says about this machine, for `focal devices` and for tests that must
/// tell "no GPU" from "the driver is too old" or "no backend".
struct CudaStatus {
  bool built = false;         ///< this build contains the CUDA backend
  int runtime_version = 0;    ///< the CUDA runtime linked in, e.g. 13000 for 13.0; 0 if none
  int driver_version = 0;     ///< the newest CUDA version the driver supports; 0 without one
  std::string architectures;  ///< the compute capabilities compiled in, e.g. "80,90"
  std::vector<CudaDevice> devices;
  /// Empty when at least one device is usable, else why none is: no backend, no driver, a
  /// driver older than the runtime, no device, or the runtime's own error message.
  std::string why_none;
};

/// The backend, runtime, driver and devices, and why no device is usable when none is.
[[nodiscard]] CudaStatus cuda_status();

/// The CUDA devices this process sees (usable or not, see CudaDevice::supported); empty without
/// the backend, a driver or a GPU. cuda_status().why_none says which.
[[nodiscard]] std::vector<CudaDevice> cuda_devices();

/// The device with the given index.
/// \throw DeviceError saying why it cannot be used: no CUDA backend in this build, no driver or
///        no device, an index out of range, or a device this build has no code for.
[[nodiscard]] CudaDevice require_cuda_device(int index = 0);

}  // namespace focal
