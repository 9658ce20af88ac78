#include "focal/triangle_curvature.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "focal/error.h"
#include "focal/surfaces.h"
#include "test_meshes.h"

namespace focal {
namespace {

AnalyticSurface surface(SurfaceKind kind, Triangulation tri, int vertices, double a = 0) {
  SurfaceOptions o;
  o.kind = kind;
  o.triangulation = tri;
  o.target_vertices = vertices;
  o.a = a;
  o.seed = 7;
  return make_surface(o);
}

// On a sphere the three rays of any triangle meet in the centre: G = X / r exactly, so
// A = C / r^2 and B = 2 C / r (eq. 7), i.e. K = 1/r^2 and H = 1/r up to rounding (eq. 9).
TEST(TriangleCurvature, SpherePerFaceIsExact) {
  for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
    for (double r : {1e-2, 1.0, 1e2}) {
      const AnalyticSurface s = surface(SurfaceKind::sphere, tri, 1000, r);
      const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
      for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
        ASSERT_NEAR(t.K[f] * r * r, 1.0, 1e-9) << "face " << f;
        ASSERT_NEAR(t.H[f] * r, 1.0, 1e-9) << "face " << f;
        ASSERT_NEAR(t.lambda1[f] / r, -1.0, 1e-9);  // focal depth: the centre, r below
        ASSERT_EQ(static_cast<PointClass>(t.point_class[f]), PointClass::umbilic);
      }
    }
  }
}

TEST(TriangleCurvature, SphereVertexAverageIsExact) {
  const AnalyticSurface s = surface(SurfaceKind::sphere, Triangulation::irregular, 1000, 3.0);
  CurvatureOptions o;
  o.method = Method::triangle;
  const CurvatureResult r = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, o);
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    ASSERT_NEAR(r.k1[i] * 3.0, 1.0, 1e-9);
    ASSERT_NEAR(r.k2[i] * 3.0, 1.0, 1e-9);
  }
}

// All normals of a cylinder are perpendicular to its axis, and so is each face's mean normal:
// every (sigma, tau) lies on one line through the origin, the columns of G are parallel and
// A = det G vanishes up to rounding. One focal sheet is at infinity: parabolic (paper 4.3).
TEST(TriangleCurvature, CylinderFacesAreParabolic) {
  for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
    const AnalyticSurface s = surface(SurfaceKind::cylinder, tri, 1500, 2.0);
    const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
    for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
      ASSERT_EQ(static_cast<PointClass>(t.point_class[f]), PointClass::parabolic) << "face " << f;
      ASSERT_TRUE(std::isinf(t.lambda2[f]) || std::abs(t.lambda2[f]) > 1e6);
    }
  }
}

// The roots of A l^2 + B l + C are the focal depths -1/k (eq. 6-8).
TEST(TriangleCurvature, FocalDepthsSolveTheCharacteristicEquation) {
  const AnalyticSurface s = surface(SurfaceKind::ellipsoid, Triangulation::irregular, 1500);
  const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
  for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
    for (double l : {t.lambda1[f], t.lambda2[f]}) {
      const double scale = std::abs(t.A[f]) * l * l + std::abs(t.B[f] * l) + std::abs(t.C[f]);
      EXPECT_LE(std::abs(t.A[f] * l * l + t.B[f] * l + t.C[f]), 1e-9 * scale) << "face " << f;
    }
  }
}

// Appendix B, Lemma 2: the two slits are perpendicular; both lie in the face's tangent plane.
// Exact for a symmetric discrete shape operator; with the exact normals of a smooth surface M is
// symmetric up to O(h), so the cosine between the slits is O(h) (h ~ 0.05 here).
TEST(TriangleCurvature, SlitsArePerpendicular) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::regular, 4000);
  const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
  std::vector<double> cosines;
  for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = t.slit1.row(f), b = t.slit2.row(f), n = t.face_normal.row(f);
    EXPECT_NEAR(a.norm(), 1.0, 1e-12);
    EXPECT_NEAR(a.dot(n), 0.0, 1e-12);
    cosines.push_back(std::abs(a.dot(b)));
  }
  std::nth_element(cosines.begin(), cosines.begin() + cosines.size() / 2, cosines.end());
  EXPECT_LT(cosines[cosines.size() / 2], 0.05);
}

TEST(TriangleCurvature, DegenerateFacesAreUndefined) {
  Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0;
  m.F.resize(3, 3);
  m.F << 0, 1, 2,  // collinear: C = 0
      0, 1, 1,     // repeated index
      0, 1, 3;     // fine
  m.N = RowMatrixX3d::Zero(4, 3);
  m.N.col(2).setOnes();
  const TriangleCurvatureResult t = triangle_curvature(m.V, m.F, m.N);
  EXPECT_EQ(static_cast<PointClass>(t.point_class[0]), PointClass::undefined);
  EXPECT_TRUE(std::isnan(t.K[0]));
  EXPECT_EQ(static_cast<PointClass>(t.point_class[1]), PointClass::undefined);
  EXPECT_EQ(static_cast<PointClass>(t.point_class[2]), PointClass::flat);
  EXPECT_EQ(t.K[2], 0.0);
}

TEST(TriangleCurvature, InvalidArgumentsThrow) {
  const Mesh m = test::flat_grid(3);
  EXPECT_THROW((void)triangle_curvature(m.V, m.F, m.N.topRows(2)), InvalidInput);
  RowMatrixX3i bad = m.F;
  bad(0, 0) = -1;
  EXPECT_THROW((void)triangle_curvature(m.V, bad, m.N), InvalidInput);
}

}  // namespace
}  // namespace focal
