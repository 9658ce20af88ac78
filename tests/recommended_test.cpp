// The recommended estimator (recommended.h): measured accuracy against the paper's method on the
// irregular and noisy cases of the evaluation suite, exactness on spheres, the noise plan,
// determinism, boundaries and undefined vertices. DISABLED_SuiteTable prints the table of
// docs/notes/estimator-log.md ("The recommended estimator").
#include "focal/curvature/recommended.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "focal/core/error.h"
#include "focal/curvature/baselines.h"
#include "focal/curvature/estimate.h"
#include "focal/evaluation/evaluation.h"
#include "focal/normals/jets.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"
#include "test_threads.h"

namespace focal {
namespace {

enum class Noise { clean, positions, normals };

/// A case of `focal eval`: about 4000 vertices, seed 1, the paper's noise (cli/eval_cases.cpp).
AnalyticSurface suite_case(SurfaceKind kind, Triangulation t, Noise noise, int vertices = 4000) {
  SurfaceOptions o;
  o.kind = kind;
  o.triangulation = t;
  o.target_vertices = vertices;
  o.seed = 1;
  AnalyticSurface s = make_surface(o);
  if (noise == Noise::positions) add_position_noise(s.mesh, 0.1, 2);
  if (noise == Noise::normals) add_normal_noise(s.mesh, 0.05, 3);
  return s;
}

/// Relative RMS error of H over the interior. Unless `may_be_undefined` (an estimator on corrupted
/// normals), every interior vertex must have an estimate (the suite's surfaces are smooth and
/// free of bad geometry), which relative_H alone would not show.
double rel_h(const AnalyticSurface& s, const CurvatureResult& r, bool may_be_undefined = false) {
  const ErrorMetrics e = evaluate(s, r).interior;
  if (!may_be_undefined) {
    EXPECT_EQ(e.undefined, 0);
  }
  return e.relative_H;
}

double paper_file(const AnalyticSurface& s) {
  return rel_h(s, estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N));
}
double paper_max(const AnalyticSurface& s) {
  const RowMatrixX3d n = vertex_normals(s.mesh.V, s.mesh.F, NormalWeighting::max);
  return rel_h(s, estimate_curvature(s.mesh.V, s.mesh.F, n));
}
double recommended_file(const AnalyticSurface& s) {
  return rel_h(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N).curvature);
}
double recommended_none(const AnalyticSurface& s) {
  return rel_h(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, std::nullopt).curvature);
}

constexpr auto irregular = Triangulation::irregular;

TEST(Recommended, ExactOnSpheresWithAndWithoutNormals) {
  for (auto t : {Triangulation::regular, irregular}) {
    const AnalyticSurface s = suite_case(SurfaceKind::sphere, t, Noise::clean, 2000);
    EXPECT_LT(recommended_file(s), 1e-9);  // the exact file normals are kept
    EXPECT_LT(recommended_none(s), 1e-9);  // Max's normals are exact on spheres, and chosen
  }
}

// Noisy file normals: measured relative RMS error of H at about 4000 vertices (seed 1), recommended
// vs paper: torus 0.00866 vs 0.148, ellipsoid 0.00617 vs 0.204, saddle 0.0155 vs 3.99. Bounds:
// measured x 1.25 (seeds 2 and 3 stay below them).
TEST(Recommended, NoisyFileNormalsAreReplaced) {
  const struct {
    SurfaceKind kind;
    double bound;
  } cases[] = {{SurfaceKind::torus, 0.0108},
               {SurfaceKind::ellipsoid, 0.0077},
               {SurfaceKind::saddle, 0.0194}};
  for (const auto& c : cases) {
    const AnalyticSurface s = suite_case(c.kind, irregular, Noise::normals);
    const double rec = recommended_file(s), paper = paper_file(s);
    EXPECT_LT(rec, c.bound) << surface_name(c.kind);
    EXPECT_LT(5.0 * rec, paper) << surface_name(c.kind);
  }
}

