// The lane kernels of the closed-form fit, of the per-triangle solve, of the jets and of the
// area- and Max-weighted vertex normals
// (src/core/simd_lanes.h), and the polynomial fits' builds for each instruction set:
// the same bits for every instruction set they are compiled for and every thread count, and the
// same values as the scalar formulas, including the lanes that the vector code handles by select
// (invalid normals, too few rays, groups cut short at the end of a block or of the mesh).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "core/result_rows.h"
#include "core/simd_lanes.h"
#include "curvature/height_fit.h"
#include "curvature/hermite_fit.h"
#include "curvature/triangle_fit.h"
#include "curvature/two_slit_detail.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/execution.h"
#include "focal/curvature/normal_rays.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/curvature/two_slit_fit.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"
#include "kernels/local_shape.h"
#include "kernels/two_slit.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"
#include "normals/jet_normals_from.h"
#include "normals/vertex_normals_from.h"
#include "test_meshes.h"

namespace focal {
namespace {

using detail::SimdIsa;

/// An irregular torus (valences 4 to 9) with #V not a multiple of 8, some normals invalid
/// (zero, NaN) and one vertex with a single usable neighbour ray (all other neighbour normals
/// flipped), so that lanes of one group take every branch of the fit.
Mesh awkward_mesh() {
  Mesh m = test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, 3001, 0, 7).mesh;
  EXPECT_NE(m.V.rows() % 8, 0);
  m.N.row(3).setZero();
  m.N(17, 1) = std::nan("");
  m.N.row(18) *= -1.0;  // outside its neighbours' hemispheres: excluded from their fits
  const Neighbourhoods ring = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  const int lonely = 40;
  for (const int* j = ring.begin(lonely) + 1; j != ring.end(lonely); ++j) m.N.row(*j) *= -1.0;
  return m;
}

std::vector<SimdIsa> available_isas() {
  std::vector<SimdIsa> isas;
  for (SimdIsa isa : {SimdIsa::baseline, SimdIsa::avx2, SimdIsa::avx512}) {
    if (detail::simd_isa_available(isa)) isas.push_back(isa);
  }
  return isas;
}

/// Same bits, NaN where the other has NaN.
template <class A>
bool identical(const A& a, const A& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         ((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all();
}

bool identical(const CurvatureResult& a, const CurvatureResult& b) {
  return identical(a.k1, b.k1) && identical(a.k2, b.k2) && identical(a.H, b.H) &&
         identical(a.K, b.K) && identical(a.d1, b.d1) && identical(a.d2, b.d2) &&
         identical(a.residual, b.residual) &&
         (a.point_class.array() == b.point_class.array()).all() &&
         (a.rays_used.array() == b.rays_used.array()).all() &&
         (a.rays_excluded.array() == b.rays_excluded.array()).all();
}

struct FitCase {
  int rings;
  RayWeighting weighting;
};

CurvatureResult fit(const Mesh& m, const FitCase& c, int threads, SimdIsa isa) {
  CurvatureOptions o;
  o.rings = c.rings;
  o.weighting = c.weighting;
  const ExecutionScope scope({.threads = threads});
  std::vector<char> ok;
  const RowMatrixX3d unit = detail::unit_rows(m.N, ok);
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  const Neighbourhoods rings = c.rings == 1 ? one : k_ring(one, c.rings);
  return detail::fit_vertices({m.V, unit, ok, rings, mean_edge_length(m.V, m.F)}, o, isa);
}

TEST(SimdKernels, FitIsBitIdenticalForEveryInstructionSetAndThreadCount) {
  const Mesh m = awkward_mesh();
  for (const FitCase c : {FitCase{1, RayWeighting::uniform}, FitCase{2, RayWeighting::gaussian}}) {
    const CurvatureResult reference = fit(m, c, 1, SimdIsa::baseline);
    for (SimdIsa isa : available_isas()) {
      for (int threads : {1, 2, 3}) {
        EXPECT_TRUE(identical(fit(m, c, threads, isa), reference))
            << "rings " << c.rings << " isa " << static_cast<int>(isa) << " threads " << threads;
      }
    }
  }
}

// The roughness-only fit (detail::fit_roughness, the recommended estimator's rating of normal
// fields): the full fit's residual bit for bit where it made a ray of every neighbour, NaN
// elsewhere, for every instruction set and thread count. The awkward mesh has vertices of each
// kind (excluded rays, invalid normals, too few rays).
TEST(SimdKernels, RoughnessIsTheFullFitsResidualWhereNoRayWasExcluded) {
  const Mesh m = awkward_mesh();
  for (const FitCase c : {FitCase{1, RayWeighting::uniform}, FitCase{2, RayWeighting::gaussian}}) {
    const CurvatureResult full = fit(m, c, 1, SimdIsa::baseline);
    Eigen::VectorXd expected = full.residual;
    int excluded = 0, finite = 0;
    for (Eigen::Index i = 0; i < expected.size(); ++i) {
      if (full.rays_excluded[i] > 0) expected[i] = NAN, ++excluded;
      finite += std::isfinite(expected[i]);
    }
    ASSERT_GT(excluded, 0);
    ASSERT_GT(finite, expected.size() / 2);
    CurvatureOptions o;
    o.rings = c.rings;
    o.weighting = c.weighting;
    std::vector<char> ok;
    const RowMatrixX3d unit = detail::unit_rows(m.N, ok);
    const Neighbourhoods one = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
    const Neighbourhoods rings = c.rings == 1 ? one : k_ring(one, c.rings);
    for (SimdIsa isa : available_isas()) {
      for (int threads : {1, 2, 3}) {
        const ExecutionScope scope({.threads = threads});
        const Eigen::VectorXd r =
            detail::fit_roughness({m.V, unit, ok, rings, mean_edge_length(m.V, m.F)}, o, isa);
        EXPECT_TRUE(identical(r, expected))
            << "rings " << c.rings << " isa " << static_cast<int>(isa) << " threads " << threads;
        // At listed vertices only (every third, in reverse, so that each group holds vertices
        // of other groups' neighbourhoods): the same bits in list order.
        std::vector<int> some;
        for (int i = static_cast<int>(m.V.rows()) - 1; i >= 0; i -= 3) some.push_back(i);
        const Eigen::VectorXd at =
            detail::fit_roughness_at({m.V, unit, ok, rings, mean_edge_length(m.V, m.F)}, o,
                                     some.data(), static_cast<Eigen::Index>(some.size()), isa);
        Eigen::VectorXd expected_at(static_cast<Eigen::Index>(some.size()));
        for (std::size_t k = 0; k < some.size(); ++k) {
          expected_at[static_cast<Eigen::Index>(k)] = expected[some[k]];
        }
        EXPECT_TRUE(identical(at, expected_at))
            << "listed, rings " << c.rings << " isa " << static_cast<int>(isa);
      }
    }
  }
}

// The scalar formulas (tangent_frame, normal_ray, fit_two_slits_closed_form) vertex by vertex:
// the lane kernel solves the same normal equations by cofactors, so values agree to rounding.
TEST(SimdKernels, FitMatchesTheScalarClosedFormVertexByVertex) {
  const Mesh m = awkward_mesh();
  const CurvatureResult r = fit(m, {1, RayWeighting::uniform}, 0, SimdIsa::best);
  const Neighbourhoods ring = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  int undefined = 0;
  for (int i = 0; i < m.V.rows(); ++i) {
    const Eigen::Vector3d n = m.N.row(i).transpose();
    const bool normal_ok = std::isfinite(n.norm()) && n.norm() > 0.0;
    std::vector<NormalRay> rays;
    if (normal_ok) {
      const TangentFrame frame = tangent_frame(n.normalized());
      for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
        const Eigen::Vector3d nj = m.N.row(*j).transpose();
        if (!std::isfinite(nj.norm()) || !(nj.norm() > 0.0)) continue;
        if (auto ray = normal_ray(frame, m.V.row(i).transpose(), m.V.row(*j).transpose(),
                                  nj.normalized())) {
          rays.push_back(*ray);
        }
      }
    }
    ASSERT_EQ(r.rays_used[i], static_cast<int>(rays.size())) << "vertex " << i;
    ASSERT_EQ(r.rays_excluded[i], normal_ok ? ring.size(i) - r.rays_used[i] : 0);
    const SlitFit f = normal_ok ? fit_two_slits_closed_form(rays) : SlitFit{};
    if (!f.valid) {
      ++undefined;
      ASSERT_EQ(r.class_of(i), PointClass::undefined) << "vertex " << i;
      ASSERT_TRUE(std::isnan(r.k1[i]) && std::isnan(r.d1(i, 0)) && std::isnan(r.residual[i]));
      continue;
    }
    const double scale = std::max(std::abs(f.k1), std::abs(f.k2));
    ASSERT_NEAR(r.k1[i], f.k1, 1e-12 * scale) << "vertex " << i;
    ASSERT_NEAR(r.k2[i], f.k2, 1e-12 * scale) << "vertex " << i;
    ASSERT_NEAR(r.residual[i], std::sqrt(f.energy / static_cast<double>(rays.size())),
                1e-9 * scale);
  }
  EXPECT_GE(undefined, 3);  // vertices 3, 17 (invalid normals) and 40 (one ray)
}

/// Bitwise equality, NaN included.
bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

/// The closed-form fit of vertex i with the shared formulas (kernels/local_shape.h,
/// kernels/two_slit.h) on plain doubles, one neighbour after the other, as the lane kernel's
/// contract states it: frame_of, normal_ray and principal_axes with reciprocal quotients,
/// add_ray in neighbour order, solve_slits, slit_misfit.
struct ScalarFit {
  bool valid = false;
  double k1, k2, residual;
  kernels::Vec3<double> d1, d2;
  int used = 0, excluded = 0;
};

ScalarFit scalar_fit(const Mesh& m, const RowMatrixX3d& unit, const std::vector<char>& ok,
                     const Neighbourhoods& rings, int i, double inverse_two_width_squared) {
  using kernels::Quotient;
  ScalarFit out;
  if (!ok[static_cast<std::size_t>(i)]) return out;
  const auto vec = [](const auto& row) { return kernels::Vec3<double>{row(0), row(1), row(2)}; };
  const kernels::Frame<double> frame = kernels::frame_of(vec(unit.row(i)));
  const kernels::Vec3<double> p = vec(m.V.row(i));
  kernels::SlitSums<double> sums;
  std::vector<kernels::NormalRay<double>> rays;
  std::vector<double> weights;
  double weight_sum = 0.0;
  int positive = 0;
  for (const int* j = rings.begin(i); j != rings.end(i); ++j) {
    const kernels::Vec3<double> d = vec(m.V.row(*j)) - p;
    const kernels::Vec3<double> n = vec(unit.row(*j));
    kernels::NormalRay<double> ray;
    if (!ok[static_cast<std::size_t>(*j)] ||
        !kernels::normal_ray<Quotient::reciprocal>(frame, d, n, n, ray)) {
      ++out.excluded;
      continue;
    }
    const double w =
        inverse_two_width_squared > 0.0
            ? std::exp(-(d.x * d.x + d.y * d.y + d.z * d.z) * inverse_two_width_squared)
            : 1.0;
    kernels::add_ray(sums, w, ray.u, ray.v, ray.sigma, ray.tau);
    weight_sum += w;
    positive += w > 0.0;
    rays.push_back(ray);
    weights.push_back(w);
  }
  out.used = static_cast<int>(rays.size());
  const kernels::SlitSolution<double> w =
      kernels::solve_slits(sums, detail::kMinRelativeDeterminant);
  if (positive < 2 || !w.valid) return out;
  double energy = 0.0;
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const kernels::NormalRay<double>& r = rays[k];
    energy += weights[k] * kernels::slit_misfit(w, r.u, r.v, r.sigma, r.tau);
  }
  const kernels::Principal<double> e =
      kernels::principal_axes<Quotient::reciprocal, Quotient::reciprocal>(w.a, w.b, w.c);
  out.valid = true;
  out.k1 = e.k1, out.k2 = e.k2;
  out.residual = std::sqrt(energy / (inverse_two_width_squared > 0.0 ? weight_sum : out.used));
  out.d1 = frame.from_plane(e.d1x, e.d1y), out.d2 = frame.from_plane(-e.d1y, e.d1x);
  return out;
}

// The lane kernel's contract (curvature.cpp): every lane has the bits of the shared formulas run
// on plain doubles one vertex at a time, on the awkward mesh's every kind of vertex (invalid
// normals, excluded rays, too few rays), with uniform and Gaussian weights.
TEST(SimdKernels, FitIsTheSharedFormulaOnScalarsBitForBit) {
  const Mesh m = awkward_mesh();
  std::vector<char> ok;
  const RowMatrixX3d unit = detail::unit_rows(m.N, ok);
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  const double h = mean_edge_length(m.V, m.F);
  for (const FitCase c : {FitCase{1, RayWeighting::uniform}, FitCase{2, RayWeighting::gaussian}}) {
    const Neighbourhoods rings = c.rings == 1 ? one : k_ring(one, c.rings);
    const double width = h * c.rings;  // the default Gaussian width
    const double inverse = c.weighting == RayWeighting::gaussian ? 0.5 / (width * width) : 0.0;
    for (SimdIsa isa : available_isas()) {
      const CurvatureResult r = fit(m, c, 0, isa);
      int undefined = 0;
      for (int i = 0; i < m.V.rows(); ++i) {
        const ScalarFit s = scalar_fit(m, unit, ok, rings, i, inverse);
        ASSERT_EQ(r.rays_used[i], s.used) << i;
        ASSERT_EQ(r.rays_excluded[i], s.excluded) << i;
        if (!s.valid) {
          ++undefined;
          ASSERT_EQ(r.class_of(i), PointClass::undefined) << i;
          ASSERT_TRUE(std::isnan(r.k1[i]) && std::isnan(r.d2(i, 2)) && std::isnan(r.residual[i]));
          continue;
        }
        ASSERT_TRUE(same_bits(r.k1[i], s.k1) && same_bits(r.k2[i], s.k2)) << i;
        ASSERT_TRUE(same_bits(r.H[i], 0.5 * (s.k1 + s.k2)) && same_bits(r.K[i], s.k1 * s.k2)) << i;
        ASSERT_TRUE(same_bits(r.residual[i], s.residual)) << i;
        ASSERT_TRUE(same_bits(r.d1(i, 0), s.d1.x) && same_bits(r.d1(i, 1), s.d1.y) &&
                    same_bits(r.d1(i, 2), s.d1.z))
            << i;
        ASSERT_TRUE(same_bits(r.d2(i, 0), s.d2.x) && same_bits(r.d2(i, 1), s.d2.y) &&
                    same_bits(r.d2(i, 2), s.d2.z))
            << i;
      }
      EXPECT_GE(undefined, 3) << "vertices 3, 17 (invalid normals) and 40 (one ray)";
    }
  }
}

TEST(SimdKernels, TriangleIsBitIdenticalForEveryInstructionSetAndThreadCount) {
  const Mesh m = awkward_mesh();
  const TriangleFields all;
  TriangleFields curvatures;
  curvatures.coefficients = curvatures.focal_depths = curvatures.directions = false;
  curvatures.slits = curvatures.face_normal = curvatures.shape_operator = false;
  for (const TriangleFields& fields : {all, curvatures}) {
    CurvatureOptions o;
    const ExecutionScope serial({.threads = 1});
    const TriangleCurvatureResult reference =
        detail::triangle_curvature(m.V, m.F, m.N, o, fields, SimdIsa::baseline);
    for (SimdIsa isa : available_isas()) {
      for (int threads : {1, 2, 3}) {
        const ExecutionScope scope({.threads = threads});
        const TriangleCurvatureResult t = detail::triangle_curvature(m.V, m.F, m.N, o, fields, isa);
        EXPECT_TRUE(identical(t.A, reference.A) && identical(t.B, reference.B) &&
                    identical(t.C, reference.C) && identical(t.K, reference.K) &&
                    identical(t.H, reference.H) && identical(t.k1, reference.k1) &&
                    identical(t.k2, reference.k2) && identical(t.lambda1, reference.lambda1) &&
                    identical(t.lambda2, reference.lambda2) && identical(t.d1, reference.d1) &&
                    identical(t.d2, reference.d2) && identical(t.slit1, reference.slit1) &&
                    identical(t.slit2, reference.slit2) &&
                    identical(t.face_normal, reference.face_normal) &&
                    identical(t.shape_operator, reference.shape_operator) &&
                    (t.point_class.array() == reference.point_class.array()).all())
            << "isa " << static_cast<int>(isa) << " threads " << threads;
      }
    }
  }
}

/// A mesh on which the jets take every path of their lanes: a noisy 9 x 9 grid (its corners and
/// edges hold too few points for a cubic or quartic: lower degrees, by the scalar path), a fan of
/// 12 triangles whose rim lies on a circle around its centre (the cubic's normal equations there
/// are singular: x (x^2 + y^2 - r^2) vanishes at every point of the 1-ring, and the rim vertices'
/// rings are no better), a vertex at NaN (its neighbours skip it; its faces' vertices start
/// from NaN normals: no jet) and a vertex in no face (no jet). 81 + 13 + 1 vertices: the last
/// batch of every lane width is cut short.
struct DegenerateRings {
  RowMatrixX3d V;
  Neighbourhoods one;
  RowMatrixX3d start;  ///< Max's normals, NaN around the NaN vertex
};

DegenerateRings degenerate_rings() {
  constexpr int kGrid = 9, kRim = 12;
  RowMatrixX3d V(kGrid * kGrid + 1 + kRim + 1, 3);
  std::mt19937 random(19);
  std::uniform_real_distribution<double> noise(-0.05, 0.05);
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      const double x = i + noise(random), y = j + noise(random);
      V.row(i * kGrid + j) << x, y, 0.05 * x * x - 0.03 * x * y * y / kGrid + noise(random);
    }
  }
  const int centre = kGrid * kGrid;
  V.row(centre) << 20.0, 0.0, 0.0;
  for (int k = 0; k < kRim; ++k) {
    const double t = 2.0 * M_PI * k / kRim;
    V.row(centre + 1 + k) << 20.0 + std::cos(t), std::sin(t), 0.0;
  }
  V.row(V.rows() - 1) << 5.0, 5.0, 5.0;  // in no face
  std::vector<Eigen::RowVector3i> faces;
  for (int i = 0; i + 1 < kGrid; ++i) {
    for (int j = 0; j + 1 < kGrid; ++j) {
      const int a = i * kGrid + j, b = a + kGrid;
      faces.push_back({a, b, a + 1});
      faces.push_back({a + 1, b, b + 1});
    }
  }
  for (int k = 0; k < kRim; ++k)
    faces.push_back({centre, centre + 1 + k, centre + 1 + (k + 1) % kRim});
  RowMatrixX3i F(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) F.row(static_cast<Eigen::Index>(f)) = faces[f];
  RowMatrixX3d start = vertex_normals(V, F, NormalWeighting::max);
  const int lost = 4 * kGrid + 4;  // the grid's middle vertex
  V.row(lost).setConstant(std::nan(""));
  Neighbourhoods one = vertex_adjacency(static_cast<int>(V.rows()), F);
  for (const int* j = one.begin(lost); j != one.end(lost); ++j)
    start.row(*j).setConstant(std::nan(""));
  return {V, std::move(one), start};
}

