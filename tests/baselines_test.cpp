#include "focal/curvature/baselines.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "focal/core/error.h"
#include "focal/surfaces/surfaces.h"
#include "test_meshes.h"

namespace focal {
namespace {

using Estimator = std::function<CurvatureResult(PositionsRef, FacesRef)>;

struct Baseline {
  const char* name;
  Estimator run;
};

std::vector<Baseline> baselines_under_test() {
  return {{"MDSB03", [](PositionsRef V, FacesRef F) { return baselines::meyer_2003(V, F); }},
          {"CSM03",
           [](PositionsRef V, FacesRef F) { return baselines::cohen_steiner_morvan_2003(V, F); }}};
}

AnalyticSurface surface(SurfaceKind kind, Triangulation tri, int vertices, double a = 0) {
  return test::analytic_surface(kind, tri, vertices, a, 42);
}

double rms_k_error(const CurvatureResult& r, const AnalyticSurface& s, const std::vector<int>& at) {
  const double e1 = test::rms_error(r.k1, s.k1, at), e2 = test::rms_error(r.k2, s.k2, at);
  return std::sqrt(0.5 * (e1 * e1 + e2 * e2));
}

// The sphere (radius 1): both baselines are consistent, not exact. On the latitude-longitude
// grid (poles included) the relative RMS error of H was measured at 8.6e-4 (MDSB03) and 1.1e-2
// (CSM03), bounded by 0.02; on irregular triangulations neither converges pointwise (a known
// property of 1-ring cotangent and normal-cycle estimates), measured 3.9e-2 and 7.9e-2, bounded
// by 0.1. The sign convention must match focal's: H > 0 everywhere.
TEST(Baselines, SphereMeanCurvature) {
  for (const Baseline& b : baselines_under_test()) {
    for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
      const AnalyticSurface s = surface(SurfaceKind::sphere, tri, 2000);
      const CurvatureResult r = b.run(s.mesh.V, s.mesh.F);
      std::vector<int> all(static_cast<std::size_t>(s.mesh.V.rows()));
      for (int i = 0; i < static_cast<int>(all.size()); ++i) all[i] = i;
      const Eigen::VectorXd truth = Eigen::VectorXd::Ones(s.mesh.V.rows());
      const double bound = tri == Triangulation::regular ? 0.02 : 0.1;
      EXPECT_LE(test::rms_error(r.H, truth, all), bound) << b.name;
      EXPECT_GT(r.H.minCoeff(), 0.0) << b.name;
    }
  }
}

// The torus on a regular grid: both are second-order accurate there (error ratio 0.26 measured
// for a halved edge length, asserted <= 0.35), and their principal directions are accurate
// (median d1 error 0.04-0.33 degrees measured, bounded by 1).
TEST(Baselines, TorusRegularConvergesAtSecondOrder) {
  for (const Baseline& b : baselines_under_test()) {
    const AnalyticSurface coarse = surface(SurfaceKind::torus, Triangulation::regular, 2000);
    const AnalyticSurface fine = surface(SurfaceKind::torus, Triangulation::regular, 8000);
    const CurvatureResult rc = b.run(coarse.mesh.V, coarse.mesh.F);
    const CurvatureResult rf = b.run(fine.mesh.V, fine.mesh.F);
    const double ec = rms_k_error(rc, coarse, test::interior_vertices(coarse.mesh, 2));
    const double ef = rms_k_error(rf, fine, test::interior_vertices(fine.mesh, 2));
    EXPECT_LE(ef / ec, 0.35) << b.name << " coarse " << ec << " fine " << ef;
    std::vector<double> angles;
    for (Eigen::Index i = 0; i < fine.mesh.V.rows(); ++i) {
      angles.push_back(test::line_angle_degrees(rf.d1.row(i), fine.d1.row(i)));
    }
    std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
    EXPECT_LE(angles[angles.size() / 2], 1.0) << b.name;
  }
}

// The torus, irregular: O(1) error that does not shrink with h (measured 6.6-7.5% of the largest
// curvature 2.5), bounded by 10%; directions within 3 degrees (median; measured 1.5-2.1).
TEST(Baselines, TorusIrregularBounded) {
  for (const Baseline& b : baselines_under_test()) {
    const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::irregular, 4000);
    const CurvatureResult r = b.run(s.mesh.V, s.mesh.F);
    EXPECT_LE(rms_k_error(r, s, test::interior_vertices(s.mesh, 2)), 0.1 * 2.5) << b.name;
    std::vector<double> angles;
    for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
      angles.push_back(test::line_angle_degrees(r.d1.row(i), s.d1.row(i)));
    }
    std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
    EXPECT_LE(angles[angles.size() / 2], 3.0) << b.name;
  }
}