// No normals on irregular meshes: jets instead of first-order Max normals. Measured (seed 1):
// torus 0.00866 vs 0.0346 (paper with Max normals), helix tube 0.0164 vs 0.0351, saddle 0.0155 vs
// 0.257. Bounds: measured x 1.25.
TEST(Recommended, IrregularMeshesWithoutNormals) {
  const struct {
    SurfaceKind kind;
    double bound;
  } cases[] = {{SurfaceKind::torus, 0.0108},
               {SurfaceKind::helix_tube, 0.0205},
               {SurfaceKind::saddle, 0.0194}};
  for (const auto& c : cases) {
    const AnalyticSurface s = suite_case(c.kind, irregular, Noise::clean);
    const double rec = recommended_none(s);
    EXPECT_LT(rec, c.bound) << surface_name(c.kind);
    EXPECT_LT(1.5 * rec, paper_max(s)) << surface_name(c.kind);
  }
}

// Vertex noise with exact file normals: the normals are kept and the fit widens to 3 rings.
// Measured (seed 1): torus 0.0212 vs 0.0426 (paper), saddle 0.0512 vs 0.216; bounds measured
// x 1.25. Without normals: wide jets, torus 0.0327 vs 0.358 (paper with Max normals), saddle
// 0.287 vs 9.25.
TEST(Recommended, NoisyPositions) {
  for (SurfaceKind kind : {SurfaceKind::torus, SurfaceKind::saddle}) {
    const AnalyticSurface s = suite_case(kind, irregular, Noise::positions);
    const double rec = recommended_file(s), rec_none = recommended_none(s);
    // The paper's error over ours: measured 2.0 (torus, seeds 1 to 3: 2.006, 1.997, 1.998) and
    // 4.2 (saddle); asserted with a 1.25 margin on the torus's.
    EXPECT_LT(1.6 * rec, paper_file(s)) << surface_name(kind);
    EXPECT_LT(rec, kind == SurfaceKind::torus ? 0.0265 : 0.064) << surface_name(kind);
    EXPECT_LT(5.0 * rec_none, paper_max(s)) << surface_name(kind);
  }
}

// A regular (latitude-longitude) mesh's pole is a fan of slivers: 10% vertex noise folds them,
// Max's normals there turn over in clusters, and the jets fitted in those frames come out
// turned or tilted; their patch normals (the vector area over the jets' rings) are not. Measured
// without normals (focal eval's cases, relative H error): pear seed 2 0.895 -> 0.0449 (file normals
// 0.0195), sphere seed 1 0.100 -> 0.0400; bounds measured x 1.25.
TEST(Recommended, FoldedPolesWithoutNormals) {
  struct Case {
    SurfaceKind kind;
    unsigned seed;
    double bound;
  };
  for (const Case& k : {Case{SurfaceKind::pear, 2, 0.056}, Case{SurfaceKind::sphere, 1, 0.050}}) {
    SurfaceOptions o;
    o.kind = k.kind;
    o.triangulation = Triangulation::regular;
    o.target_vertices = 4000;
    o.seed = k.seed;
    AnalyticSurface s = make_surface(o);
    add_position_noise(s.mesh, 0.1, k.seed + 1);
    EXPECT_LT(recommended_none(s), k.bound) << surface_name(k.kind);
  }
}

TEST(Recommended, NoisePlan) {
  // Measured noise: about 1e-4 on clean smooth meshes (7e-3 on the helix tube), 0.055-0.061
  // for the paper's 10% vertex noise.
  const AnalyticSurface clean = suite_case(SurfaceKind::helix_tube, irregular, Noise::clean);
  const RecommendedPlan c = recommended_plan(clean.mesh.V, clean.mesh.F);
  EXPECT_LT(c.noise, 0.01);
  EXPECT_EQ(c.rings, 1);
  const AnalyticSurface noisy = suite_case(SurfaceKind::torus, irregular, Noise::positions);
  const RecommendedPlan n = recommended_plan(noisy.mesh.V, noisy.mesh.F);
  EXPECT_NEAR(n.noise, 0.1 / std::sqrt(3.0), 0.01);  // uniform noise: a / sqrt(3)
  EXPECT_EQ(n.rings, 3);
  EXPECT_TRUE(n.gaussian);
  EXPECT_EQ(recommended_plan_for_noise(NAN).rings, 1);
  EXPECT_EQ(recommended_plan_for_noise(0.5 * (kNoiseForTwoRings + kNoiseForThreeRings)).rings, 2);
}

