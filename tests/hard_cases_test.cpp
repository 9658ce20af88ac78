// The hard cases of `focal eval --suite hard` (issue 16) and the recommended estimator's steps
// for them: the generators (strips, graded density, outliers, spikes, the capped cylinder with
// its creases), the scoring (rings 1-2, creases left out), and value tests of the estimator's
// position noise, robust refit, never-NaN refit and crease handling on analytic truth.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "focal/core/error.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/estimate.h"
#include "focal/curvature/recommended.h"
#include "focal/io/fields_io.h"
#include "focal/evaluation/evaluation.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"

namespace focal {
namespace {

AnalyticSurface surface(SurfaceKind kind, Triangulation t, int vertices, double aspect = 1.0,
                        double grading = 1.0) {
  SurfaceOptions o;
  o.kind = kind;
  o.triangulation = t;
  o.target_vertices = vertices;
  o.aspect = aspect;
  o.grading = grading;
  return make_surface(o);
}

double rel_h(const AnalyticSurface& s, const CurvatureResult& r) {
  return evaluate(s, r).interior.relative_H;
}

int undefined_count(const CurvatureResult& r) {
  int n = 0;
  for (Eigen::Index i = 0; i < r.H.size(); ++i) n += !std::isfinite(r.H[i]);
  return n;
}

TEST(HardCases, CappedCylinderIsClosedWithCreasesExactlyOnTheRims) {
  const AnalyticSurface s = make_capped_cylinder(1.0, 2.0, 2000);
  const Eigen::Index n = s.mesh.V.rows();
  EXPECT_NEAR(static_cast<double>(n), 2000.0, 200.0);
  std::set<std::pair<int, int>> edges;
  for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = s.mesh.F(f, c), b = s.mesh.F(f, (c + 1) % 3);
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  // Closed genus 0: V - E + F = 2, and no boundary.
  EXPECT_EQ(n - static_cast<Eigen::Index>(edges.size()) + s.mesh.F.rows(), 2);
  EXPECT_EQ(interior_mask(static_cast<int>(n), s.mesh.F).cast<int>().sum(), n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d x = s.mesh.V.row(i).transpose();
    const bool rim =
        std::abs(std::abs(x.z()) - 1.0) < 1e-12 && std::abs(x.head<2>().norm() - 1.0) < 1e-12;
    EXPECT_EQ(s.crease[i] != 0, rim) << i;
    const bool cap = std::abs(std::abs(x.z()) - 1.0) < 1e-12 && !rim;
    EXPECT_DOUBLE_EQ(s.k1[i], cap ? 0.0 : 1.0) << i;
    EXPECT_NEAR(s.mesh.N.row(i).norm(), 1.0, 1e-12);
  }
  // Faces turn outward: the signed volume is the cylinder's, pi r^2 h.
  double volume = 0.0;
  for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = s.mesh.V.row(s.mesh.F(f, 0)), b = s.mesh.V.row(s.mesh.F(f, 1)),
                          c = s.mesh.V.row(s.mesh.F(f, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  EXPECT_NEAR(volume, 2.0 * M_PI, 0.02 * 2.0 * M_PI);  // inscribed polygons: below by O(h^2)
  EXPECT_THROW((void)make_capped_cylinder(0.0, 1.0, 100), InvalidInput);
  EXPECT_THROW((void)make_capped_cylinder(1.0, 1.0, 8), InvalidInput);
}

TEST(HardCases, AspectMakesStripsAndGradingMakesDensityRise) {
  // Cylinder strips 1:8 along the axis: edges along z about 8 times those around.
  const AnalyticSurface strips =
      surface(SurfaceKind::cylinder, Triangulation::regular, 2000, 0.125);
  double along = 0.0, around = 1e300;
  for (Eigen::Index f = 0; f < strips.mesh.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d e =
          strips.mesh.V.row(strips.mesh.F(f, (c + 1) % 3)) - strips.mesh.V.row(strips.mesh.F(f, c));
      if (std::abs(e.z()) < 1e-12) around = std::min(around, e.norm());
      if (e.head<2>().norm() < 1e-12) along = std::max(along, e.norm());
    }
  }
  EXPECT_NEAR(along / around, 8.0, 8.0 * 0.15);  // grid sizes are whole numbers
  // Saddle graded 10:1 in u: vertices per area in the last tenth of u over the first, about 10.
  const AnalyticSurface graded =
      surface(SurfaceKind::saddle, Triangulation::irregular, 3000, 1.0, 10.0);
  // Interior vertices only: the boundary curves are sampled at the smallest spacing throughout.
  const VectorXu8 interior =
      interior_mask(static_cast<int>(graded.mesh.V.rows()), graded.mesh.F, 1);
  int first = 0, last = 0;
  for (Eigen::Index i = 0; i < graded.uv.rows(); ++i) {
    first += interior[i] && graded.uv(i, 0) < -0.8;
    last += interior[i] && graded.uv(i, 0) > 0.8;
  }
  // Expected g^0.9 = 7.9 between the two tenths; random sampling: the bound is the order.
  EXPECT_GT(static_cast<double>(last) / first, 5.0);
  EXPECT_LT(static_cast<double>(last) / first, 20.0);
  EXPECT_NEAR(static_cast<double>(graded.mesh.V.rows()), 3000.0, 0.3 * 3000.0);
}

TEST(HardCases, OutlierNormalsAndSpikesTouchTheStatedFraction) {
  const AnalyticSurface clean = surface(SurfaceKind::sphere, Triangulation::irregular, 2000);
  AnalyticSurface outliers = clean, spikes = clean;
  add_outlier_normals(outliers.mesh, 0.02, 7);
  add_spikes(spikes.mesh, 0.005, 2.0, 7);
  const double h = mean_edge_length(clean.mesh.V, clean.mesh.F);
  int changed_normals = 0, moved = 0;
  for (Eigen::Index i = 0; i < clean.mesh.V.rows(); ++i) {
    changed_normals += outliers.mesh.N.row(i) != clean.mesh.N.row(i);
    EXPECT_NEAR(outliers.mesh.N.row(i).norm(), 1.0, 1e-12);
    const Eigen::RowVector3d d = spikes.mesh.V.row(i) - clean.mesh.V.row(i);
    if (d.norm() == 0.0) continue;
    ++moved;
    EXPECT_NEAR(d.norm(), 2.0 * h, 1e-12 * h);
    EXPECT_NEAR(std::abs(d.normalized().dot(clean.mesh.N.row(i))), 1.0, 1e-12);
  }
  EXPECT_EQ(changed_normals, std::lround(0.02 * clean.mesh.V.rows()));
  EXPECT_EQ(moved, std::lround(0.005 * clean.mesh.V.rows()));
  EXPECT_THROW(add_spikes(spikes.mesh, 1.5, 2.0, 1), InvalidInput);
  EXPECT_THROW(add_outlier_normals(spikes.mesh, -0.1, 1), InvalidInput);
}

TEST(HardCases, BoundaryBandAndCreasesScoreTheRightVertices) {
  const AnalyticSurface s = surface(SurfaceKind::saddle, Triangulation::irregular, 1000);
  const int n = static_cast<int>(s.mesh.V.rows());
  const VectorXu8 band = boundary_band_mask(n, s.mesh.F, 1, 2);
  const Eigen::VectorXi distance =
      rings_to_boundary(vertex_adjacency(n, s.mesh.F), boundary_vertices(n, s.mesh.F), 3);
  for (int i = 0; i < n; ++i) EXPECT_EQ(band[i] != 0, distance[i] >= 1 && distance[i] <= 2);
  EXPECT_THROW((void)boundary_band_mask(n, s.mesh.F, 2, 1), InvalidInput);
  // Crease vertices are scored nowhere: a wrong value there changes no metric.
  const AnalyticSurface capped = make_capped_cylinder(1.0, 2.0, 1000);
  CurvatureResult truth =
      estimate_curvature_recommended(capped.mesh.V, capped.mesh.F, capped.mesh.N).curvature;
  const Evaluation before = evaluate(capped, truth);
  for (Eigen::Index i = 0; i < truth.H.size(); ++i) {
    if (capped.crease[i]) truth.H[i] = truth.k1[i] = 1e6;
  }
  const Evaluation after = evaluate(capped, truth);
  EXPECT_EQ(after.interior.relative_H, before.interior.relative_H);
  EXPECT_EQ(after.interior.vertices + after.near_boundary.vertices,
            capped.mesh.V.rows() - capped.crease.cast<int>().sum());
}

// Creases (recommended.h step 5): on the capped cylinder the default must not smear the rims
// into the pieces. Every piece is a plane or a cylinder, on which the fit is exact with exact
// normals (docs/notes/estimator-log.md): 1e-9 is rounding with a wide margin. Before crease handling the
// relative H error was 2.4 (focal eval --suite hard).
TEST(HardCases, CreasesAreFlaggedAndNotSmeared) {
  AnalyticSurface s = make_capped_cylinder(1.0, 2.0, 2000);
  AnalyticSurface noisy_normals = s;
  add_normal_noise(noisy_normals.mesh, 0.05, 3);
  for (const auto& [mesh, with_normals] : {std::pair{&s.mesh, true}, std::pair{&s.mesh, false},
                                           std::pair{&noisy_normals.mesh, true}}) {
    const RecommendedResult r =
        with_normals ? estimate_curvature_recommended(mesh->V, mesh->F, mesh->N)
                     : estimate_curvature_recommended(mesh->V, mesh->F, std::nullopt);
    ASSERT_EQ(r.crease.size(), s.crease.size());
    EXPECT_EQ(r.crease, s.crease);
    for (Eigen::Index i = 0; i < s.k1.size(); ++i) {
      if (s.crease[i]) continue;
      EXPECT_NEAR(r.curvature.H[i], 0.5 * (s.k1[i] + s.k2[i]), 1e-9) << i << " " << with_normals;
    }
  }
  RecommendedOptions off;
  off.crease_angle = 0.0;
  const RecommendedResult smeared =
      estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N, off);
  EXPECT_GT(rel_h(s, smeared.curvature), 0.5);  // measured 2.4: the test above can fail
}

// The crease flags reach the outputs: Estimate::crease (focal curvature, focal.curvature) and
// the `crease` column of the CSV and PLY writers; the paper's estimator has none.
TEST(HardCases, CreaseFlagsReachTheOutputs) {
  const AnalyticSurface s = make_capped_cylinder(1.0, 2.0, 2000);
  const PreparedMesh mesh(s.mesh.V, s.mesh.F, s.mesh.N);
  const Estimate e = estimate(mesh);
  EXPECT_EQ(e.crease, s.crease);
  EstimateOptions paper;
  paper.estimator = Estimator::paper;
  EXPECT_EQ(estimate(mesh, paper).crease.size(), 0);
  // Noisy positions: no crease test, all 0 (not empty: the column is there for every mesh).
  AnalyticSurface noisy = s;
  add_position_noise(noisy.mesh, 0.1, 5);
  const Estimate n = estimate(PreparedMesh(noisy.mesh.V, noisy.mesh.F, noisy.mesh.N));
  ASSERT_GT(n.plan.rings, 1);
  EXPECT_EQ(n.crease, VectorXu8::Zero(s.crease.size()));

  const std::filesystem::path csv =
      std::filesystem::temp_directory_path() / ("focal_crease_" + std::to_string(::getpid()) + ".csv");
  write_curvature_csv(csv, e.curvature, e.crease);
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,residual,class,crease");
  Eigen::Index row = 0, mismatched = 0;
  for (; std::getline(in, line); ++row) {
    mismatched += line.substr(line.rfind(',') + 1) != (s.crease[row] ? "1" : "0");
  }
  EXPECT_EQ(row, s.crease.size());
  EXPECT_EQ(mismatched, 0);
  std::filesystem::remove(csv);
  EXPECT_THROW(write_curvature_csv(csv, e.curvature, VectorXu8::Zero(3)), InvalidInput);
  EXPECT_FALSE(std::filesystem::exists(csv));
}

// The position noise (recommended_plan): the jets' truncation error is not noise. The coarse
// helix tube's 2-ring cubic jets leave 0.08 edge lengths of truncation residual (measured),
// which planned a 3-ring fit (relative H error 0.35 against 0.017 for the per-triangle pass).
TEST(HardCases, PositionNoiseLeavesTruncationOut) {
  const AnalyticSurface coarse = surface(SurfaceKind::helix_tube, Triangulation::irregular, 850);
  const RecommendedPlan plan = recommended_plan(coarse.mesh.V, coarse.mesh.F);
  EXPECT_GT(plan.noise, kNoiseForThreeRings);
  EXPECT_LT(plan.position_noise, kNoiseForTwoRings);
  EXPECT_EQ(plan.rings, 1);
  EXPECT_EQ(recommended_reach(plan), kRecommendedMaxReach);
  // Under the paper's 10% noise both agree (uniform amplitude a: a / sqrt(3) = 0.058; measured
  // 0.055 to 0.058 over five surfaces, regular and irregular).
  AnalyticSurface noisy = surface(SurfaceKind::torus, Triangulation::irregular, 2000);
  add_position_noise(noisy.mesh, 0.1, 2);
  const RecommendedPlan noisy_plan = recommended_plan(noisy.mesh.V, noisy.mesh.F);
  EXPECT_NEAR(noisy_plan.position_noise, noisy_plan.noise, 0.05 * noisy_plan.noise);
  EXPECT_EQ(noisy_plan.rings, 3);
  EXPECT_EQ(recommended_reach(noisy_plan), 12);
}

// Strong vertex noise without normals (issue 16's target: relative H error at most 0.5, no
// NaN). 50% noise folds faces; before the refitted jets, the turn with the neighbours and the
// refit of undefined vertices: sphere 3.3 with 48 undefined vertices, torus 8.1 with 68 (focal
// eval, 4000 vertices); now 0.073 and 0.22 (seed 2 of the noise: 0.095, 0.075). At 2000
// vertices the torus measures 0.72: the target holds at the suite's resolution only.
TEST(HardCases, StrongNoiseWithoutNormalsHasNoNaN) {
  for (const SurfaceKind kind : {SurfaceKind::sphere, SurfaceKind::torus}) {
    AnalyticSurface s = surface(kind, Triangulation::irregular, 4000);  // as focal eval
    add_position_noise(s.mesh, 0.5, 2);
    const RecommendedResult r = estimate_curvature_recommended(s.mesh.V, s.mesh.F, std::nullopt);
    EXPECT_EQ(undefined_count(r.curvature), 0) << surface_name(kind);
    EXPECT_LT(rel_h(s, r.curvature), 0.5) << surface_name(kind);
  }
}

// Robust refit (rays beyond 5 robust scales rejected): wild normals lose their pull. Noisy
// positions with exact file normals of which 2% are random: the error stays within 2.5 times
// that of the case without outliers (measured 0.0137 against 0.0073, 1.9 times).
TEST(HardCases, RobustRefitTakesThePullOfOutlierNormals) {
  AnalyticSurface s = surface(SurfaceKind::sphere, Triangulation::irregular, 2000);
  add_position_noise(s.mesh, 0.1, 2);
  const double clean =
      rel_h(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N).curvature);
  add_outlier_normals(s.mesh, 0.02, 5);
  const double wild =
      rel_h(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N).curvature);
  EXPECT_LT(wild, 2.5 * clean);
}

