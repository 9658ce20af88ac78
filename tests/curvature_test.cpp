#include "focal/curvature.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "focal/error.h"
#include "focal/normals.h"
#include "focal/surfaces.h"
#include "test_meshes.h"

namespace focal {
namespace {

using test::interior_vertices;
using test::rms;
using test::rms_error;

AnalyticSurface surface(SurfaceKind kind, Triangulation tri, int vertices, double a = 0) {
  SurfaceOptions o;
  o.kind = kind;
  o.triangulation = tri;
  o.target_vertices = vertices;
  o.a = a;
  o.seed = 42;
  return make_surface(o);
}

CurvatureOptions with(Solver solver, int rings = 1, RayWeighting w = RayWeighting::uniform) {
  CurvatureOptions o;
  o.solver = solver;
  o.rings = rings;
  o.weighting = w;
  return o;
}

// ---- Sphere: every normal ray passes through the centre, so the rays satisfy g = x / r exactly
// and the closed form recovers k1 = k2 = 1/r up to rounding, for any triangulation, scale,
// neighbourhood and weighting (DESIGN.md; paper Fig. 2a).

class SphereExact : public ::testing::TestWithParam<std::tuple<Triangulation, double, int>> {};

TEST_P(SphereExact, ClosedFormGivesOneOverRadius) {
  const auto [tri, radius, rings] = GetParam();
  const AnalyticSurface s = surface(SurfaceKind::sphere, tri, 1500, radius);
  for (auto w : {RayWeighting::uniform, RayWeighting::gaussian}) {
    const CurvatureResult r =
        estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, with(Solver::closed_form, rings, w));
    for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
      ASSERT_NEAR(r.k1[i] * radius, 1.0, 1e-9) << "vertex " << i;
      ASSERT_NEAR(r.k2[i] * radius, 1.0, 1e-9) << "vertex " << i;
      ASSERT_NEAR(r.H[i] * radius, 1.0, 1e-9);
      ASSERT_NEAR(r.K[i] * radius * radius, 1.0, 1e-9);
      ASSERT_EQ(r.class_of(static_cast<int>(i)), PointClass::umbilic);
      ASSERT_LT(r.residual[i], 1e-9);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    AnyTriangulationAndScale, SphereExact,
    ::testing::Combine(::testing::Values(Triangulation::regular, Triangulation::irregular),
                       ::testing::Values(1e-3, 1.0, 1e3), ::testing::Values(1, 2)));

TEST(Curvature, LevenbergMarquardtAlsoExactOnTheSphere) {
  const AnalyticSurface s = surface(SurfaceKind::sphere, Triangulation::irregular, 800, 2.0);
  const CurvatureResult r =
      estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, with(Solver::levenberg_marquardt));
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    ASSERT_NEAR(r.k1[i], 0.5, 1e-9);
    ASSERT_NEAR(r.k2[i], 0.5, 1e-9);
  }
}

// ---- Principal directions: unit, orthogonal, tangent to the vertex normal, (d1, d2, N)
// right-handed, wherever the vertex is defined.
TEST(Curvature, DirectionsAreAnOrthonormalTangentFrame) {
  for (auto kind : {SurfaceKind::torus, SurfaceKind::ellipsoid, SurfaceKind::saddle}) {
    const AnalyticSurface s = surface(kind, Triangulation::irregular, 1500);
    const CurvatureResult r = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
    for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
      if (r.class_of(static_cast<int>(i)) == PointClass::undefined) continue;
      const Eigen::Vector3d d1 = r.d1.row(i), d2 = r.d2.row(i), n = s.mesh.N.row(i);
      EXPECT_NEAR(d1.norm(), 1.0, 1e-12);
      EXPECT_NEAR(d2.norm(), 1.0, 1e-12);
      EXPECT_NEAR(d1.dot(d2), 0.0, 1e-12);
      EXPECT_NEAR(d1.dot(n), 0.0, 1e-12);
      EXPECT_NEAR(d1.cross(d2).dot(n), 1.0, 1e-12);
      EXPECT_GE(r.k1[i], r.k2[i]);
      EXPECT_NEAR(r.H[i], 0.5 * (r.k1[i] + r.k2[i]), 1e-12 * (1 + std::abs(r.H[i])));
      EXPECT_NEAR(r.K[i], r.k1[i] * r.k2[i], 1e-12 * (1 + std::abs(r.K[i])));
    }
  }
}

