#include "focal/curvature/curvature.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "focal/core/error.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

using test::interior_vertices;
using test::rms;
using test::rms_error;

AnalyticSurface surface(SurfaceKind kind, Triangulation tri, int vertices, double a = 0) {
  return test::analytic_surface(kind, tri, vertices, a, 42);
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
  o.tolerances.zero = -1;
  EXPECT_THROW((void)estimate_curvature(m.V, m.F, m.N, o), InvalidInput);
}

// ---- Results do not depend on the thread count (gather per vertex, no atomics).
TEST(Curvature, DeterministicForAnyThreadCount) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::irregular, 3000);
  for (auto method : {Method::vertex, Method::triangle}) {
    CurvatureOptions o;
    o.method = method;
    o.rings = 2;
    const auto run = [&] { return estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, o); };
    const CurvatureResult a = test::on_threads(1, run);
    const CurvatureResult b = test::on_threads(2, run);
    EXPECT_TRUE(a.k1.cwiseEqual(b.k1).all());
    EXPECT_TRUE(a.k2.cwiseEqual(b.k2).all());
    EXPECT_TRUE(a.d1.cwiseEqual(b.d1).all());
    EXPECT_TRUE(a.residual.cwiseEqual(b.residual).all());
  }
}

}  // namespace
}  // namespace focal

