// Jet normals and jet curvature (normals/jets.h): exactness where the polynomial model is
// exact, measured convergence orders on irregular meshes, noise estimate, determinism, errors.
#include "focal/normals/jets.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/curvature/normal_rays.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"
#include "normals/jet_points.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

AnalyticSurface irregular(SurfaceKind kind, int vertices) {
  SurfaceOptions o;
  o.kind = kind;
  o.triangulation = Triangulation::irregular;
  o.target_vertices = vertices;
  return make_surface(o);
}

double rms_angle(const RowMatrixX3d& a, const RowMatrixX3d& b) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const double t = std::acos(std::min(1.0, a.row(i).dot(b.row(i))));
    sum += t * t;
  }
  return std::sqrt(sum / static_cast<double>(a.rows()));
}

JetOptions jet(int degree, int rings = 2) {
  JetOptions o;
  o.degree = degree;
  o.rings = rings;
  o.iterations = 1;
  return o;
}

TEST(JetNormals, ExactOnATiltedPlaneAndResidualZero) {
  SurfaceOptions o;
  o.kind = SurfaceKind::saddle;
  o.triangulation = Triangulation::irregular;
  o.target_vertices = 500;
  Mesh m = make_surface(o).mesh;
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    m.V(i, 2) = -(n.x() * m.V(i, 0) + n.y() * m.V(i, 1)) / n.z();
  for (int degree : {1, 2, 3, 4}) {
    const JetNormals j = jet_normals(m.V, m.F, jet(degree));
    for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
      ASSERT_NEAR((j.N.row(i).transpose() - n).norm(), 0.0, 1e-12) << "degree " << degree;
      ASSERT_FALSE(j.residual[i] > 1e-12);  // NaN where the points just determine the fit
    }
  }
}

// Normal error (RMS angle to the exact normals) at about 2000 and 8000 vertices; the order is
// log(e1 / e2) / log(h1 / h2). Measured: Max 1.01 (torus), 1.18 (ellipsoid); quadratic jets 2.04,
// 2.01; cubic jets 3.10, 3.11.
double measured_order(SurfaceKind kind, int degree) {
  double e[2], h[2];
  for (int k = 0; k < 2; ++k) {
    const AnalyticSurface s = irregular(kind, k == 0 ? 2000 : 8000);
    const RowMatrixX3d N = degree == 0 ? vertex_normals(s.mesh.V, s.mesh.F, NormalWeighting::max)
                                       : jet_normals(s.mesh.V, s.mesh.F, jet(degree)).N;
    e[k] = rms_angle(N, s.mesh.N);
    h[k] = mean_edge_length(s.mesh.V, s.mesh.F);
  }
  return std::log(e[0] / e[1]) / std::log(h[0] / h[1]);
}

/// The plain jet of vertex i, the reference of jets.cpp's hand-written LDL^T: the same least
/// squares problem (the vertex and its k-ring as offsets in the frame of start normal n, scaled
/// by the largest, heights over the full polynomial of the degree) solved by Eigen's LDLT of the
/// normal equations. Its normal, and the bound on how far another backward-stable solve of the
/// same problem may lie from it: forming A^T A and solving it perturb the system by a relative
/// (points + coefficients) eps each, which the condition number of A^T A amplifies, for each of
/// the two solves.
struct PlainJet {
  Eigen::Vector3d normal;
  double bound;
};

