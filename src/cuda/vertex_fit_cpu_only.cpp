// estimate_curvature_cuda in a build without the CUDA backend: a DeviceError that says why,
// never a silent fallback to the CPU (STYLE.md, convention 8).
#include "focal/cuda/curvature.h"
#include "focal/core/error.h"

namespace focal {

CurvatureResult estimate_curvature_cuda(PositionsRef /*V*/, FacesRef /*F*/, NormalsRef /*N*/,
                                        const CurvatureOptions& /*options*/, int /*device*/) {
  throw DeviceError(
      "estimate_curvature_cuda: this build of focal has no CUDA backend; configure with "
      "-DFOCAL_WITH_CUDA=ON on a machine with the CUDA toolkit (nvcc) to use a GPU, or call "
      "estimate_curvature");
}

}  // namespace focal
