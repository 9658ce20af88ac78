#pragma once
/// \file image_state.h
/// The handle of ImageCurvatureCudaContext's device state (focal/image_space/image_space.h):
/// declared here, below image space, so that the CUDA backend that defines it
/// (src/cuda/image_space.cu) and the context that holds it both see it.

#include <memory>

namespace focal::detail {

struct ImageDeviceState;  ///< a frame's device and pinned buffers and stream (src/cuda)
struct ImageDeviceStateDeleter {
  void operator()(ImageDeviceState* state) const noexcept;
};
using ImageDeviceStatePtr = std::unique_ptr<ImageDeviceState, ImageDeviceStateDeleter>;

}  // namespace focal::detail