/// Bitwise equal fields (NaN where the other has NaN).
void expect_same(const CurvatureResult& a, const CurvatureResult& b) {
  ASSERT_EQ(a.k1.size(), b.k1.size());
  for (Eigen::Index i = 0; i < a.k1.size(); ++i) {
    ASSERT_TRUE(a.k1[i] == b.k1[i] || (std::isnan(a.k1[i]) && std::isnan(b.k1[i]))) << i;
    ASSERT_TRUE(a.k2[i] == b.k2[i] || (std::isnan(a.k2[i]) && std::isnan(b.k2[i]))) << i;
    ASSERT_TRUE(a.d1.row(i) == b.d1.row(i) || a.d1.row(i).hasNaN()) << i;
  }
  EXPECT_TRUE(a.point_class == b.point_class);
}

TEST(Recommended, SameResultForAnyThreadCount) {
  for (Noise noise : {Noise::normals, Noise::positions}) {
    const AnalyticSurface s = suite_case(SurfaceKind::saddle, irregular, noise, 3000);
    for (const bool given : {true, false}) {
      const auto run = [&] {
        return estimate_curvature_recommended(s.mesh.V, s.mesh.F,
                                              given ? s.mesh.normals() : std::nullopt)
            .curvature;
      };
      expect_same(test::on_threads(1, run), test::on_threads(3, run));
    }
  }
}

TEST(Recommended, BoundaryVerticesAreEstimated) {
  // The saddle is open: one-sided rings at the boundary still give a fit. Relative RMS error of
  // H within two rings of the boundary, measured: noisy normals 0.224 (paper: 3.89), no normals
  // 0.161 (paper with Max normals: 0.539).
  const AnalyticSurface s = suite_case(SurfaceKind::saddle, irregular, Noise::normals);
  const Evaluation rec =
      evaluate(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N).curvature);
  const Evaluation paper = evaluate(s, estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N));
  const Evaluation none =
      evaluate(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, std::nullopt).curvature);
  const Evaluation max =
      evaluate(s, estimate_curvature(s.mesh.V, s.mesh.F,
                                     vertex_normals(s.mesh.V, s.mesh.F, NormalWeighting::max)));
  EXPECT_EQ(rec.near_boundary.undefined, 0);
  EXPECT_EQ(none.near_boundary.undefined, 0);
  EXPECT_LT(rec.near_boundary.relative_H, 0.3);
  EXPECT_LT(none.near_boundary.relative_H, 0.25);
  EXPECT_LT(3.0 * rec.near_boundary.relative_H, paper.near_boundary.relative_H);
  EXPECT_LT(none.near_boundary.relative_H, max.near_boundary.relative_H);
}

TEST(Recommended, NormalsFromPositionsNearBoundaries) {
  // Without normals on clean positions, the jets of vertices whose 2-ring a boundary cuts fit
  // over 3 rings where that field is smoother (recommended_normals.cpp, with_boundary_jets): a
  // one-sided 2-ring holds about as many points as a cubic has coefficients. Relative RMS error of
  // H within two rings of the boundary against the analytic truth, measured: saddle 0.0134, monkey
  // saddle 0.0114, cylinder 0.0016 (with 2-ring jets there: 0.144, 0.0744, 0.0107).
  struct Case {
    SurfaceKind kind;
    double limit;
  };
  for (const Case& k : {Case{SurfaceKind::saddle, 0.02}, Case{SurfaceKind::monkey_saddle, 0.02},
                        Case{SurfaceKind::cylinder, 0.004}}) {
    const AnalyticSurface s = suite_case(k.kind, irregular, Noise::clean);
    const Evaluation none =
        evaluate(s, estimate_curvature_recommended(s.mesh.V, s.mesh.F, std::nullopt).curvature);
    EXPECT_EQ(none.near_boundary.undefined, 0) << surface_name(k.kind);
    EXPECT_LT(none.near_boundary.relative_H, k.limit) << surface_name(k.kind);
    std::printf("%s near boundary, no normals: relative H %.4g\n",
                std::string(surface_name(k.kind)).c_str(), none.near_boundary.relative_H);
  }
}