/// Coarse meshes: the default against the paper's 1-ring fit, with the plan the default makes
/// (docs/notes/estimator-log.md, "Spikes without normals", last paragraph):
/// build/release/tests/hard_cases_test --gtest_also_run_disabled_tests
///   --gtest_filter='*DISABLED_MeasureCoarse*'
TEST(HardCases, DISABLED_MeasureCoarse) {
  for (SurfaceKind k : {SurfaceKind::torus, SurfaceKind::helix_tube}) {
    for (int n : {300, 425, 600, 850}) {
      for (std::uint64_t seed : {1, 2}) {
        const AnalyticSurface a = make_surface(
            {.kind = k, .triangulation = Triangulation::irregular, .target_vertices = n, .seed = seed});
        const auto rel = [&](const CurvatureResult& r) { return evaluate(a, r).interior.relative_H; };
        const RecommendedResult none = estimate_curvature_recommended(a.mesh.V, a.mesh.F, std::nullopt);
        const double def_none = rel(none.curvature);
        std::printf("   plan: rings %d noise %.4f position noise %.4f, creases %d\n", none.plan.rings,
                    none.plan.noise, none.plan.position_noise, none.crease.cast<int>().sum());
        const double def_file =
            rel(estimate_curvature_recommended(a.mesh.V, a.mesh.F, a.mesh.normals()).curvature);
        const double paper_max = rel(estimate_curvature(
            a.mesh.V, a.mesh.F, vertex_normals(a.mesh.V, a.mesh.F, NormalWeighting::max), {}));
        const double paper_file = rel(estimate_curvature(a.mesh.V, a.mesh.F, a.mesh.N, {}));
        std::printf("%-10s %4d (%5d v) seed %d | no normals: default %.4f paper/Max %.4f | file: default %.4f paper %.4f\n",
                    std::string(surface_name(k)).c_str(), n, static_cast<int>(a.mesh.V.rows()),
                    static_cast<int>(seed), def_none, paper_max, def_file, paper_file);
      }
    }
  }
}


}  // namespace
}  // namespace focal
