// The image-space device state in a build without the CUDA backend. Never reached through
// estimate_image_curvature_cuda or ImageCurvatureCudaContext, which ask require_cuda_device
// first (a DeviceError saying that this build has no CUDA backend); a DeviceError here too,
// never a silent CPU fallback.
#include "cuda/launch.h"
#include "focal/core/error.h"

namespace focal::detail {
namespace {

[[noreturn]] void no_backend() {
  throw DeviceError(
      "image space on a GPU: this build of focal has no CUDA backend; configure with "
      "-DFOCAL_WITH_CUDA=ON on a machine with the CUDA toolkit (nvcc) to use a GPU");
}

}  // namespace

// No state is ever made here, so none is ever deleted.
void ImageDeviceStateDeleter::operator()(ImageDeviceState* /*state*/) const noexcept {}

ImageDeviceStatePtr make_image_device_state(int /*width*/, int /*height*/, int /*window*/,
                                            bool /*pinned*/, int /*device*/) {
  no_backend();
}
void upload_frame(ImageDeviceState& /*state*/, const image_kernel::ImageView& /*image*/) {
  no_backend();
}
void run_frame(ImageDeviceState& /*state*/, float /*discontinuity_ratio*/, int /*window*/) {
  no_backend();
}
void download_frame(ImageDeviceState& /*state*/, const image_kernel::ImageFields& /*out*/) {
  no_backend();
}

}  // namespace focal::detail
