#include "focal/cuda/device.h"

#include <gtest/gtest.h>

#include "focal/core/error.h"

namespace focal {
namespace {

TEST(Device, WithoutTheBackendAskingForADeviceIsAnError) {
  if (cuda_built()) GTEST_SKIP() << "this build has the CUDA backend";
  EXPECT_TRUE(cuda_devices().empty());
  EXPECT_THROW((void)require_cuda_device(), DeviceError);
}

TEST(Device, WithTheBackendDevicesAreDescribedOrTheAbsenceReported) {
  if (!cuda_built()) GTEST_SKIP() << "this build has no CUDA backend";
  const auto devices = cuda_devices();
  if (devices.empty()) {
    EXPECT_THROW((void)require_cuda_device(), DeviceError);
    GTEST_SKIP() << "no CUDA device on this machine (expected in CI)";
  }
  for (const CudaDevice& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_GE(d.compute_major, 7);
    EXPECT_GT(d.memory_bytes, 0u);
  }
  EXPECT_EQ(require_cuda_device(0).name, devices[0].name);
  EXPECT_THROW((void)require_cuda_device(static_cast<int>(devices.size())), DeviceError);
}

}  // namespace
}  // namespace focal