TEST(Recommended, UndefinedCasesAndMissingNormals) {
  Mesh m = suite_case(SurfaceKind::sphere, irregular, Noise::clean, 300).mesh;
  const auto n = m.V.rows();
  m.V.conservativeResize(n + 1, 3);
  m.V.row(n) << 9, 9, 9;  // in no face
  m.N.conservativeResize(n + 1, 3);
  m.N.row(n) << 0, 0, 1;
  m.N.row(0).setZero();  // no file normal: the jet normal takes its place
  const CurvatureResult r = estimate_curvature_recommended(m.V, m.F, m.N).curvature;
  EXPECT_EQ(r.class_of(static_cast<int>(n)), PointClass::undefined);
  EXPECT_TRUE(std::isnan(r.H[n]));
  EXPECT_NEAR(r.H[0], 1.0, 0.02);
  const CurvatureResult none = estimate_curvature_recommended(m.V, m.F, std::nullopt).curvature;
  EXPECT_EQ(none.class_of(static_cast<int>(n)), PointClass::undefined);
  // A lone triangle: its estimated normals are all the face's, so no vertex has rays to fit:
  // undefined with NaN, not flat with zeros.
  RowMatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  RowMatrixX3i F(1, 3);
  F << 0, 1, 2;
  // Both through focal::estimate (what the command line and Python run) and the estimator alone.
  for (const CurvatureResult& tri :
       {estimate(PreparedMesh(V, F, std::nullopt), EstimateOptions{}).curvature,
        estimate_curvature_recommended(V, F, std::nullopt).curvature}) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(tri.class_of(i), PointClass::undefined) << "vertex " << i;
      EXPECT_TRUE(std::isnan(tri.H[i]) && std::isnan(tri.k1[i])) << "vertex " << i;
    }
  }
}

// 5% normal noise: the file's normals are ignored as a whole (their median angle to the jet
// normals is 5 to 4600 times the position noise), so the result is the one without normals;
// inward file normals keep their side, which flips H and leaves K.
TEST(Recommended, NoisyFileNormalsAreIgnoredAsAWhole) {
  for (auto [kind, t] : {std::pair{SurfaceKind::torus, irregular},
                         std::pair{SurfaceKind::helix_tube, Triangulation::regular}}) {
    const AnalyticSurface s = suite_case(kind, t, Noise::normals, 3000);
    const RecommendedResult file = estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N);
    EXPECT_FALSE(file.file_normals_used) << surface_name(kind);
    expect_same(file.curvature,
                estimate_curvature_recommended(s.mesh.V, s.mesh.F, std::nullopt).curvature);
    const RowMatrixX3d inward = -s.mesh.N;
    const CurvatureResult flipped =
        estimate_curvature_recommended(s.mesh.V, s.mesh.F, inward).curvature;
    for (Eigen::Index i = 0; i < flipped.H.size(); ++i) {
      if (std::isnan(file.curvature.H[i])) continue;
      ASSERT_EQ(flipped.H[i], -file.curvature.H[i]) << i;
      ASSERT_EQ(flipped.K[i], file.curvature.K[i]) << i;
    }
  }
}

