// The per-triangle kernel's launcher in a build without the CUDA backend. Never reached through
// triangle_curvature_cuda, which asks require_cuda_device first (a DeviceError saying that this
// build has no CUDA backend); a DeviceError here too, never a silent CPU fallback.
#include "focal/core/error.h"
#include "cuda/launch.h"

namespace focal::detail {

void triangle_faces_on_device(const TriangleInput& /*in*/, std::vector<float>& /*values*/,
                              std::vector<std::uint8_t>& /*classes*/, int /*device*/) {
  throw DeviceError(
      "triangle_curvature_cuda: this build of focal has no CUDA backend; configure with "
      "-DFOCAL_WITH_CUDA=ON on a machine with the CUDA toolkit (nvcc) to use a GPU");
}

}  // namespace focal::detail
