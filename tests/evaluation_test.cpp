#include "focal/evaluation/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"

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

/// Rows of a CSV written by write_csv (numbers only after the header).
std::vector<std::vector<double>> read_numbers(const std::filesystem::path& path,
                                              std::string& header) {
  std::ifstream in(path);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::istringstream fields(line);
    for (std::string cell; std::getline(fields, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

std::filesystem::path temporary_folder(const char* name) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The exported case is what the estimators saw, bit for bit, and its interior flags select the
// same vertex set that evaluate() measures, so external tools compute the same metrics.
TEST(Evaluation, ExportedCaseReadsBackExactly) {
  AnalyticSurface s = saddle();
  add_position_noise(s.mesh, 0.1, 7);
  const auto dir = temporary_folder("focal_evaluation_export");
  export_case(dir / "case.ply", dir / "case.truth.csv", s);
  const Mesh back = read_mesh(dir / "case.ply");
  EXPECT_EQ(back.V, s.mesh.V);
  EXPECT_EQ(back.F, s.mesh.F);
  EXPECT_EQ(back.N, s.mesh.N);

  std::string header;
  const auto rows = read_numbers(dir / "case.truth.csv", header);
  EXPECT_EQ(header, "k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,interior");
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(s.mesh.V.rows()));
  int interior = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 11u);
    EXPECT_EQ(rows[i][0], s.k1[static_cast<Eigen::Index>(i)]);  // shortest round-trip form
    EXPECT_EQ(rows[i][2],
              0.5 * (s.k1[static_cast<Eigen::Index>(i)] + s.k2[static_cast<Eigen::Index>(i)]));
    EXPECT_EQ(rows[i][4], s.d1(static_cast<Eigen::Index>(i), 0));
    interior += rows[i][10] == 1.0;
  }
  EXPECT_EQ(interior, evaluate(s, as_estimate(s, 1.0)).interior.vertices);
  std::filesystem::remove_all(dir);
}

// On a closed surface there is no boundary: every vertex is interior.
TEST(Evaluation, InteriorMaskOfAClosedSurfaceIsAllOnes) {
  SurfaceOptions o;
  o.target_vertices = 300;
  const AnalyticSurface sphere = make_surface(o);
  const VectorXu8 mask = interior_mask(static_cast<int>(sphere.mesh.V.rows()), sphere.mesh.F);
  EXPECT_EQ(mask.cast<int>().sum(), sphere.mesh.V.rows());
  EXPECT_THROW((void)interior_mask(3, sphere.mesh.F), InvalidInput);  // F indexes beyond 3
  EXPECT_THROW((void)interior_mask(static_cast<int>(sphere.mesh.V.rows()), sphere.mesh.F, -1),
               InvalidInput);
}

/// A strip of 2 m vertices along x: vertex 2j at (j, 0), 2j+1 at (j, 1), two triangles per cell.
Mesh strip(int m) {
  Mesh mesh;
  mesh.V.resize(2 * m, 3);
  for (int j = 0; j < m; ++j) {
    mesh.V.row(2 * j) << j, 0, 0;
    mesh.V.row(2 * j + 1) << j, 1, 0;
  }
  mesh.F.resize(2 * (m - 1), 3);
  for (int j = 0; j + 1 < m; ++j) {
    mesh.F.row(2 * j) << 2 * j, 2 * j + 2, 2 * j + 3;
    mesh.F.row(2 * j + 1) << 2 * j, 2 * j + 3, 2 * j + 1;
  }
  return mesh;
}