// Exact file normals are kept at every vertex, on clean and on noisy positions (replacing them
// where two truncation-level fit residuals differ by 2x used to cost up to 0.5% of H error).
TEST(Recommended, ExactFileNormalsAreKept) {
  for (auto [kind, noise] :
       {std::pair{SurfaceKind::ellipsoid, Noise::clean}, std::pair{SurfaceKind::pear, Noise::clean},
        std::pair{SurfaceKind::torus, Noise::positions}}) {
    const AnalyticSurface s = suite_case(kind, irregular, noise, 3000);
    const RecommendedResult r = estimate_curvature_recommended(s.mesh.V, s.mesh.F, s.mesh.N);
    EXPECT_TRUE(r.file_normals_used) << surface_name(kind);
    EXPECT_LT(r.file_disagreement, 2.0 * r.plan.noise) << surface_name(kind);
    for (Eigen::Index i = 0; i < s.mesh.N.rows(); ++i) {
      ASSERT_LT((r.N.row(i) - s.mesh.N.row(i).normalized()).norm(), 1e-15)
          << surface_name(kind) << " vertex " << i;
    }
  }
}

// A clean file with isolated bad normals (every 40th: flipped, or turned by 60 degrees): those
// are replaced, the rest kept. Measured relative H error on the irregular torus: 0.00859 (exact
// normals: 0.00840); the paper's fit on the same file: 0.629.
TEST(Recommended, IsolatedBadFileNormalsAreReplaced) {
  const AnalyticSurface s = suite_case(SurfaceKind::torus, irregular, Noise::clean, 3000);
  Mesh bad = s.mesh;
  std::vector<Eigen::Index> corrupted;
  for (Eigen::Index i = 0; i < bad.N.rows(); i += 40) {
    const Eigen::Vector3d n = bad.N.row(i).transpose();
    const Eigen::Vector3d t = n.unitOrthogonal();
    const Eigen::Vector3d turned = 0.5 * n + 0.866 * t;
    bad.N.row(i) = (corrupted.size() % 2 == 0 ? Eigen::Vector3d(-n) : turned).transpose();
    corrupted.push_back(i);
  }
  const RecommendedResult r = estimate_curvature_recommended(bad.V, bad.F, bad.N);
  EXPECT_TRUE(r.file_normals_used);
  for (Eigen::Index i : corrupted) {
    EXPECT_GT((r.N.row(i) - bad.N.row(i).normalized()).norm(), 0.5) << "vertex " << i;
  }
  const double with_bad = rel_h(s, r.curvature);
  // The paper's fit leaves out the flipped normals' rays: some vertices are left without two.
  const double paper_bad = rel_h(s, estimate_curvature(bad.V, bad.F, bad.N), true);
  EXPECT_GT(paper_bad, 10.0 * with_bad);
  // A replaced normal is the positions' (third order only), and so are those of about 220
  // neighbours of the corrupted vertices that the replacement also takes: the Hermite fit
  // takes their heights but not their slopes, and fits their own vertices with a free
  // gradient. Measured 0.0010, against 0.00039 on the clean mesh (isolated replacements stay
  // within 1.1 times of it: SmallOutliersAreReplaced) and 0.0036 for the per-triangle pass on
  // the clean mesh: below 0.75 of the latter, the lower-order steps' own gain
  // (corrected_step_test).
  CurvatureOptions triangles;
  triangles.method = Method::triangle;
  EXPECT_LT(with_bad, 0.75 * rel_h(s, estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, triangles)));
}

// Outliers a few degrees off (every 40th normal turned by 8 degrees: over 4 times the outlier
// limit of 10 x the noise, 1.1 degrees on this coarse mesh, and beyond the 3 x median
// roughness that puts a normal in doubt) are still found without the jets of every vertex, and
// replaced.
TEST(Recommended, SmallOutliersAreReplaced) {
  const AnalyticSurface s = suite_case(SurfaceKind::torus, irregular, Noise::clean, 3000);
  Mesh bad = s.mesh;
  std::vector<Eigen::Index> turned;
  const double angle = 8.0 * M_PI / 180.0;
  for (Eigen::Index i = 0; i < bad.N.rows(); i += 40) {
    const Eigen::Vector3d n = bad.N.row(i).transpose();
    bad.N.row(i) = (std::cos(angle) * n + std::sin(angle) * n.unitOrthogonal()).transpose();
    turned.push_back(i);
  }
  const RecommendedResult r = estimate_curvature_recommended(bad.V, bad.F, bad.N);
  ASSERT_TRUE(r.file_normals_used);
  ASSERT_LT(10.0 * r.plan.noise, angle / 4.0);
  for (const Eigen::Index i : turned) {
    // Replaced: the chosen normal is nearer the surface's than the turned one (chord 0.14).
    EXPECT_LT((r.N.row(i) - s.mesh.N.row(i)).norm(), 0.5 * (bad.N.row(i) - s.mesh.N.row(i)).norm())
        << "vertex " << i;
  }
  EXPECT_LT(rel_h(s, r.curvature), 1.1 * recommended_file(s));
}