// ---- Degenerate inputs give flags, not crashes.
TEST(Curvature, FlatPatchIsFlatWithZeroCurvature) {
  const Mesh m = test::flat_grid(6, 0.5);
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    EXPECT_EQ(r.class_of(static_cast<int>(i)), PointClass::flat);
    EXPECT_EQ(r.k1[i], 0.0);
    EXPECT_EQ(r.k2[i], 0.0);
  }
}

TEST(Curvature, SingleTriangleAndIsolatedVertices) {
  Mesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5, 6, 6, 6;  // vertices 3 and 4 are in no face
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  m.N = RowMatrixX3d::Zero(5, 3);
  m.N.col(2).setOnes();
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(r.class_of(i), PointClass::flat);  // two independent rays determine W = 0
    EXPECT_EQ(r.rays_used[i], 2);
  }
  for (int i = 3; i < 5; ++i) {
    EXPECT_EQ(r.class_of(i), PointClass::undefined);
    EXPECT_TRUE(std::isnan(r.k1[i]) && std::isnan(r.k2[i]) && std::isnan(r.H[i]) &&
                std::isnan(r.K[i]) && std::isnan(r.residual[i]) && std::isnan(r.d1(i, 0)));
    EXPECT_EQ(r.rays_used[i], 0);
  }
}

TEST(Curvature, BadNormalsMakeTheirVertexUndefinedAndAreExcludedElsewhere) {
  Mesh m = test::flat_grid(4);
  m.N.row(5) << 0, 0, 0;
  m.N.row(6) << std::nan(""), 0, 1;
  m.N.row(9) << 0, 0, -1;  // flipped: outside every neighbour's hemisphere
  m.N.row(10) *= 3.0;      // not unit: normalised, not an error
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  EXPECT_EQ(r.class_of(5), PointClass::undefined);
  EXPECT_EQ(r.class_of(6), PointClass::undefined);
  EXPECT_EQ(r.class_of(10), PointClass::flat);
  // Vertex 10's neighbours are 5, 6, 9, 11, 14, 15 (grid diagonals run a -> d): 5, 6, 9 are out.
  EXPECT_EQ(r.rays_excluded[10], 3);
  EXPECT_EQ(r.rays_used[10], 3);
  // Vertex 9 (normal -z) sees every neighbour's normal outside its hemisphere: nothing to fit.
  EXPECT_EQ(r.class_of(9), PointClass::undefined);
  EXPECT_EQ(r.rays_excluded[9], 6);
}

TEST(Curvature, InvalidArgumentsThrow) {
  const Mesh m = test::flat_grid(3);
  EXPECT_THROW((void)estimate_curvature(m.V, m.F, m.N.topRows(4)), InvalidInput);
  RowMatrixX3i bad = m.F;
  bad(2, 1) = 9;
  EXPECT_THROW((void)estimate_curvature(m.V, bad, m.N), InvalidInput);
  CurvatureOptions o;
  o.rings = 0;
  EXPECT_THROW((void)estimate_curvature(m.V, m.F, m.N, o), InvalidInput);
  o = {};
  o.zero_tolerance = -1;
  EXPECT_THROW((void)estimate_curvature(m.V, m.F, m.N, o), InvalidInput);
}

// ---- Results do not depend on the thread count (gather per vertex, no atomics).
TEST(Curvature, DeterministicForAnyThreadCount) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::irregular, 3000);
  for (auto method : {Method::vertex, Method::triangle}) {
    CurvatureOptions one, two;
    one.method = two.method = method;
    one.rings = two.rings = 2;
    one.threads = 1;
    two.threads = 2;
    const CurvatureResult a = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, one);
    const CurvatureResult b = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, two);
    EXPECT_TRUE(a.k1.cwiseEqual(b.k1).all());
    EXPECT_TRUE(a.k2.cwiseEqual(b.k2).all());
    EXPECT_TRUE(a.d1.cwiseEqual(b.d1).all());
    EXPECT_TRUE(a.residual.cwiseEqual(b.residual).all());
  }
}

}  // namespace
}  // namespace focal
