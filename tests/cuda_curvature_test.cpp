// The CUDA per-vertex fit (estimate_curvature_cuda) against the CPU estimator.
//
// (a) always: the kernel's FOCAL_HD math (src/kernels/vertex_fit.h) run on the CPU in float,
//     as the device runs it, and in double, against estimate_curvature (double);
// (b) with a GPU: estimate_curvature_cuda against estimate_curvature (skipped without one);
// (c) the error paths: DeviceError without backend or device, InvalidInput for bad input.
//
// Tolerances (docs/GPU.md). Float's unit roundoff is u = 6e-8. The device path computes the rays
// to a few u relative to |k| h (hi/lo pairs, see kernels/vertex_fit.h); the 3x3 solve amplifies by
// the condition of the normal equations (< 100 on these meshes) and the eigen-decomposition's
// absolute error is a few u x kappa, kappa = max(|k1|, |k2|) at the vertex. So:
//  - |dk| <= 1e-5 kappa at every vertex (170 u; measured max 3.4e-6 on the regular sphere,
//    whose pole fans have many neighbours, 5e-7 elsewhere);
//  - |dk| / |k| < 1e-4 (the accuracy target) where |k| h >= 1e-2, i.e. ten times the zero
//    tolerance: below, |k| << kappa and the absolute bound above is the meaningful one;
//  - d1 within 1e-5 kappa / (k1 - k2) radians (a perturbation of the shape operator of size e
//    turns its eigenvectors by e / gap), checked where the gap is at least 1e-3 kappa;
//  - classes identical except where the CPU's k1, k2 lie within 1e-5 kappa of a class threshold
//    (then float rounding may fall on the other side; such vertices are counted and printed);
//  - the double instantiation reproduces the CPU to 1e-10 kappa: same formula, other rounding.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cuda/vertex_fit.h"
#include "focal/core/error.h"
#include "focal/cuda/curvature.h"
#include "focal/cuda/device.h"
#include "focal/surfaces/surfaces.h"
#include "gpu_required.h"
#include "test_meshes.h"

