// The device API of a build without the CUDA backend.
#include "focal/core/error.h"
#include "focal/cuda/device.h"

namespace focal {

bool cuda_built() { return false; }

std::vector<CudaDevice> cuda_devices() { return {}; }

CudaDevice require_cuda_device(int /*index*/) {
  throw DeviceError(
      "this build of focal has no CUDA backend; configure with -DFOCAL_WITH_CUDA=ON on a machine "
      "with the CUDA toolkit (nvcc) to use a GPU");
}

}  // namespace focal
