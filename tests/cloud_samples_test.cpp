#include "focal/surfaces/cloud_samples.h"

#include <gtest/gtest.h>

#include <cmath>

#include "focal/core/error.h"
#include "focal/evaluation/cloud_evaluation.h"

namespace focal {
namespace {

TEST(CloudSamples, UniformSamplesAreTheIrregularVerticesWithoutFaces) {
  const AnalyticSurface mesh = make_surface({.kind = SurfaceKind::torus,
                                             .triangulation = Triangulation::irregular,
                                             .target_vertices = 1000});
  const AnalyticSurface cloud =
      sample_cloud({.surface = {.kind = SurfaceKind::torus, .target_vertices = 1000}});
  EXPECT_TRUE(cloud.mesh.is_cloud());
  EXPECT_EQ(cloud.mesh.V, mesh.mesh.V);
  EXPECT_EQ(cloud.mesh.N, mesh.mesh.N);
  EXPECT_EQ(cloud.k1, mesh.k1);
}

TEST(CloudSamples, GradedDensityOutliersAndNoNormals) {
  const AnalyticSurface graded = sample_cloud(
      {.surface = {.kind = SurfaceKind::sphere, .target_vertices = 4000}, .graded = 0.8});
  int low = 0, high = 0;
  for (Eigen::Index i = 0; i < graded.mesh.V.rows(); ++i) (graded.mesh.V(i, 0) < 0 ? low : high)++;
  // Kept with probability 1 - 0.8 t, t = (x + 1) / 2: on average 1 - 0.8 x 0.25 = 0.8 of the
  // x < 0 half and 0.4 of the other (the sphere's area is uniform in x): ratio 2, asserted > 1.5.
  EXPECT_GT(low, 1.5 * high);
  const AnalyticSurface outliers =
      sample_cloud({.surface = {.kind = SurfaceKind::sphere, .target_vertices = 4000},
                    .outliers = 0.05,
                    .normals = false});
  EXPECT_EQ(outliers.mesh.N.rows(), 0);
  int off = 0;
  for (Eigen::Index i = 0; i < outliers.k1.size(); ++i) off += std::isnan(outliers.k1[i]) ? 1 : 0;
  const double fraction = static_cast<double>(off) / static_cast<double>(outliers.k1.size());
  EXPECT_NEAR(fraction, 0.05, 0.015);  // binomial: 3.4 standard deviations at ~4000 points
  EXPECT_THROW((void)sample_cloud({.graded = 1.0}), InvalidInput);
  EXPECT_THROW((void)sample_cloud({.outliers = -0.1}), InvalidInput);
}

TEST(CloudEvaluation, ErrorsOfTheDefaultOnTheTorus) {
  const std::vector<CloudCase> cases = cloud_cases(2000, 1);
  ASSERT_EQ(cases.size(), all_surfaces().size() * 6);
  for (const CloudCase& c : cases) {
    if (c.name != "torus/exact normals" && c.name != "torus/2% outliers, no normals") continue;
    const CloudCaseResult r = evaluate_cloud_case(c);
    EXPECT_EQ(r.undefined, 0);
    EXPECT_EQ(r.k, 16);
    // Measured at 2000 points: 0.0093 with exact normals (CloudCurvature.ConvergesOnTheTorus
    // bounds its convergence); outliers spoil their neighbours' fits. Bounds: 2x and 10x that.
    EXPECT_LT(r.h_relative_rms, c.name == "torus/exact normals" ? 0.02 : 0.1) << c.name;
  }
}

}  // namespace
}  // namespace focal