// A strip of 3 cells: 8 vertices, 13 edges. H = +1 on the left two columns, -1 on the right two:
// the bottom, top and diagonal edges of the middle cell change sign, 3 of 13. H h = +-h.
TEST(Evaluation, FieldSmoothnessCountsSignChangesAcrossEdges) {
  const Mesh mesh = strip(4);
  Eigen::VectorXd H(8);
  H << 1, 1, 1, 1, -1, -1, -1, -1;
  const FieldSmoothness s = field_smoothness(mesh.V, mesh.F, H);
  const double h = mean_edge_length(mesh.V, mesh.F);
  EXPECT_EQ(s.vertices, 8);
  EXPECT_EQ(s.undefined, 0);
  EXPECT_EQ(s.edges, 13);  // 3 bottom + 3 top + 3 diagonals + 4 verticals
  EXPECT_EQ(s.sign_changes, 3);
  EXPECT_DOUBLE_EQ(s.sign_change_fraction, 3.0 / 13.0);
  EXPECT_DOUBLE_EQ(s.edge_length, h);
  EXPECT_DOUBLE_EQ(s.min, -h);
  EXPECT_DOUBLE_EQ(s.max, h);
  EXPECT_DOUBLE_EQ(s.variance, h * h);  // +-h with equal counts: mean 0, variance h^2

  H[7] = NAN;  // one undefined vertex: counted, its 3 edges (top, vertical, diagonal) left out
  const FieldSmoothness u = field_smoothness(mesh.V, mesh.F, H);
  EXPECT_EQ(u.undefined, 1);
  EXPECT_EQ(u.edges, 10);
  EXPECT_EQ(u.sign_changes, 3);

  // Round-off around zero is no sign: H = +-1e-12 / h (|H h| = 1e-12 < kSignZero) flips nothing.
  Eigen::VectorXd flat(8);
  flat << 1e-12, -1e-12, 1e-12, -1e-12, -1e-12, 1e-12, -1e-12, 1e-12;
  EXPECT_EQ(field_smoothness(mesh.V, mesh.F, flat / h).sign_changes, 0);
  EXPECT_EQ(field_smoothness(mesh.V, mesh.F, 1e4 * flat / h).sign_changes, 8);  // 1e-8: signs
}

// numpy.percentile's linear interpolation: over H h = 0, 1, ..., 100 (times h), the 1st and 99th
// percentiles are exactly 1 h and 99 h; over 0..9, the 99th is 8.91 h.
TEST(Evaluation, FieldSmoothnessPercentilesInterpolateLikeNumpy) {
  const Mesh mesh = strip(51);  // 102 vertices
  const double h = mean_edge_length(mesh.V, mesh.F);
  Eigen::VectorXd H(102);
  for (int i = 0; i < 102; ++i) H[i] = i <= 100 ? i : NAN;
  const FieldSmoothness s = field_smoothness(mesh.V, mesh.F, H);
  EXPECT_NEAR(s.percentile_1, 1.0 * h, 1e-12);
  EXPECT_NEAR(s.percentile_99, 99.0 * h, 1e-12);
  EXPECT_EQ(s.sign_changes, 0);  // all >= 0: zero is no sign

  const Mesh small = strip(5);
  Eigen::VectorXd G(10);
  for (int i = 0; i < 10; ++i) G[i] = 9 - i;  // order does not matter
  const double g = mean_edge_length(small.V, small.F);
  EXPECT_NEAR(field_smoothness(small.V, small.F, G).percentile_99, 8.91 * g, 1e-12);
}

TEST(Evaluation, FieldSmoothnessRejectsBadInput) {
  const Mesh mesh = strip(3);
  EXPECT_THROW((void)field_smoothness(mesh.V, mesh.F, Eigen::VectorXd::Zero(5)), InvalidInput);
  RowMatrixX3i bad = mesh.F;
  bad(0, 0) = 6;
  EXPECT_THROW((void)field_smoothness(mesh.V, bad, Eigen::VectorXd::Zero(6)), InvalidInput);
  const FieldSmoothness none = field_smoothness(mesh.V, mesh.F, Eigen::VectorXd::Constant(6, NAN));
  EXPECT_EQ(none.undefined, 6);
  EXPECT_TRUE(std::isnan(none.variance));
  EXPECT_TRUE(std::isnan(none.sign_change_fraction));
}

}  // namespace
}  // namespace focal
