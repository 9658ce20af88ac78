#include "focal/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace focal {
namespace {

AnalyticSurface saddle() {
  SurfaceOptions o;
  o.kind = SurfaceKind::saddle;
  o.target_vertices = 900;
  return make_surface(o);
}

/// The truth of a surface as a CurvatureResult, every vertex classified.
CurvatureResult as_estimate(const AnalyticSurface& s, double scale) {
  CurvatureResult r;
  r.k1 = scale * s.k1;
  r.k2 = scale * s.k2;
  r.H = 0.5 * (r.k1 + r.k2);
  r.K = r.k1.cwiseProduct(r.k2);
  r.d1 = s.d1;
  r.d2 = s.d2;
  r.point_class =
      VectorXu8::Constant(s.k1.size(), static_cast<std::uint8_t>(PointClass::hyperbolic));
  return r;
}

TEST(Evaluation, TheTruthHasNoError) {
  const AnalyticSurface s = saddle();
  const Evaluation e = evaluate(s, as_estimate(s, 1.0));
  EXPECT_EQ(e.interior.relative_H, 0.0);
  EXPECT_EQ(e.interior.rms_k1, 0.0);
  EXPECT_EQ(e.interior.median_angle_d1, 0.0);
  EXPECT_EQ(e.interior.undefined, 0);
  EXPECT_GT(e.near_boundary.vertices, 0);  // the saddle is open: both sets are non-empty
  EXPECT_EQ(e.interior.vertices + e.near_boundary.vertices, s.mesh.V.rows());
}

// Scaling every curvature by 1.1 is a relative error of exactly 0.1 in H, k1, k2 and 0.21 in K.
TEST(Evaluation, RelativeErrorsOfAScaledEstimate) {
  const AnalyticSurface s = saddle();
  const Evaluation e = evaluate(s, as_estimate(s, 1.1));
  EXPECT_NEAR(e.interior.relative_H, 0.1, 1e-12);
  EXPECT_NEAR(e.interior.relative_k1, 0.1, 1e-12);
  EXPECT_NEAR(e.interior.relative_k2, 0.1, 1e-12);
  EXPECT_NEAR(e.interior.relative_K, 0.21, 1e-12);
}

TEST(Evaluation, UndefinedVerticesAreCountedNotAveraged) {
  const AnalyticSurface s = saddle();
  CurvatureResult r = as_estimate(s, 1.0);
  int interior_vertex = -1;
  const Evaluation before = evaluate(s, r);
  for (int i = 0; i < r.k1.size() && interior_vertex < 0; ++i) {
    if (std::abs(s.mesh.V(i, 0)) < 0.2 && std::abs(s.mesh.V(i, 1)) < 0.2) interior_vertex = i;
  }
  ASSERT_GE(interior_vertex, 0);
  r.k1[interior_vertex] = std::nan("");
  r.point_class[interior_vertex] = static_cast<std::uint8_t>(PointClass::undefined);
  const Evaluation after = evaluate(s, r);
  EXPECT_EQ(after.interior.undefined, 1);
  EXPECT_EQ(after.interior.relative_H, 0.0);
  EXPECT_EQ(after.interior.vertices, before.interior.vertices);
}

}  // namespace
}  // namespace focal