bool identical(const JetNormals& a, const JetNormals& b) {
  return identical(a.N, b.N) && identical(a.residual, b.residual) && a.degree == b.degree;
}

TEST(SimdKernels, JetLanesEqualTheScalarPathVertexByVertex) {
  const DegenerateRings m = degenerate_rings();
  const int centre = 81;
  JetOptions cubic;
  cubic.degree = 3;
  cubic.rings = 2;
  cubic.iterations = 1;
  std::vector<JetOptions> cases(6, cubic);  // the default's jets first
  cases[1].rings = 3;
  cases[2].degree = 4;
  cases[3].degree = 2, cases[3].rings = 1;
  cases[4].degree = 1, cases[4].rings = 1;
  cases[5].iterations = 2;
  for (JetOptions o : cases) {
    const ExecutionScope serial({.threads = 1});
    const JetNormals scalar = detail::jet_normals_from(m.V, m.one, m.start, o, std::nullopt);
    const auto with_degree = [&](auto predicate) {
      return (scalar.degree.array().unaryExpr(predicate)).count();
    };
    // Every path is taken: the degree asked for, lower degrees, no jet.
    EXPECT_GT(with_degree([&](int d) { return d == o.degree; }), 20);
    if (o.degree > 1) {
      EXPECT_GT(with_degree([&](int d) { return d > 0 && d < o.degree; }), 3);
    }
    EXPECT_GE(with_degree([](int d) { return d == 0; }), 2);
    if (o.degree == 3) {
      EXPECT_EQ(scalar.degree[centre], 2) << "the fan's cubic is singular";
    }
    for (SimdIsa isa : available_isas()) {
      for (int threads : {1, 2, 3}) {
        const ExecutionScope scope({.threads = threads});
        EXPECT_TRUE(identical(detail::jet_normals_from(m.V, m.one, m.start, o, isa), scalar))
            << "degree " << o.degree << " rings " << o.rings << " isa " << static_cast<int>(isa)
            << " threads " << threads;
      }
      // Other batches: the vertices listed backwards, every third.
      std::vector<int> some;
      for (int v = static_cast<int>(m.V.rows()) - 1; v >= 0; v -= 3) some.push_back(v);
      const JetNormals at = detail::jet_normals_at(m.V, m.one, m.start, o, some, isa);
      for (std::size_t k = 0; k < some.size(); ++k) {
        const auto row = static_cast<Eigen::Index>(k);
        EXPECT_EQ(at.degree[row], scalar.degree[some[k]]);
        EXPECT_TRUE(identical(RowMatrixX3d(at.N.row(row)), RowMatrixX3d(scalar.N.row(some[k]))))
            << "vertex " << some[k];
      }
    }
  }
}