namespace focal {
namespace {

struct Case {
  std::string name;
  SurfaceKind kind;
  Triangulation triangulation;
  int vertices;
  int rings = 1;
  RayWeighting weighting = RayWeighting::uniform;
};

std::vector<Case> cases() {
  using S = SurfaceKind;
  using T = Triangulation;
  return {
      {"sphere regular", S::sphere, T::regular, 2000},
      {"sphere irregular", S::sphere, T::irregular, 2000},
      {"torus regular", S::torus, T::regular, 4000},
      {"torus irregular", S::torus, T::irregular, 4000},
      {"ellipsoid irregular", S::ellipsoid, T::irregular, 4000},
      {"saddle regular", S::saddle, T::regular, 4000},
      {"saddle irregular", S::saddle, T::irregular, 4000},
      {"pear irregular", S::pear, T::irregular, 4000},
      {"torus irregular gaussian", S::torus, T::irregular, 4000, 1, RayWeighting::gaussian},
      {"ellipsoid irregular 2 rings", S::ellipsoid, T::irregular, 4000, 2},
      {"saddle irregular 2 rings gaussian", S::saddle, T::irregular, 4000, 2,
       RayWeighting::gaussian},
  };
}

Mesh mesh_of(const Case& c) {
  return test::analytic_surface(c.kind, c.triangulation, c.vertices, 0.0, 1).mesh;
}

CurvatureOptions options_of(const Case& c) {
  CurvatureOptions o;
  o.rings = c.rings;
  o.weighting = c.weighting;
  return o;
}

/// Whether k1, k2 lie within `margin` of a threshold of classify (zero, umbilic, sign of K).
bool near_class_threshold(double k1, double k2, double zero, double umbilic, double margin) {
  const double gap = k1 - k2 - umbilic * std::max(std::abs(k1), std::abs(k2));
  return std::abs(std::abs(k1) - zero) <= margin || std::abs(std::abs(k2) - zero) <= margin ||
         std::abs(gap) <= 2 * margin || std::abs(k1) <= margin || std::abs(k2) <= margin;
}

struct Comparison {
  double max_kappa_error = 0;           // max |dk| / kappa
  std::vector<double> relative_errors;  // |dk| / |k| where |k| h >= 1e-2
  double max_direction_excess = 0;      // max angle / (1e-5 kappa / gap); must stay <= 1
  int class_mismatches = 0;             // all near a threshold
  int unexplained_class_mismatches = 0;
  double max_residual_error = 0;  // max |dr| / (kappa h): residuals are slopes ~ kappa h
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// Compares `got` with the CPU's `want` vertex by vertex (see the file comment for the bounds).
Comparison compare(const CurvatureResult& want, const CurvatureResult& got, double h,
                   const CurvatureOptions& o) {
  Comparison c;
  const double zero = o.tolerances.zero / h;
  for (Eigen::Index i = 0; i < want.k1.size(); ++i) {
    EXPECT_EQ(got.rays_used[i], want.rays_used[i]) << "vertex " << i;
    EXPECT_EQ(got.rays_excluded[i], want.rays_excluded[i]) << "vertex " << i;
    if (got.point_class[i] != want.point_class[i]) {
      ++c.class_mismatches;
      const double kappa = std::max(std::abs(want.k1[i]), std::abs(want.k2[i]));
      if (!std::isfinite(kappa) ||
          !near_class_threshold(want.k1[i], want.k2[i], zero, o.tolerances.umbilic, 1e-5 * kappa)) {
        ++c.unexplained_class_mismatches;
      }
    }
    if (!std::isfinite(want.k1[i]) || !std::isfinite(got.k1[i])) continue;
    const double kappa = std::max(std::abs(want.k1[i]), std::abs(want.k2[i]));
    for (const auto& [a, b] :
         {std::pair{want.k1[i], got.k1[i]}, std::pair{want.k2[i], got.k2[i]}}) {
      c.max_kappa_error = std::max(c.max_kappa_error, std::abs(a - b) / kappa);
      if (std::abs(a) * h >= 1e-2) c.relative_errors.push_back(std::abs(a - b) / std::abs(a));
    }
    const double gap = want.k1[i] - want.k2[i];
    if (gap >= 1e-3 * kappa) {
      // The angle from the cross product: acos of the dot product would read the float
      // vector's length error (1 - 6e-8) as an angle of sqrt(2 x 6e-8) = 3.5e-4.
      const Eigen::Vector3d a = want.d1.row(i), b = got.d1.row(i);
      const double angle = std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
      const double bound = 1e-5 * kappa / gap;
      c.max_direction_excess = std::max(c.max_direction_excess, angle / bound);
    }
    c.max_residual_error =
        std::max(c.max_residual_error, std::abs(want.residual[i] - got.residual[i]) / (kappa * h));
  }
  return c;
}

void expect_float_agreement(const Comparison& c, const std::string& name) {
  const std::vector<double>& r = c.relative_errors;
  std::printf(
      "%-36s |dk|/kappa max %.2e; |dk|/|k| (|k|h>=1e-2, %zu values) max %.2e median %.2e; "
      "d1 excess %.2f; residual err/(kappa h) %.2e; class mismatches %d\n",
      name.c_str(), c.max_kappa_error, r.size(),
      r.empty() ? 0.0 : *std::max_element(r.begin(), r.end()), median(r), c.max_direction_excess,
      c.max_residual_error, c.class_mismatches);
  EXPECT_LT(c.max_kappa_error, 1e-5) << name;
  for (double e : r) ASSERT_LT(e, 1e-4) << name;
  EXPECT_LE(c.max_direction_excess, 1.0) << name;
  // Residuals are sums of squared misfits far below kappa h: their float error is the rounding
  // of the misfits' terms (~ u kappa h), bounded with 100x headroom.
  EXPECT_LT(c.max_residual_error, 1e-5) << name;
  EXPECT_EQ(c.unexplained_class_mismatches, 0) << name;
}

// --- (a) the kernel's math on the CPU -------------------------------------------------------

TEST(CudaVertexFitOnHost, FloatMatchesCpuEstimator) {
  for (const Case& k : cases()) {
    const Mesh m = mesh_of(k);
    const CurvatureOptions o = options_of(k);
    const CurvatureResult want = estimate_curvature(m.V, m.F, m.N, o);
    const CurvatureResult got = cuda::fit_vertices_on_host<float>(m.V, m.F, m.N, o);
    expect_float_agreement(compare(want, got, mean_edge_length(m.V, m.F), o), k.name);
  }
}

TEST(CudaVertexFitOnHost, DoubleReproducesCpuEstimator) {
  for (const Case& k : cases()) {
    const Mesh m = mesh_of(k);
    const CurvatureOptions o = options_of(k);
    const CurvatureResult want = estimate_curvature(m.V, m.F, m.N, o);
    const CurvatureResult got = cuda::fit_vertices_on_host<double>(m.V, m.F, m.N, o);
    const Comparison c = compare(want, got, mean_edge_length(m.V, m.F), o);
    EXPECT_LT(c.max_kappa_error, 1e-10) << k.name;
    EXPECT_LT(c.max_residual_error, 1e-10) << k.name;
    EXPECT_EQ(c.class_mismatches, 0) << k.name;
  }
}

// Far from the origin and in tiny units, float coordinates alone would lose the edge: the hi/lo
// pairs and the power-of-two length unit keep the same accuracy (a mesh at 1e4 radii from the
// origin, scaled by 1e-6: plain float coordinates would be off by 1.4e-3 / 2.3e4 of their size,
// 1.5% of an edge length).
// hi + lo carry each coordinate to about 48 bits (2 x 24): |hi + lo - x| <= 2^-47 |x| (the
// rounding of lo). Guards the split against the compiler: g++ 12 -O3 once gave lo = 0 for two
// of three coordinates when it was inlined into a loop.
TEST(CudaVertexFitOnHost, RecordsCarryPositionsAndNormalsToAbout48Bits) {
  const Mesh m =
      test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, 4000, 0.0, 1).mesh;
  const cuda::PreparedVertexFit<float> p = cuda::prepare_vertex_fit<float>(m.V, m.F, m.N, {});
  std::vector<cuda::VertexRecord<float>> renormalised = p.vertices;
  const RowMatrixX3d N2 = 3.0 * m.N;  // any length: the records hold the unit normal
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) cuda::set_record_normal(N2, i, renormalised[i]);
  const double bound = std::ldexp(1.0, -47);
  const double unit = cuda::length_unit(mean_edge_length(m.V, m.F), 1);
  int bad = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const cuda::VertexRecord<float>& r = p.vertices[static_cast<std::size_t>(i)];
    const cuda::VertexRecord<float>& q = renormalised[static_cast<std::size_t>(i)];
    const Eigen::RowVector3d n = m.N.row(i).normalized();
    for (int c = 0; c < 3; ++c) {
      const double x = m.V(i, c) / unit;
      bad += !(std::abs(double(r.position_hi[c]) + double(r.position_lo[c]) - x) <=
               bound * std::abs(x));
      bad += !(std::abs(double(r.normal_hi[c]) + double(r.normal_lo[c]) - n[c]) <= bound);
      bad += !(std::abs(double(q.normal_hi[c]) + double(q.normal_lo[c]) - n[c]) <= bound);
    }
  }
  EXPECT_EQ(bad, 0);
}

