#include "focal/curvature/focal_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "focal/core/error.h"
#include "focal/curvature/curvature.h"
#include "focal/surfaces/surfaces.h"
#include "test_meshes.h"

namespace focal {
namespace {

AnalyticSurface surface(SurfaceKind kind, Triangulation tri, int vertices, double a = 0) {
  return test::analytic_surface(kind, tri, vertices, a, 3);
}

/// A CurvatureResult holding the exact principal curvatures of an analytic surface.
CurvatureResult exact(const AnalyticSurface& s) {
  CurvatureResult r;
  r.k1 = s.k1;
  r.k2 = s.k2;
  r.d1 = s.d1;
  r.d2 = s.d2;
  return r;
}

Eigen::Vector3d face_normal(const Mesh& m, Eigen::Index f) {
  const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
  return (b - a).cross(c - a).normalized();
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(FocalMesh, SphereFocalPointsAreTheCentre) {
  SurfaceOptions o;
  o.a = 2.0;
  o.target_vertices = 500;
  const AnalyticSurface s = make_surface(o);
  const CurvatureResult c = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
  const FocalMeshes f = focal_meshes(s.mesh.V, s.mesh.F, s.mesh.N, c);
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    EXPECT_LT(f.gamma1.mesh.V.row(i).norm(), 1e-9);
    EXPECT_LT(f.gamma2.mesh.V.row(i).norm(), 1e-9);
    EXPECT_EQ(f.gamma1.flag[i], 0);
  }
  EXPECT_EQ(f.gamma1.mesh.F, s.mesh.F);  // the base mesh's connectivity
}

// Both focal sets of a torus degenerate to curves: Gamma_1 (k1 = 1/b) is the core circle of
// radius a in the plane z = 0, Gamma_2 lies on the axis of revolution.
TEST(FocalMesh, TorusFocalSetsAreTheCoreCircleAndTheAxis) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::irregular, 3000);
  const FocalMeshes f = focal_meshes(s.mesh.V, s.mesh.F, s.mesh.N, exact(s));
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    const Eigen::Vector3d g1 = f.gamma1.mesh.V.row(i), g2 = f.gamma2.mesh.V.row(i);
    EXPECT_NEAR(std::hypot(g1.x(), g1.y()), 1.0, 1e-9);  // default major radius a = 1
    EXPECT_NEAR(g1.z(), 0.0, 1e-9);
    if (f.gamma2.flag[i] == 0) {
      EXPECT_LT(std::hypot(g2.x(), g2.y()), 1e-9);
    }
  }
}

// Paper Property 2 (Appendix A): the normal of Gamma_1 is d1, and the base normal is tangent to
// Gamma_1 (Property 1). Checked on the ellipsoid, whose focal sheets are genuine surfaces
// (the torus's are curves, see above). The faces of a piecewise-linear focal mesh approximate
// the tangent plane to O(h) away from the cuspidal edges of the focal sheets, so the median
// angle over all faces is small while single faces near cusps are not: 5 degrees bounds the
// median at this resolution (h ~ 0.04).
TEST(FocalMesh, FocalMeshNormalIsThePrincipalDirection) {
  const AnalyticSurface s = surface(SurfaceKind::ellipsoid, Triangulation::regular, 6000);
  const FocalMeshes f = focal_meshes(s.mesh.V, s.mesh.F, s.mesh.N, exact(s));
  std::vector<double> to_d1, to_normal;
  for (Eigen::Index t = 0; t < s.mesh.F.rows(); ++t) {
    const Eigen::Vector3d n = face_normal(f.gamma1.mesh, t);
    if (!n.allFinite()) continue;
    for (int c = 0; c < 3; ++c) {
      const int v = s.mesh.F(t, c);
      to_d1.push_back(test::line_angle_degrees(n, s.d1.row(v)));
      to_normal.push_back(90.0 - test::line_angle_degrees(n, s.mesh.N.row(v)));
    }
  }
  EXPECT_LT(median(to_d1), 5.0);
  EXPECT_LT(median(to_normal), 5.0);
}

TEST(FocalMesh, PointsAtInfinityAreFlaggedClampedAndOptionallyDropped) {
  const AnalyticSurface s = surface(SurfaceKind::cylinder, Triangulation::regular, 800);
  FocalMeshOptions o;
  o.max_distance = 50.0;
  const FocalMeshes kept = focal_meshes(s.mesh.V, s.mesh.F, s.mesh.N, exact(s), o);
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    EXPECT_EQ(kept.gamma1.flag[i], 0);
    EXPECT_EQ(kept.gamma2.flag[i], 1);  // k2 = 0 exactly
    EXPECT_NEAR((kept.gamma2.mesh.V.row(i) - s.mesh.V.row(i)).norm(), 50.0, 1e-9);
  }
  EXPECT_EQ(kept.gamma2.mesh.F.rows(), s.mesh.F.rows());
  o.drop_faces_at_infinity = true;
  const FocalMeshes dropped = focal_meshes(s.mesh.V, s.mesh.F, s.mesh.N, exact(s), o);
  EXPECT_EQ(dropped.gamma2.mesh.F.rows(), 0);
  EXPECT_EQ(dropped.gamma1.mesh.F.rows(), s.mesh.F.rows());
}

TEST(FocalMesh, UndefinedCurvatureKeepsTheBaseVertexAndIsFlagged) {
  const Mesh m = test::flat_grid(3);
  CurvatureResult c;
  c.k1 = Eigen::VectorXd::Constant(9, 0.5);
  c.k2 = Eigen::VectorXd::Constant(9, 0.25);
  c.k1[4] = std::nan("");
  const FocalMeshes f = focal_meshes(m.V, m.F, m.N, c);
  EXPECT_EQ(f.gamma1.flag[4], 2);
  EXPECT_EQ(f.gamma1.mesh.V.row(4), m.V.row(4));
  EXPECT_NEAR(f.gamma1.mesh.V(0, 2), -2.0, 1e-15);  // S - N / k1 with N = +z, k1 = 0.5
  EXPECT_NEAR(f.gamma2.mesh.V(0, 2), -4.0, 1e-15);
  c.k2.resize(3);
  EXPECT_THROW((void)focal_meshes(m.V, m.F, m.N, c), InvalidInput);
}

}  // namespace
}  // namespace focal