namespace focal {
namespace {

// ---- Accuracy against analytic truth, with bounds as functions of the mean edge length h.
//
// With exact normals the rays of a vertex satisfy g = W x + q(x), q the second-order term of
// the normal map (size ~ kappa^2 |x|^2 for curvature scale kappa). The least-squares W absorbs
// the first moments of q: on irregular neighbourhoods they do not cancel and the error is
// first order, O(h kappa^2); on the symmetric neighbourhoods of a regular grid the odd moments
// vanish and it is second order, O(h^2 kappa^3). Each case is checked twice: the order, by
// the ratio of errors at ~2000 and ~8000 vertices (h halves: 0.5 for first order, 0.25 for
// second; asserted <= 0.65 and <= 0.35), and the size, by RMS(k error) <= c h kappa^2 resp.
// c h^2 kappa^3, kappa = max |k| over the measured vertices, c measured at 0.03-0.09 (first
// order) and 0.03-0.19 (second order, the pear's fast-varying waist highest) and bounded by
// 0.15 and 0.3.
//
// With normals estimated from faces (Max's weights) on a regular grid the normal error is
// O(h^2) and the same second-order convergence holds. On irregular meshes the estimated
// normals are only first-order accurate; divided by the O(h) ray spacing that is an O(1)
// relative curvature error that does not shrink under refinement (the paper's method needs
// good normals; making it better is the evaluation issue's job). Measured 0.84-3.6% of kappa
// (property rms_over_kappa_*), fine/coarse 0.60-1.02;
// asserted: RMS <= 0.06 kappa at both resolutions and no growth (ratio <= 1.25).

struct AccuracyCase {
  SurfaceKind kind;
  Triangulation triangulation;
  bool estimated_normals;
};

std::string case_name(const ::testing::TestParamInfo<AccuracyCase>& info) {
  std::string s(surface_name(info.param.kind));
  for (char& c : s) c = c == '-' ? '_' : c;
  s += info.param.triangulation == Triangulation::regular ? "_regular" : "_irregular";
  return s + (info.param.estimated_normals ? "_estimated" : "_exact");
}

struct Measured {
  double h = 0, kappa = 0, rms = 0, median_angle = 0;
};

Measured measure(const AccuracyCase& c, int vertices) {
  const AnalyticSurface s = surface(c.kind, c.triangulation, vertices);
  const RowMatrixX3d N =
      c.estimated_normals ? vertex_normals(s.mesh.V, s.mesh.F, NormalWeighting::max) : s.mesh.N;
  const CurvatureResult r = estimate_curvature(s.mesh.V, s.mesh.F, N);
  const std::vector<int> at = interior_vertices(s.mesh, 2);
  Measured m;
  m.h = mean_edge_length(s.mesh.V, s.mesh.F);
  for (int i : at) m.kappa = std::max({m.kappa, std::abs(s.k1[i]), std::abs(s.k2[i])});
  const double e1 = rms_error(r.k1, s.k1, at), e2 = rms_error(r.k2, s.k2, at);
  m.rms = std::sqrt(0.5 * (e1 * e1 + e2 * e2));
  std::vector<double> angles;
  for (int i : at) {
    if (s.k1[i] - s.k2[i] > 0.2 * m.kappa) {  // directions are ill-defined near umbilics
      angles.push_back(test::line_angle_degrees(r.d1.row(i), s.d1.row(i)));
    }
  }
  if (!angles.empty()) {
    std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
    m.median_angle = angles[angles.size() / 2];
  }
  return m;
}

/// True for the grids whose vertex neighbourhoods are point-symmetric (second-order case);
/// the monkey saddle's concentric-ring disc is not.
bool symmetric_grid(const AccuracyCase& c) {
  return c.triangulation == Triangulation::regular && c.kind != SurfaceKind::monkey_saddle;
}

class Accuracy : public ::testing::TestWithParam<AccuracyCase> {};

TEST_P(Accuracy, ErrorBoundedAndConverging) {
  const AccuracyCase c = GetParam();
  const Measured coarse = measure(c, 2000), fine = measure(c, 8000);
  const double ratio = fine.rms / coarse.rms;
  const auto text = [](double x) {
    std::ostringstream s;
    s << std::setprecision(3) << x;
    return s.str();
  };
  RecordProperty("rms_coarse", text(coarse.rms));
  RecordProperty("rms_fine", text(fine.rms));
  RecordProperty("median_d1_angle_fine", text(fine.median_angle));
  // The error as a fraction of the largest curvature (docs/notes/estimator-log.md quotes it for
  // estimated normals on irregular meshes).
  RecordProperty("rms_over_kappa_coarse", text(coarse.rms / coarse.kappa));
  RecordProperty("rms_over_kappa_fine", text(fine.rms / fine.kappa));
  if (coarse.rms < 1e-12) {  // exact up to rounding (cylinder): nothing to converge
    EXPECT_LE(fine.rms, 1e-12);
  } else if (c.estimated_normals && c.triangulation == Triangulation::irregular) {
    EXPECT_LE(coarse.rms, 0.06 * coarse.kappa);
    EXPECT_LE(fine.rms, 0.06 * fine.kappa);
    EXPECT_LE(ratio, 1.25);
  } else if (symmetric_grid(c)) {
    EXPECT_LE(ratio, 0.35) << "coarse " << coarse.rms << " fine " << fine.rms;
    EXPECT_LE(fine.rms, 0.3 * fine.h * fine.h * std::pow(fine.kappa, 3));
  } else {
    EXPECT_LE(ratio, 0.65) << "coarse " << coarse.rms << " fine " << fine.rms;
    EXPECT_LE(fine.rms, 0.15 * fine.h * fine.kappa * fine.kappa);
  }
  // Principal directions away from umbilics: the median d1 error over the fine mesh
  // (measured 0.00-0.7 degrees over all cases).
  EXPECT_LE(fine.median_angle, 2.0);
}

std::vector<AccuracyCase> accuracy_cases() {
  std::vector<AccuracyCase> cases;
  for (auto kind :
       {SurfaceKind::cylinder, SurfaceKind::torus, SurfaceKind::ellipsoid, SurfaceKind::saddle,
        SurfaceKind::monkey_saddle, SurfaceKind::helix_tube, SurfaceKind::pear}) {
    for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
      for (bool estimated : {false, true}) cases.push_back({kind, tri, estimated});
    }
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(AnalyticSurfaces, Accuracy, ::testing::ValuesIn(accuracy_cases()),
                         case_name);

// A cylinder's normal rays all meet its axis: like the sphere, the closed form is exact up to
// rounding with exact normals (k1 = 1/a, k2 = 0). (Max's estimated normals are exact on the
// regular grid too; on irregular meshes they carry the O(1) error discussed above.)
TEST(Curvature, CylinderIsExact) {
  for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
    const AnalyticSurface s = surface(SurfaceKind::cylinder, tri, 2000, 2.0);
    const CurvatureResult r = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
    for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
      ASSERT_NEAR(r.k1[i], 0.5, 1e-9);
      ASSERT_NEAR(r.k2[i], 0.0, 1e-9);
      ASSERT_EQ(r.class_of(static_cast<int>(i)), PointClass::parabolic);
      ASSERT_LT(test::line_angle_degrees(r.d2.row(i), Eigen::Vector3d::UnitZ()), 1e-6);
    }
  }
}

// The paper's solver converges to the closed form's global minimum on smooth surfaces.
TEST(Curvature, LevenbergMarquardtReproducesTheClosedForm) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::irregular, 2000);
  const CurvatureResult cf = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
  const CurvatureResult lm =
      estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, with(Solver::levenberg_marquardt));
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    EXPECT_NEAR(lm.k1[i], cf.k1[i], 1e-7);
    EXPECT_NEAR(lm.k2[i], cf.k2[i], 1e-7);
    EXPECT_LE(cf.residual[i], lm.residual[i] * (1 + 1e-9) + 1e-15);
  }
}

TEST(Curvature, ClassesOnKnownSurfaces) {
  const AnalyticSurface t = surface(SurfaceKind::torus, Triangulation::regular, 4000);
  const CurvatureResult r = estimate_curvature(t.mesh.V, t.mesh.F, t.mesh.N);
  int agree = 0, total = 0;
  for (Eigen::Index i = 0; i < t.mesh.V.rows(); ++i) {
    const double x = std::hypot(t.mesh.V(i, 0), t.mesh.V(i, 1));
    if (std::abs(x - 1.0) < 0.1) continue;  // near the parabolic circles (top and bottom)
    ++total;
    agree += r.class_of(static_cast<int>(i)) ==
             (x > 1.0 ? PointClass::elliptic : PointClass::hyperbolic);
  }
  EXPECT_EQ(agree, total);
}

}  // namespace
}  // namespace focal