TEST(CudaVertexFitOnHost, FloatAccuracyIndependentOfPlacementAndUnits) {
  Mesh m = test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, 4000, 0.0, 1).mesh;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    m.V.row(i) = (m.V.row(i) + Eigen::RowVector3d(1e4, -2e4, 5e3)) * 1e-6;
  }
  const CurvatureOptions o;
  const CurvatureResult want = estimate_curvature(m.V, m.F, m.N, o);
  const CurvatureResult got = cuda::fit_vertices_on_host<float>(m.V, m.F, m.N, o);
  expect_float_agreement(compare(want, got, mean_edge_length(m.V, m.F), o),
                         "torus far, 1e-6 units");
}

// Invalid normals and positions: the same vertices undefined, NaN fields and ray counts as the CPU.
TEST(CudaVertexFitOnHost, DegenerateInputFlaggedAsOnCpu) {
  Mesh m =
      test::analytic_surface(SurfaceKind::ellipsoid, Triangulation::irregular, 500, 0.0, 1).mesh;
  m.N.row(3).setZero();
  m.N(7, 0) = std::nan("");
  m.V(11, 2) = std::numeric_limits<double>::infinity();
  m.N.row(20) = -m.N.row(20);  // its neighbours exclude its ray (outside their hemisphere)
  const CurvatureOptions o;
  const CurvatureResult want = estimate_curvature(m.V, m.F, m.N, o);
  const CurvatureResult got = cuda::fit_vertices_on_host<float>(m.V, m.F, m.N, o);
  for (int i : {3, 7}) {
    EXPECT_EQ(got.class_of(i), PointClass::undefined);
    EXPECT_TRUE(std::isnan(got.k1[i]) && std::isnan(got.d1(i, 0)) && std::isnan(got.residual[i]));
  }
  int excluded = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    EXPECT_EQ(got.point_class[i], want.point_class[i]) << "vertex " << i;
    EXPECT_EQ(got.rays_used[i], want.rays_used[i]) << "vertex " << i;
    EXPECT_EQ(got.rays_excluded[i], want.rays_excluded[i]) << "vertex " << i;
    excluded += got.rays_excluded[i];
  }
  EXPECT_GT(excluded, 0);
}

