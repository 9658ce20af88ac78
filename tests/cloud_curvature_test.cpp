#include "focal/curvature/cloud_curvature.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "focal/core/error.h"
#include "test_clouds.h"

namespace focal {
namespace {

TEST(CloudCurvature, Explore) {
  for (SurfaceKind kind : all_surfaces()) {
    for (int n : {2000, 8000}) {
      const AnalyticSurface s = test::cloud_of(kind, n);
      for (int k : {8, 12, 16, 24, 32}) {
        const CloudCurvature given = estimate_cloud_curvature(s.mesh.V, NormalsRef(s.mesh.N), {.k = k});
        const CloudCurvature none = estimate_cloud_curvature(s.mesh.V, std::nullopt, {.k = k});
        const auto a = test::h_error(s, given.curvature), b = test::h_error(s, none.curvature);
        std::printf("%-14s n=%5d k=%2d given %.5f (%d) estimated %.5f (%d)\n",
                    std::string(surface_name(kind)).c_str(), n, k, a.relative_rms, a.undefined,
                    b.relative_rms, b.undefined);
      }
    }
  }
}

}  // namespace
}  // namespace focal