PlainJet plain_jet(const RowMatrixX3d& V, const Neighbourhoods& ring, int i,
                   const Eigen::Vector3d& n, int degree) {
  const TangentFrame f = tangent_frame(n);
  std::vector<Eigen::Vector3d> q{Eigen::Vector3d::Zero()};
  double scale = 0.0;
  for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
    q.push_back((V.row(*j) - V.row(i)).transpose());
    scale = std::max(scale, q.back().norm());
  }
  const int m = (degree + 1) * (degree + 2) / 2;
  const auto points = static_cast<Eigen::Index>(q.size());
  Eigen::MatrixXd A(points, m);
  Eigen::VectorXd z(points);
  for (Eigen::Index p = 0; p < points; ++p) {
    const double x = f.x.dot(q[p]) / scale, y = f.y.dot(q[p]) / scale;
    z[p] = f.n.dot(q[p]) / scale;
    int k = 0;  // x^a y^b by total degree: 1, x, y, x^2, ...
    for (int t = 0; t <= degree; ++t) {
      for (int b = 0; b <= t; ++b) A(p, k++) = std::pow(x, t - b) * std::pow(y, b);
    }
  }
  const Eigen::MatrixXd normal_matrix = A.transpose() * A;
  const Eigen::VectorXd c = normal_matrix.ldlt().solve(A.transpose() * z);
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(normal_matrix).singularValues();
  const double condition = s[0] / s[s.size() - 1];
  constexpr double eps = std::numeric_limits<double>::epsilon();
  // The normal (-z_x, -z_y, 1) / |.| moves by at most |d(z_x, z_y)| <= |dc|.
  return {(f.n - c[1] * f.x - c[2] * f.y).normalized(),
          2.0 * static_cast<double>(points + m) * eps * condition * c.norm()};
}

// jets.cpp solves the normal equations by a hand-written, unrolled LDL^T in lanes (in Eigen's
// LDLT's pivot order); Eigen's own LDLT is the plain reference it is tested against, one fit (in
// the frame of the start normals) at every vertex fitted with the full degree, within the bound
// of two backward-stable solves of the same system (PlainJet; measured at most 0.01 of it).
TEST(JetNormals, TheHandWrittenSolveMatchesEigensLdlt) {
  for (const SurfaceKind kind : {SurfaceKind::ellipsoid, SurfaceKind::saddle}) {
    const AnalyticSurface s = irregular(kind, 1500);
    const Neighbourhoods one = vertex_adjacency(static_cast<int>(s.mesh.V.rows()), s.mesh.F);
    const RowMatrixX3d start = vertex_normals(s.mesh.V, s.mesh.F, NormalWeighting::max);
    for (const int degree : {2, 3}) {
      const JetOptions o = jet(degree);
      const Neighbourhoods ring = k_ring(one, o.rings);
      const JetNormals j = jet_normals(s.mesh.V, s.mesh.F, one, start, o);
      int compared = 0;
      double worst = 0.0;
      for (int i = 0; i < s.mesh.V.rows(); ++i) {
        if (j.degree[i] != degree) continue;
        const PlainJet plain = plain_jet(s.mesh.V, ring, i, start.row(i).transpose(), degree);
        const double gap = (plain.normal - j.N.row(i).transpose()).norm();
        ASSERT_LE(gap, plain.bound) << "vertex " << i << ", degree " << degree;
        worst = std::max(worst, gap / plain.bound);
        ++compared;
      }
      EXPECT_GT(compared, s.mesh.V.rows() * 9 / 10) << "degree " << degree;
      RecordProperty("worst_ratio_surface_" + std::to_string(static_cast<int>(kind)) + "_degree_" +
                         std::to_string(degree),
                     std::to_string(worst));
    }
  }
}

TEST(JetNormals, OrderOfAccuracyOnIrregularMeshesIsTheDegree) {
  for (SurfaceKind kind : {SurfaceKind::torus, SurfaceKind::ellipsoid}) {
    const double max = measured_order(kind, 0), quadratic = measured_order(kind, 2),
                 cubic = measured_order(kind, 3);
    EXPECT_LT(max, 1.4) << surface_name(kind);  // first order: why jets exist
    EXPECT_GT(quadratic, 1.8) << surface_name(kind);
    EXPECT_GT(cubic, 2.8) << surface_name(kind);
  }
}

TEST(JetNormals, ResidualMeasuresNoiseNormalToTheSurface) {
  // Uniform noise of amplitude a along the normal has standard deviation a / sqrt(3).
  AnalyticSurface s = irregular(SurfaceKind::sphere, 4000);
  const double h = mean_edge_length(s.mesh.V, s.mesh.F), a = 0.1 * h;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-a, a);
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) s.mesh.V.row(i) += u(rng) * s.mesh.N.row(i);
  const JetNormals j = jet_normals(s.mesh.V, s.mesh.F, jet(3));
  std::vector<double> r(j.residual.data(), j.residual.data() + j.residual.size());
  std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
  EXPECT_NEAR(r[r.size() / 2] / (a / std::sqrt(3.0)), 1.0, 0.1);
}