// Orientation comes from the faces: reversing every face reverses the sign of H and k.
TEST(Baselines, ReversedFacesReverseTheSign) {
  const AnalyticSurface s = surface(SurfaceKind::ellipsoid, Triangulation::irregular, 800);
  RowMatrixX3i reversed = s.mesh.F;
  reversed.col(1).swap(reversed.col(2));
  for (const Baseline& b : baselines_under_test()) {
    const CurvatureResult r = b.run(s.mesh.V, s.mesh.F), q = b.run(s.mesh.V, reversed);
    for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
      ASSERT_NEAR(q.H[i], -r.H[i], 1e-9 * (1 + std::abs(r.H[i]))) << b.name;
      ASSERT_NEAR(q.k1[i], -r.k2[i], 1e-9 * (1 + std::abs(r.k2[i]))) << b.name;
    }
  }
}

TEST(Baselines, DeterministicForAnyThreadCountAndRingSize) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::irregular, 3000);
  for (int rings : {1, 2}) {
    CurvatureOptions one, two;
    one.rings = two.rings = rings;
    one.threads = 1;
    two.threads = 2;
    const auto a = baselines::cohen_steiner_morvan_2003(s.mesh.V, s.mesh.F, one);
    const auto b = baselines::cohen_steiner_morvan_2003(s.mesh.V, s.mesh.F, two);
    EXPECT_TRUE(a.k1.cwiseEqual(b.k1).all() && a.d1.cwiseEqual(b.d1).all());
    const auto c = baselines::meyer_2003(s.mesh.V, s.mesh.F, one);
    const auto d = baselines::meyer_2003(s.mesh.V, s.mesh.F, two);
    EXPECT_TRUE(c.k1.cwiseEqual(d.k1).all() && c.d1.cwiseEqual(d.d1).all());
  }
}

TEST(Baselines, DegenerateInputGivesUndefinedNotCrashes) {
  Mesh m = test::flat_grid(4);
  m.V.conservativeResize(m.V.rows() + 1, 3);
  m.V.row(m.V.rows() - 1) << 9, 9, 9;  // isolated vertex
  for (const Baseline& b : baselines_under_test()) {
    const CurvatureResult r = b.run(m.V, m.F);
    EXPECT_EQ(r.class_of(static_cast<int>(m.V.rows()) - 1), PointClass::undefined) << b.name;
    EXPECT_TRUE(std::isnan(r.H[m.V.rows() - 1]));
    EXPECT_EQ(r.class_of(5), PointClass::flat) << b.name;  // interior vertex of the plane
  }
  RowMatrixX3i bad = m.F;
  bad(0, 0) = 99;
  EXPECT_THROW((void)baselines::meyer_2003(m.V, bad), InvalidInput);
  EXPECT_THROW((void)baselines::cohen_steiner_morvan_2003(m.V, bad), InvalidInput);
  CurvatureOptions o;
  o.rings = 0;
  EXPECT_THROW((void)baselines::cohen_steiner_morvan_2003(m.V, m.F, o), InvalidInput);
}

}  // namespace
}  // namespace focal
