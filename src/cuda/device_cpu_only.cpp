// The device API of a build without the CUDA backend.
#include "focal/core/error.h"
#include "focal/cuda/device.h"

namespace focal {
namespace {

constexpr const char* kNoBackend =
    "this build of focal has no CUDA backend; configure with -DFOCAL_WITH_CUDA=ON on a machine "
    "with the CUDA toolkit (nvcc) to use a GPU";

}  // namespace

bool cuda_built() { return false; }

std::vector<CudaDevice> cuda_devices() { return {}; }

CudaStatus cuda_status() {
  CudaStatus s;
  s.why_none = kNoBackend;
  return s;
}

CudaDevice require_cuda_device(int /*index*/) { throw DeviceError(kNoBackend); }

}  // namespace focal