// The per-mesh choices are medians over every (n / 4096)-th vertex by index: on a mesh of
// 20,000 vertices (every 4th), the noise is the median of those vertices' 2-ring cubic jet
// residuals, bit for bit.
TEST(Recommended, MeshWideChoicesAreTheSamplesMedians) {
  const AnalyticSurface s = suite_case(SurfaceKind::pear, irregular, Noise::positions, 20000);
  const PreparedMesh mesh(s.mesh.V, s.mesh.F, NormalsRef(s.mesh.N));
  const RecommendedMeshWide m = recommended_mesh_wide(mesh);
  const JetNormals jets = jet_normals(mesh, {.rings = 2, .degree = 3, .iterations = 1});
  const Eigen::Index step = s.mesh.V.rows() / 4096;
  ASSERT_EQ(step, 4);
  std::vector<double> sample;
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); i += step) {
    if (std::isfinite(jets.residual[i])) sample.push_back(jets.residual[i]);
  }
  const auto mid = sample.begin() + static_cast<std::ptrdiff_t>(sample.size() / 2);
  std::nth_element(sample.begin(), mid, sample.end());
  EXPECT_EQ(m.noise, *mid / mesh.mean_edge_length());
  // The median over every vertex differs (4 in 5 vertices are not in the sample) by under 2%.
  std::vector<double> all(jets.residual.begin(), jets.residual.end());
  std::erase_if(all, [](double x) { return !std::isfinite(x); });
  const auto half = all.begin() + static_cast<std::ptrdiff_t>(all.size() / 2);
  std::nth_element(all.begin(), half, all.end());
  EXPECT_NEAR(m.noise, *half / mesh.mean_edge_length(), 0.02 * m.noise);
}

TEST(Recommended, RejectsInvalidInput) {
  const Mesh m = suite_case(SurfaceKind::sphere, irregular, Noise::clean, 200).mesh;
  EXPECT_THROW((void)estimate_curvature_recommended(m.V, m.F, m.N.topRows(5)), InvalidInput);
  RowMatrixX3i F = m.F;
  F(0, 0) = static_cast<int>(m.V.rows());
  EXPECT_THROW((void)estimate_curvature_recommended(m.V, F, std::nullopt).curvature, InvalidInput);
}

// The table of docs/notes/estimator-log.md: build/release/tests/recommended_test
//   --gtest_also_run_disabled_tests --gtest_filter='*SuiteTable*'
TEST(Recommended, DISABLED_SuiteTable) {
  std::printf(
      "| case | paper / file | recommended / file | paper / Max | recommended / none | "
      "MDSB03 | CSM03 |\n|---|---|---|---|---|---|---|\n");
  for (SurfaceKind kind : all_surfaces()) {
    for (auto t : {Triangulation::regular, irregular}) {
      for (Noise noise : {Noise::clean, Noise::positions, Noise::normals}) {
        const AnalyticSurface s = suite_case(kind, t, noise);
        std::printf("| %s, %s, %s | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g |\n",
                    std::string(surface_name(kind)).c_str(),
                    t == irregular ? "irregular" : "regular",
                    noise == Noise::clean       ? "clean"
                    : noise == Noise::positions ? "vertex noise 10%"
                                                : "normal noise 5%",
                    paper_file(s), recommended_file(s), paper_max(s), recommended_none(s),
                    rel_h(s, baselines::meyer_2003(s.mesh.V, s.mesh.F)),
                    rel_h(s, baselines::cohen_steiner_morvan_2003(s.mesh.V, s.mesh.F)));
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace
}  // namespace focal