/// The awkward torus with a face of three collinear vertices (zero area), a face that repeats an
/// index, a face given twice with opposite orientations (its terms cancel at its corners), a
/// vertex at NaN and a vertex in no face: every kind of corner the normals' lanes add as +0.
Mesh awkward_faces() {
  const Mesh m = awkward_mesh();
  const auto n = static_cast<int>(m.V.rows()), f = static_cast<int>(m.F.rows());
  Mesh out;
  out.V.resize(n + 4, 3);
  out.V.topRows(n) = m.V;
  out.V.bottomRows(4) << 10.0, 0.0, 0.0, 11.0, 0.0, 0.0, 12.0, 0.0, 0.0, 0.0, 0.0, 50.0;
  out.V(5, 0) = std::nan("");
  out.F.resize(f + 4, 3);
  out.F.topRows(f) = m.F;
  out.F.bottomRows(4) << n, n + 1, n + 2, 7, 7, 8, 9, 10, 11, 9, 11, 10;
  return out;
}

TEST(SimdKernels, AreaAndMaxNormalsInLanesEqualTheScalarLoopVertexByVertex) {
  const Mesh m = awkward_faces();
  for (NormalWeighting weighting : {NormalWeighting::area, NormalWeighting::max}) {
    const detail::VertexFaces inc = detail::vertex_face_incidence(m.V.rows(), m.F, 1);
    const RowMatrixX3d scalar =
        detail::vertex_normals_from(m.V, m.F, inc, weighting, 1, std::nullopt);
    EXPECT_TRUE(scalar.row(m.V.rows() - 1).array().isNaN().all()) << "the vertex in no face";
    EXPECT_TRUE(scalar.row(5).array().isNaN().all()) << "the vertex at NaN";
    EXPECT_GT(scalar.array().isFinite().rowwise().all().count(), m.V.rows() - 20);
    for (SimdIsa isa : available_isas()) {
      for (int threads : {1, 2, 3}) {
        EXPECT_TRUE(
            identical(detail::vertex_normals_from(m.V, m.F, inc, weighting, threads, isa), scalar))
            << "weighting " << static_cast<int>(weighting) << " isa " << static_cast<int>(isa)
            << " threads " << threads;
      }
    }
  }
}

