#pragma once
// Bitwise comparison of two results, for the tests of tiles (tiles_test, cloud_tiles_test): a
// tiled run must give the whole run's bits.

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "focal/core/fields.h"

namespace focal::test {

/// Bitwise equality of every field (NaN included), naming the first differing vertex.
inline void expect_identical(const CurvatureResult& a, const CurvatureResult& b,
                             const std::string& what) {
  ASSERT_EQ(a.k1.size(), b.k1.size()) << what;
  for (Eigen::Index i = 0; i < a.k1.size(); ++i) {
    const auto same = [&](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    bool equal = same(a.k1[i], b.k1[i]) && same(a.k2[i], b.k2[i]) && same(a.H[i], b.H[i]) &&
                 same(a.K[i], b.K[i]) && same(a.residual[i], b.residual[i]) &&
                 a.point_class[i] == b.point_class[i] && a.rays_used[i] == b.rays_used[i] &&
                 a.rays_excluded[i] == b.rays_excluded[i];
    for (int c = 0; c < 3; ++c)
      equal &= same(a.d1(i, c), b.d1(i, c)) && same(a.d2(i, c), b.d2(i, c));
    ASSERT_TRUE(equal) << what << ": vertex " << i << " differs: k1 " << a.k1[i] << " vs "
                       << b.k1[i];
  }
}

}  // namespace focal::test
