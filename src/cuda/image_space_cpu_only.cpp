// The image-space kernels' launcher in a build without the CUDA backend. Never reached through
// estimate_image_curvature_cuda, which asks require_cuda_device first (a DeviceError saying that
// this build has no CUDA backend); a DeviceError here too, never a silent CPU fallback.
#include "focal/core/error.h"
#include "cuda/launch.h"

namespace focal::detail {

void image_curvature_on_device(const image_kernel::ImageView& /*image*/,
                               float /*discontinuity_ratio*/, int /*window*/,
                               const image_kernel::ImageFields& /*out*/, int /*device*/) {
  throw DeviceError(
      "estimate_image_curvature_cuda: this build of focal has no CUDA backend; configure with "
      "-DFOCAL_WITH_CUDA=ON on a machine with the CUDA toolkit (nvcc) to use a GPU");
}

}  // namespace focal::detail