// Cubic jets over 2 rings and quadratic jets over 4 (the recommended estimator's two kinds).
TEST(JetNormals, OrientedLikeTheFacesAndDeterministic) {
  const AnalyticSurface s = irregular(SurfaceKind::torus, 3000);
  for (JetOptions o : {jet(3), jet(2, 4)}) {
    const auto run = [&] { return jet_normals(s.mesh.V, s.mesh.F, o); };
    const JetNormals one = test::on_threads(1, run);
    const JetNormals three = test::on_threads(3, run);
    EXPECT_TRUE(one.N == three.N) << o.rings << " rings";
    const auto a = one.residual.array(), b = three.residual.array();
    EXPECT_TRUE((a == b || (a.isNaN() && b.isNaN())).all()) << o.rings << " rings";
    EXPECT_TRUE(one.degree == three.degree) << o.rings << " rings";
    for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i)
      ASSERT_GT(one.N.row(i).dot(s.mesh.N.row(i)), 0.99) << o.rings << " rings, vertex " << i;
  }
}

TEST(JetNormals, GivenStartNormalsGiveTheSameResultAndAreValidated) {
  const AnalyticSurface s = irregular(SurfaceKind::ellipsoid, 3000);
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(s.mesh.V.rows()), s.mesh.F);
  const RowMatrixX3d max = vertex_normals(s.mesh.V, s.mesh.F, NormalWeighting::max);
  for (const JetOptions& o : {jet(3), jet(2, 3), jet(4, 1)}) {
    const JetNormals a = jet_normals(s.mesh.V, s.mesh.F, one, o);
    const JetNormals b = jet_normals(s.mesh.V, s.mesh.F, one, max, o);
    EXPECT_TRUE(a.N == b.N);
    EXPECT_TRUE(a.residual.cwiseEqual(b.residual).count() + a.residual.array().isNaN().count() ==
                a.residual.size());
    EXPECT_TRUE(a.degree == b.degree);
  }
  // Exact normals as the start: a different frame, the same surface to rounding of the fit.
  const JetNormals exact = jet_normals(s.mesh.V, s.mesh.F, one, s.mesh.N, jet(3));
  EXPECT_LT(rms_angle(exact.N, jet_normals(s.mesh.V, s.mesh.F, one, jet(3)).N), 1e-3);
  EXPECT_THROW((void)jet_normals(s.mesh.V, s.mesh.F, one, max.topRows(10), jet(3)), InvalidInput);
  RowMatrixX3d scaled = max;
  scaled.row(7) *= 2.0;
  EXPECT_THROW((void)jet_normals(s.mesh.V, s.mesh.F, one, scaled, jet(3)), InvalidInput);
  scaled.row(7).setConstant(std::numeric_limits<double>::quiet_NaN());  // allowed: no jet there
  const JetNormals nan_start = jet_normals(s.mesh.V, s.mesh.F, one, scaled, jet(3));
  EXPECT_EQ(nan_start.degree[7], 0);
  EXPECT_TRUE(std::isnan(nan_start.N(7, 0)));
}

TEST(JetNormals, LowersTheDegreeOnSmallNeighbourhoodsAndFlagsIsolatedVertices) {
  RowMatrixX3d V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.1, 5, 5, 5;  // vertex 4 is in no face
  RowMatrixX3i F(2, 3);
  F << 0, 1, 2, 1, 3, 2;
  const JetNormals j = jet_normals(V, F, jet(3));
  for (int i = 0; i < 4; ++i) {
    EXPECT_GE(j.degree[i], 1);
    EXPECT_LT(j.degree[i], 3);  // 4 points cannot carry 10 coefficients
    EXPECT_GT(j.N(i, 2), 0.9);
  }
  EXPECT_EQ(j.degree[4], 0);
  EXPECT_TRUE(std::isnan(j.N(4, 0)));
}

