#pragma once
// GPU tests skip where no usable CUDA device is present (CI, build hosts), unless the
// environment sets FOCAL_REQUIRE_GPU=1: then a missing device is a failure, so that a run on a
// GPU machine cannot report green without running its GPU tests (docs/GPU.md).

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "focal/cuda/device.h"

namespace focal::test {

/// True when FOCAL_REQUIRE_GPU=1.
inline bool gpu_required() {
  const char* v = std::getenv("FOCAL_REQUIRE_GPU");
  return v != nullptr && std::string(v) == "1";
}

/// Empty when a usable CUDA device is present, else why there is none (no backend, no driver,
/// an old driver, no device, or none this build has code for).
inline std::string why_no_gpu() { return cuda_status().why_none; }

}  // namespace focal::test

/// At the top of a test that needs a GPU: skips without one, fails without one under
/// FOCAL_REQUIRE_GPU=1.
#define FOCAL_NEEDS_GPU()                                                        \
  if (const std::string why = ::focal::test::why_no_gpu(); !why.empty()) {       \
    if (::focal::test::gpu_required()) FAIL() << "FOCAL_REQUIRE_GPU=1: " << why; \
    GTEST_SKIP() << why;                                                         \
  }