// The Hermite and height fits' blocks, compiled for AVX2 and for baseline x86-64
// (polynomial::fit_rows_for), and their lanes (a vertex a lane) against each vertex fitted
// alone: the same rows bit for bit, on an irregular torus where some
// vertices' positions are flagged as moved and some normals as guessed (their free terms).
TEST(SimdKernels, PolynomialFitsAreBitIdenticalForEveryInstructionSet) {
  const Mesh m =
      test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, 3001, 0, 7).mesh;
  const PreparedMesh mesh(m.V, m.F, m.N);
  const auto n = static_cast<std::size_t>(m.V.rows());
  const std::vector<char> ok(n, 1), keep;
  std::vector<char> moved(n, 0), guessed(n, 0);
  for (std::size_t i = 0; i < n; i += 37) moved[i] = 1;
  for (std::size_t i = 5; i < n; i += 41) guessed[i] = 1;
  const auto hermite = [&](SimdIsa isa, bool in_lanes) {
    CurvatureResult fit = detail::undefined_result(m.V.rows());
    fit.residual.setConstant(1.0);  // no row exact
    const std::vector<char> written =
        detail::prefer_hermite_fit(m.V, m.N, ok, mesh.one_ring(), *detail::incidence(mesh), keep,
                                   moved, guessed, 1e-9, {}, fit, isa, in_lanes);
    EXPECT_GT(std::count(written.begin(), written.end(), 1), static_cast<long>(n / 2));
    return fit;
  };
  const auto height = [&](SimdIsa isa, bool in_lanes) {
    CurvatureResult fit = detail::undefined_result(m.V.rows());
    fit.residual.setConstant(1.0);
    const std::vector<char> written =
        detail::prefer_height_fit(m.V, m.N, ok, mesh.one_ring(), *detail::incidence(mesh), keep,
                                  moved, 1e-9, {}, fit, isa, in_lanes);
    EXPECT_GT(std::count(written.begin(), written.end(), 1), static_cast<long>(n / 2));
    return fit;
  };
  // The references fit each vertex alone; the lanes take most vertices (all but the moved, and
  // for the Hermite fit the guessed and those whose rows are few), four or two at once.
  const CurvatureResult hermite_reference = hermite(SimdIsa::baseline, false);
  const CurvatureResult height_reference = height(SimdIsa::baseline, false);
  for (SimdIsa isa : available_isas()) {
    EXPECT_TRUE(identical(hermite(isa, false), hermite_reference)) << static_cast<int>(isa);
    EXPECT_TRUE(identical(hermite(isa, true), hermite_reference)) << static_cast<int>(isa);
    EXPECT_TRUE(identical(height(isa, false), height_reference)) << static_cast<int>(isa);
    EXPECT_TRUE(identical(height(isa, true), height_reference)) << static_cast<int>(isa);
  }
}

}  // namespace
}  // namespace focal