TEST(CudaVertexFitOnHost, RejectsWhatTheDeviceDoesNotRun) {
  const Mesh m = test::flat_grid(4);
  CurvatureOptions o;
  o.method = Method::triangle;
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(m.V, m.F, m.N, o), InvalidInput);
  o = {};
  o.solver = Solver::levenberg_marquardt;
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(m.V, m.F, m.N, o), InvalidInput);
  o = {};
  o.rings = 0;
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(m.V, m.F, m.N, o), InvalidInput);
  o = {};
  o.gaussian_width = -1.0;
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(m.V, m.F, m.N, o), InvalidInput);
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(m.V, m.F, m.N.topRows(3), {}), InvalidInput);
  RowMatrixX3i bad = m.F;
  bad(0, 0) = 99;
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(m.V, bad, m.N, {}), InvalidInput);
  const RowMatrixX3d tiny = m.V * 1e-40;  // edge length beyond float's range
  EXPECT_THROW((void)cuda::prepare_vertex_fit<float>(tiny, m.F, m.N, {}), InvalidInput);
}

// --- (b) on a GPU -----------------------------------------------------------------------------

TEST(CudaVertexFitOnDevice, MatchesCpuEstimator) {
  FOCAL_NEEDS_GPU();
  for (const Case& k : cases()) {
    const Mesh m = mesh_of(k);
    const CurvatureOptions o = options_of(k);
    const CurvatureResult want = estimate_curvature(m.V, m.F, m.N, o);
    const CurvatureResult got = estimate_curvature_cuda(m.V, m.F, m.N, o);
    expect_float_agreement(compare(want, got, mean_edge_length(m.V, m.F), o), k.name + " (GPU)");
  }
}

TEST(CudaVertexFitOnDevice, InvalidInputBeforeAnyWork) {
  FOCAL_NEEDS_GPU();
  const Mesh m = test::flat_grid(4);
  CurvatureOptions o;
  o.method = Method::triangle;
  EXPECT_THROW((void)estimate_curvature_cuda(m.V, m.F, m.N, o), InvalidInput);
  EXPECT_THROW((void)estimate_curvature_cuda(m.V, m.F, m.N.topRows(3)), InvalidInput);
  const RowMatrixX3d none(0, 3);
  const CurvatureResult empty = estimate_curvature_cuda(none, RowMatrixX3i(0, 3), none);
  EXPECT_EQ(empty.k1.size(), 0);
}

