// The estimate pipeline (estimate.h): the normals chosen by their source, the estimator run on
// them, and what was done reported; the same fields as the estimator called directly.

#include "focal/curvature/estimate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <utility>

#include "focal/core/error.h"
#include "focal/normals/vertex_normals.h"
#include "test_meshes.h"

namespace focal {
namespace {

bool same(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  }
  return true;
}

bool same(const RowMatrixX3d& a, const RowMatrixX3d& b) {
  return a.rows() == b.rows() &&
         ((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all();
}

Mesh torus(int vertices = 2000) {
  return test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, vertices, 0.0, 5)
      .mesh;
}

EstimateOptions paper() {
  EstimateOptions o;
  o.estimator = Estimator::paper;
  return o;
}

TEST(Estimate, RecommendedIsTheRecommendedEstimator) {
  const Mesh m = torus();
  for (const bool normals : {true, false}) {
    const PreparedMesh p(m.V, m.F, normals ? m.normals() : std::nullopt);
    const Estimate e = estimate(p);
    const RecommendedResult r =
        estimate_curvature_recommended(m.V, m.F, normals ? m.normals() : std::nullopt);
    EXPECT_TRUE(same(e.curvature.H, r.curvature.H));
    ASSERT_TRUE(e.N.has_value());
    EXPECT_TRUE(same(*e.N, r.N));
    EXPECT_FALSE(e.F.has_value());
    EXPECT_EQ(e.plan.rings, r.plan.rings);
    EXPECT_EQ(e.file_normals_used, r.file_normals_used);
    EXPECT_EQ(e.file_normals_used, normals);
  }
}

TEST(Estimate, PaperOnTheMeshNormalsReturnsNoCopyOfThem) {
  const Mesh m = torus();
  const PreparedMesh p(m);
  const Estimate e = estimate(p, paper());
  EXPECT_FALSE(e.N.has_value());
  EXPECT_FALSE(e.F.has_value());
  EXPECT_TRUE(same(e.curvature.K, estimate_curvature(m.V, m.F, m.N).K));
  // The incidence freed for the fit is built again when asked for.
  EXPECT_TRUE(same(vertex_normals(p), vertex_normals(m.V, m.F)));
}

TEST(Estimate, PaperWithoutNormalsTakesThemFromTheFaces) {
  const Mesh m = torus();
  const PreparedMesh p(m.V, m.F);
  const Estimate e = estimate(p, paper());
  ASSERT_TRUE(e.N.has_value());
  const RowMatrixX3d max = vertex_normals(m.V, m.F, NormalWeighting::max);
  EXPECT_TRUE(same(*e.N, max));
  EXPECT_TRUE(same(e.curvature.H, estimate_curvature(m.V, m.F, max).H));
  // Asked for: area weights, also when the mesh has normals.
  EstimateOptions o = paper();
  o.normals = NormalsSource::area;
  o.paper.method = Method::triangle;
  const Estimate a = estimate(PreparedMesh(m), o);
  const RowMatrixX3d area = vertex_normals(m.V, m.F, NormalWeighting::area);
  ASSERT_TRUE(a.N.has_value());
  EXPECT_TRUE(same(*a.N, area));
  EXPECT_TRUE(same(a.curvature.H, estimate_curvature(m.V, m.F, area, o.paper).H));
}

TEST(Estimate, MeshNormalsAreFilledAndNormalised) {
  Mesh m = torus();
  m.N.row(3).setZero();
  m.N.row(8) *= 2.0;
  m.N.row(9) *= 1.0 + 1e-9;  // unit within 1e-6: left alone
  const PreparedMesh p(m);
  for (const Estimator estimator : {Estimator::paper, Estimator::recommended}) {
    EstimateOptions o;
    o.estimator = estimator;
    const PreparedNormals n = prepare_normals(p, o);
    EXPECT_EQ(n.report.filled_normal_count, 1);
    EXPECT_EQ(n.report.rescaled_normal_count, 1);
    EXPECT_FALSE(n.report.normals_against_faces);
    ASSERT_TRUE(n.N.has_value());
    EXPECT_TRUE(same(RowMatrixX3d(n.N->row(3)),
                     RowMatrixX3d(vertex_normals(m.V, m.F, NormalWeighting::max).row(3))));
    EXPECT_NEAR(n.N->row(8).norm(), 1.0, 1e-15);
    EXPECT_TRUE(n.N->row(9) == m.N.row(9));
    const Estimate e = estimate(p, o);
    EXPECT_EQ(e.normals_report.filled_normal_count, 1);
    ASSERT_TRUE(e.N.has_value());
    if (estimator == Estimator::paper) {
      EXPECT_TRUE(same(*e.N, *n.N));
    }
  }
  // Inward normals are reported, and used as they are.
  const Mesh inward{m.V, m.F, -torus().N, {}, {}};
  EXPECT_TRUE(prepare_normals(PreparedMesh(inward), paper()).report.normals_against_faces);
}

TEST(Estimate, InwardFacesAreReversedForNormalsFromThem) {
  Mesh m = torus();
  m.F.col(1).swap(m.F.col(2));  // the whole torus inward
  const PreparedMesh p(m.V, m.F);
  for (const Estimator estimator : {Estimator::paper, Estimator::recommended}) {
    EstimateOptions o;
    o.estimator = estimator;
    const Estimate e = estimate(p, o);
    EXPECT_EQ(e.normals_report.reoriented_component_count, 1);
    ASSERT_TRUE(e.F.has_value());
    const Mesh outward = torus();
    EXPECT_TRUE(*e.F == outward.F);
    EXPECT_TRUE(same(e.curvature.H, estimate(PreparedMesh(outward.V, outward.F), o).curvature.H));
  }
}

TEST(Estimate, IsolatedTrianglesWithoutNormalsAreUndefinedNotFlat) {
  // Two isolated triangles on the unit sphere and one fan of three triangles sharing vertex 6.
  const double s = std::sqrt(0.5);
  RowMatrixX3d V(10, 3);
  V << 1, 0, 0, s, s, 0, s, 0, s, -1, 0, 0, -s, s, 0, -s, 0, s, 0, 0, 1, s, 0, s, 0, s, s, -s, 0, s;
  RowMatrixX3i F(5, 3);
  F << 0, 1, 2, 3, 5, 4, 6, 7, 8, 6, 8, 9, 6, 9, 7;
  for (const EstimateOptions& o : {EstimateOptions{}, paper()}) {
    const PreparedMesh mesh(V, F, std::nullopt);
    const CurvatureResult r = estimate(mesh, o).curvature;
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(r.class_of(i), PointClass::undefined) << i;
      EXPECT_TRUE(std::isnan(r.k1[i]) && std::isnan(r.H[i])) << i;
    }
  }
  // With the exact normals of the sphere the rays of a lone triangle meet: a valid fit, k = 1.
  const RowMatrixX3d N = V.rowwise().normalized();
  const CurvatureResult r = estimate(PreparedMesh(V, F, N), paper()).curvature;
  for (int i = 0; i < 6; ++i) {
    EXPECT_NE(r.class_of(i), PointClass::undefined) << i;
    EXPECT_NEAR(r.k1[i], 1.0, 1e-9) << i;
  }
}

TEST(Estimate, RejectsWhatCannotBeDone) {
  const Mesh m = torus(500);
  const PreparedMesh none(m.V, m.F);
  EstimateOptions o;
  o.normals = NormalsSource::file;
  EXPECT_THROW((void)prepare_normals(none, o), InvalidInput);
  o.normals = NormalsSource::max;  // the recommended estimator chooses its own
  EXPECT_THROW((void)estimate(PreparedMesh(m), o), InvalidInput);
  EstimateOptions bad = paper();
  bad.paper.rings = 0;
  EXPECT_THROW((void)estimate(PreparedMesh(m), bad), InvalidInput);
}

}  // namespace
}  // namespace focal