TEST(JetNormals, RejectsInvalidOptions) {
  const AnalyticSurface s = irregular(SurfaceKind::sphere, 200);
  for (auto bad : {
           [] {
             JetOptions o;
             o.rings = 0;
             return o;
           }(),
           [] {
             JetOptions o;
             o.degree = 5;
             return o;
           }(),
           [] {
             JetOptions o;
             o.degree = 0;
             return o;
           }(),
           [] {
             JetOptions o;
             o.iterations = 0;
             return o;
           }(),
       }) {
    EXPECT_THROW((void)jet_normals(s.mesh.V, s.mesh.F, bad), InvalidInput);
  }
  RowMatrixX3i F(1, 3);
  F << 0, 1, 100000;
  EXPECT_THROW((void)jet_normals(s.mesh.V, F), InvalidInput);
  EXPECT_THROW((void)jet_curvature(s.mesh.V, s.mesh.F, jet(1)), InvalidInput);
}

TEST(JetCurvature, SphereOfRadiusTwoAndSigns) {
  SurfaceOptions o;
  o.kind = SurfaceKind::sphere;
  o.triangulation = Triangulation::irregular;
  o.target_vertices = 3000;
  o.a = 2.0;
  const AnalyticSurface s = make_surface(o);
  const CurvatureResult r = jet_curvature(s.mesh.V, s.mesh.F, jet(3));
  double worst = 0.0;
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    worst = std::max({worst, std::abs(r.k1[i] - 0.5), std::abs(r.k2[i] - 0.5)});
    ASSERT_NEAR(r.d1.row(i).cross(r.d2.row(i)).dot(s.mesh.N.row(i)), 1.0, 1e-6);
  }
  EXPECT_LT(worst, 0.01);  // measured 2.2e-3 (cubic jets over the 2-ring)
}

// The jets' neighbourhoods (jet_points.h): v and its k-ring, ascending, as k_ring lists them;
// only v where the k-ring is over kMaxNeighbourhoodSize (k_ring's empty list). A fan of 3,072
// rim vertices puts every rim vertex's 2-ring over the cap and gives the centre a 1-ring of
// 3,072; a grid beside it (another component) has rings within the cap; `sort_rows` reversed
// sorts by row.
TEST(Jets, GatheredRingsAreTheKRingsWithTheirCentre) {
  constexpr int kRim = 3072;
  const Mesh grid = test::flat_grid(20);
  const auto g = static_cast<int>(grid.V.rows());
  RowMatrixX3i F(kRim + grid.F.rows(), 3);
  for (int i = 0; i < kRim; ++i) F.row(i) << 0, 1 + i, 1 + (i + 1) % kRim;
  F.bottomRows(grid.F.rows()) = (grid.F.array() + (kRim + 1)).matrix();
  const int n = kRim + 1 + g;
  const Neighbourhoods one = vertex_adjacency(n, F);
  std::vector<int> reversed(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) reversed[static_cast<std::size_t>(v)] = n - 1 - v;
  for (const int rings : {1, 2, 3}) {
    const Neighbourhoods k = k_ring(one, rings);
    std::vector<std::uint64_t> marks;
    std::vector<int> ring, sorted;
    for (int v = 0; v < n; ++v) {
      std::vector<int> expected(k.begin(v), k.end(v));
      expected.push_back(v);
      std::sort(expected.begin(), expected.end());
      detail::jets::gather_ring(one, v, rings, marks, nullptr, ring);
      ASSERT_EQ(ring, expected) << "vertex " << v << ", " << rings << " rings";
      detail::jets::gather_ring(one, v, rings, marks, &reversed, sorted);
      std::reverse(expected.begin(), expected.end());
      ASSERT_EQ(sorted, expected) << "vertex " << v << ", " << rings << " rings, by row";
    }
    // Every mark is cleared after each ring: none is left set.
    EXPECT_TRUE(std::all_of(marks.begin(), marks.end(), [](std::uint64_t w) { return w == 0; }));
  }
  EXPECT_EQ(k_ring(one, 2).size(1), 0) << "the rim's 2-rings are over the cap";
}

}  // namespace
}  // namespace focal
