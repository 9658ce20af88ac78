#include "focal/cuda/device.h"

#include <gtest/gtest.h>

#include "focal/core/error.h"
#include "gpu_required.h"

namespace focal {
namespace {

TEST(Device, WithoutTheBackendAskingForADeviceIsAnError) {
  if (cuda_built()) GTEST_SKIP() << "this build has the CUDA backend";
  EXPECT_TRUE(cuda_devices().empty());
  EXPECT_THROW((void)require_cuda_device(), DeviceError);
  const CudaStatus s = cuda_status();
  EXPECT_FALSE(s.built);
  EXPECT_NE(s.why_none.find("no CUDA backend"), std::string::npos) << s.why_none;
}

// Runs on every machine with the backend: with no usable device the status says why, in one of
// the documented ways, and asking for a device is a DeviceError with the same reason.
TEST(Device, WithTheBackendTheStatusSaysWhyNoDeviceIsUsable) {
  if (!cuda_built()) GTEST_SKIP() << "this build has no CUDA backend";
  const CudaStatus s = cuda_status();
  EXPECT_TRUE(s.built);
  EXPECT_GE(s.runtime_version, 12000) << "the toolkit's runtime is linked in";
  EXPECT_FALSE(s.architectures.empty());
  if (!s.why_none.empty()) {
    try {
      (void)require_cuda_device();
      ADD_FAILURE() << "require_cuda_device succeeded although: " << s.why_none;
    } catch (const DeviceError& e) {
      EXPECT_FALSE(std::string(e.what()).empty());
    }
  }
}

TEST(Device, WithTheBackendDevicesAreDescribed) {
  FOCAL_NEEDS_GPU();
  const auto devices = cuda_devices();
  ASSERT_FALSE(devices.empty());
  for (const CudaDevice& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_GT(d.memory_bytes, 0u);
    EXPECT_EQ(d.supported, d.unsupported_reason.empty()) << d.unsupported_reason;
  }
  EXPECT_EQ(require_cuda_device(0).name, devices[0].name);
  EXPECT_THROW((void)require_cuda_device(static_cast<int>(devices.size())), DeviceError);
  EXPECT_THROW((void)require_cuda_device(-1), DeviceError);
}

}  // namespace
}  // namespace focal