/// Bit for bit (NaN rows included): the same kernel on the same data.
void expect_identical(const CurvatureResult& a, const CurvatureResult& b, const std::string& what) {
  const auto same = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           std::memcmp(x.data(), y.data(),
                       static_cast<std::size_t>(x.size()) * sizeof(*x.data())) == 0;
  };
  EXPECT_TRUE(same(a.k1, b.k1) && same(a.k2, b.k2) && same(a.H, b.H) && same(a.K, b.K) &&
              same(a.residual, b.residual) && same(a.d1, b.d1) && same(a.d2, b.d2) &&
              same(a.point_class, b.point_class) && same(a.rays_used, b.rays_used) &&
              same(a.rays_excluded, b.rays_excluded))
      << what;
}

TEST(CudaVertexFitOnDevice, AContextsEstimatesAreTheOneShotCallsBitsAsNormalsChange) {
  FOCAL_NEEDS_GPU();
  for (const Case& k : cases()) {
    const Mesh m = mesh_of(k);
    const CurvatureOptions o = options_of(k);
    CurvatureCudaContext context(m.V, m.F, m.N, o);
    EXPECT_EQ(context.vertex_count(), m.V.rows());
    expect_identical(context.estimate(), estimate_curvature_cuda(m.V, m.F, m.N, o), k.name);
    // Other normals: inward, then a rotation of some, a zero row and a NaN row.
    const RowMatrixX3d inward = -m.N;
    context.set_normals(inward);
    expect_identical(context.estimate(), estimate_curvature_cuda(m.V, m.F, inward, o),
                     k.name + " inward");
    RowMatrixX3d tilted = m.N;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).matrix();
    for (Eigen::Index i = 0; i < tilted.rows(); i += 3) tilted.row(i) *= turn.transpose();
    tilted.row(1).setZero();
    tilted(2, 0) = NAN;
    context.set_normals(tilted);
    expect_identical(context.estimate(), estimate_curvature_cuda(m.V, m.F, tilted, o),
                     k.name + " tilted");
  }
}

TEST(CudaVertexFitOnDevice, AContextRejectsNormalsOfAnotherMesh) {
  FOCAL_NEEDS_GPU();
  const Mesh m = test::flat_grid(4);
  CurvatureCudaContext context(m.V, m.F, m.N);
  EXPECT_THROW(context.set_normals(m.N.topRows(3)), InvalidInput);
  expect_identical(context.estimate(), estimate_curvature_cuda(m.V, m.F, m.N), "after the error");
  CurvatureOptions o;
  o.method = Method::triangle;
  EXPECT_THROW(CurvatureCudaContext(m.V, m.F, m.N, o), InvalidInput);
}

// --- (c) device errors --------------------------------------------------------------------

TEST(CudaVertexFitErrors, StandInThrowsDeviceErrorWithoutBackend) {
  if (cuda_built()) GTEST_SKIP() << "this build has the CUDA backend; the stand-in is not linked";
  const Mesh m = test::flat_grid(4);
  EXPECT_THROW((void)estimate_curvature_cuda(m.V, m.F, m.N), DeviceError);
  EXPECT_THROW(CurvatureCudaContext(m.V, m.F, m.N), DeviceError);
}

TEST(CudaVertexFitErrors, BadDeviceIndexThrowsDeviceError) {
  const Mesh m = test::flat_grid(4);
  EXPECT_THROW((void)estimate_curvature_cuda(m.V, m.F, m.N, {}, -1), DeviceError);
  EXPECT_THROW((void)estimate_curvature_cuda(m.V, m.F, m.N, {}, 1 << 20), DeviceError);
  EXPECT_THROW(CurvatureCudaContext(m.V, m.F, m.N, {}, -1), DeviceError);
}

}  // namespace
}  // namespace focal
