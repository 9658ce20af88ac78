#include "focal/curvature/recommended.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "curvature/curvature_detail.h"
#include "curvature/detail.h"
#include "focal/core/error.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/normals.h"
#include "focal/normals/jets.h"

namespace focal {
namespace {

/// Everything the steps share: the mesh, its 1-ring (built once), its edge length and Max's
/// normals (the jets' starting frames, and a candidate field of their own).
struct Context {
  PositionsRef V;
  FacesRef F;
  Neighbourhoods one_ring;
  double edge_length;
  int threads;
  RowMatrixX3d max;
};

Context make_context(PositionsRef V, FacesRef F, int threads) {
  return {V,
          F,
          vertex_adjacency(static_cast<int>(V.rows()), F),
          mean_edge_length(V, F),
          threads,
          vertex_normals(V, F, NormalWeighting::max)};
}

/// The paper's per-vertex closed-form two-slit fit of `normals` over `rings` rings, on the
/// 1-ring built once (estimate_curvature would rebuild it per call).
CurvatureResult two_slit_fit(const Context& c, NormalsRef normals, int rings, bool gaussian) {
  CurvatureOptions o;
  o.rings = rings;
  o.weighting = gaussian && rings > 1 ? RayWeighting::gaussian : RayWeighting::uniform;
  o.threads = c.threads;
  std::vector<char> ok;
  const RowMatrixX3d unit = detail::unit_rows(normals, ok, c.threads);
  if (rings == 1) return detail::fit_vertices({c.V, unit, ok, c.one_ring, c.edge_length}, o);
  const Neighbourhoods ring = k_ring(c.one_ring, rings);
  return detail::fit_vertices({c.V, unit, ok, ring, c.edge_length}, o);
}

/// How rough a normal field is at each vertex: the RMS misfit (residual, slope units) of its
/// 1-ring two-slit fit, NaN (no usable fit) where the fit had to leave out a neighbour's ray —
/// a normal more than 90 degrees from the vertex's, as a flipped or wild normal makes it; the
/// residual of the few rays left says nothing then.
Eigen::VectorXd roughness_of(const CurvatureResult& fit) {
  Eigen::VectorXd r = fit.residual;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    if (fit.rays_excluded[i] > 0) r[i] = NAN;
  }
  return r;
}

/// select_normals: how much smoother (two-slit residual) the secondary normals must be.
constexpr double kSmootherRatio = 0.5;

/// Median of the finite entries; NaN when there are none.
double finite_median(const Eigen::VectorXd& x) {
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(x.size()));
  for (double e : x) {
    if (std::isfinite(e)) v.push_back(e);
  }
  if (v.empty()) return NAN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

JetNormals local_jets(const Context& c, int rings, int degree) {
  JetOptions o;
  o.rings = rings;
  o.degree = degree;
  o.iterations = 1;
  o.threads = c.threads;
  return jet_normals(c.V, c.F, c.one_ring, c.max, o);
}

/// Per vertex, the primary normal unless the secondary field is clearly smoother there: its
/// 1-ring two-slit residual (RMS misfit of the rays, slope units) below kSmootherRatio times the
/// primary's. On clean data the two residuals measure the same truncation error and the primary
/// is kept; 10% vertex noise makes jets 5 to 10 times rougher than exact normals. Only vertices
/// where `may_replace(i)` holds are considered. `roughness` receives the chosen field's residual.
template <class MayReplace>
RowMatrixX3d select_normals(NormalsRef primary, const Eigen::VectorXd& primary_roughness,
                            NormalsRef secondary, const Eigen::VectorXd& secondary_roughness,
                            int threads, Eigen::VectorXd& roughness, MayReplace may_replace) {
  RowMatrixX3d out(primary.rows(), 3);
  roughness.resize(primary.rows());
  detail::parallel_for(primary.rows(), threads, [&](std::int64_t i) {
    const Eigen::Vector3d a = primary.row(i).normalized().transpose();
    const Eigen::Vector3d b = secondary.row(i).normalized().transpose();
    const double ra = primary_roughness[i], rb = secondary_roughness[i];
    // A field without a fit at i (too few rays, invalid normal) never wins over one with a fit.
    const bool b_fits = std::isfinite(rb), a_fits = std::isfinite(ra);
    const bool smoother = b_fits && (!a_fits || rb < kSmootherRatio * ra);
    const bool take_b = b.allFinite() && (!a.allFinite() || (smoother && may_replace(i)));
    out.row(i) = (take_b ? b : a).transpose();
    roughness[i] = take_b ? rb : ra;
  });
  return out;
}

/// The file's normals, replaced by the positions' (`from_positions`, rated `its_roughness`) only
/// at outliers: where a file normal is unusable or gives no fit, or where it is more than `limit`
/// radians from the jet normal and the positions' normal is clearly smoother. On a file whose
/// normals agree with the positions, such vertices are isolated bad normals; elsewhere the exact
/// normals stay exact (replacing them where two truncation-level residuals happen to differ by 2x
/// cost up to 0.5% of H error on clean irregular meshes).
RowMatrixX3d replace_outliers(NormalsRef file, const Eigen::VectorXd& file_roughness,
                              const Eigen::VectorXd& disagreement, NormalsRef from_positions,
                              const Eigen::VectorXd& its_roughness, double limit, int threads) {
  Eigen::VectorXd unused;
  return select_normals(file, file_roughness, from_positions, its_roughness, threads, unused,
                        [&](std::int64_t i) {
                          return !(disagreement[i] <= limit) || !std::isfinite(file_roughness[i]);
                        });
}

/// +1 when most usable rows of `file` point to the side of `estimated`, -1 when most point
/// against it (a file whose normals point inward while the faces turn outward).
double majority_side(NormalsRef file, NormalsRef estimated) {
  Eigen::Index along = 0, against = 0;
  for (Eigen::Index i = 0; i < file.rows(); ++i) {
    const double d = file.row(i).dot(estimated.row(i));
    along += d > 0.0;
    against += d < 0.0;
  }
  return against > along ? -1.0 : 1.0;
}

/// Angle (radians) between the rows of A and side * B: NaN where a row is zero or not finite.
Eigen::VectorXd angles_between(NormalsRef A, NormalsRef B, double side, int threads) {
  Eigen::VectorXd angle(A.rows());
  detail::parallel_for(A.rows(), threads, [&](std::int64_t i) {
    const Eigen::Vector3d a = A.row(i).transpose(), b = side * B.row(i).transpose();
    const bool usable = a.allFinite() && b.allFinite() && a != Eigen::Vector3d::Zero() &&
                        b != Eigen::Vector3d::Zero();
    angle[i] = usable ? std::atan2(a.cross(b).norm(), a.dot(b)) : NAN;
  });
  return angle;
}

/// The file's normals agree with the positions when their median angle to the jet normals is
/// within kAgreement times the position noise. The jets' own normal error is about the noise
/// (median angle / noise measured 0.8 to 1.05 with exact file normals under 10% vertex noise, 0.09
/// to 0.95 on clean meshes), so a median angle beyond twice it means file normals whose own
/// error is larger than the jets' (measured 5.3 to 4600 under 5% normal noise).
constexpr double kAgreement = 2.0;

/// replace_outliers: a file normal that agrees with the positions as a whole is an outlier
/// candidate where it is more than this many times the noise from the jet normal: an order of
/// magnitude beyond the jets' own error. (The suite's results are the same for 4, 10 and no
/// replacement at all; the factor matters for files with isolated bad normals.)
constexpr double kOutlierDisagreement = 10.0;

bool file_normals_agree(double median_angle, double noise) {
  if (!std::isfinite(median_angle)) return false;  // no normal of the file is usable
  if (!std::isfinite(noise)) return true;          // no jets to judge them by
  // Angles at rounding level agree whatever the noise (a plane has noise 0).
  return median_angle <= std::max(kAgreement * noise, 1e-12);
}

/// A 1-ring fit residual (RMS ray misfit, slope units) at or below this is rounding: the rays
/// meet two slits exactly (spheres, cylinders, planes), and so does the fit.
constexpr double kExactFitResidual = 1e-9;

void copy_vertex(const CurvatureResult& from, Eigen::Index i, CurvatureResult& to) {
  for (auto field : {&CurvatureResult::k1, &CurvatureResult::k2, &CurvatureResult::H,
                     &CurvatureResult::K, &CurvatureResult::residual}) {
    (to.*field)[i] = (from.*field)[i];
  }
  to.d1.row(i) = from.d1.row(i);
  to.d2.row(i) = from.d2.row(i);
  to.point_class[i] = from.point_class[i];
  to.rays_used[i] = from.rays_used[i];
  to.rays_excluded[i] = from.rays_excluded[i];
}

/// On clean positions, the per-triangle characteristic equation averaged to the vertices
/// (Method::triangle) is more accurate than the 1-ring fit on irregular meshes (measured 1.3 to
/// 1.8 times lower H error, docs/ESTIMATOR.md), but only second-order exact where the fit is
/// exact: `fit` keeps its rows where its residual says the rays fit exactly, or where the
/// triangles give no estimate, and takes the triangles' elsewhere.
void prefer_triangles(PositionsRef V, FacesRef F, NormalsRef N, int threads, CurvatureResult& fit) {
  CurvatureOptions o;
  o.method = Method::triangle;
  o.threads = threads;
  const CurvatureResult triangles = estimate_curvature(V, F, N, o);
  detail::parallel_for(V.rows(), threads, [&](std::int64_t i) {
    const bool exact_fit = fit.residual[i] <= kExactFitResidual;
    const bool triangles_defined = triangles.class_of(static_cast<int>(i)) != PointClass::undefined;
    if (!exact_fit && triangles_defined) copy_vertex(triangles, i, fit);
  });
}

/// Steps 1 to 3 of recommended.h: the plan (from the jets' residuals), whether the file's
/// normals are used, and the normals to fit, into `out`. N has 0 rows without file normals.
void choose_normals(const Context& c, NormalsRef N, RecommendedResult& out) {
  const bool has_normals = N.rows() > 0;
  const JetNormals jets = local_jets(c, 2, 3);
  out.plan = recommended_plan_for_noise(finite_median(jets.residual) / c.edge_length);
  // The file's normals decide the side (the sign of the curvature), as in estimate_curvature;
  // normals from the positions take the side of the faces until turned.
  const double side = has_normals ? majority_side(N, jets.N) : 1.0;
  const Eigen::VectorXd disagreement =
      has_normals ? angles_between(N, jets.N, side, c.threads) : Eigen::VectorXd();
  out.file_disagreement = has_normals ? finite_median(disagreement) : NAN;
  out.file_normals_used = has_normals && file_normals_agree(out.file_disagreement, out.plan.noise);
  Eigen::VectorXd roughness;
  if (!out.file_normals_used && out.plan.rings > 1) {
    // Noisy positions: normals from wider, lower-degree jets that average the noise.
    out.N = local_jets(c, out.plan.jet_rings, out.plan.jet_degree).N;
  } else {
    // The jets where Max's normals are not clearly smoother: Max's are exact on spheres, but
    // first-order (rough) on irregular meshes.
    const CurvatureResult with_max = two_slit_fit(c, c.max, 1, false);
    const CurvatureResult with_jets = two_slit_fit(c, jets.N, 1, false);
    out.N = select_normals(jets.N, roughness_of(with_jets), c.max, roughness_of(with_max),
                           c.threads, roughness, [](std::int64_t) { return true; });
  }
  if (side < 0.0) out.N = -out.N;  // the fit's residuals do not change: rays are the same lines
  if (out.file_normals_used) {
    // The file's normals, except outliers where the positions' choice is clearly smoother.
    const CurvatureResult with_file = two_slit_fit(c, N, 1, false);
    out.N = replace_outliers(N, roughness_of(with_file), disagreement, out.N, roughness,
                             kOutlierDisagreement * out.plan.noise, c.threads);
  }
}

}  // namespace

RecommendedPlan recommended_plan_for_noise(double noise) {
  RecommendedPlan plan;
  plan.noise = noise;
  if (!(noise > kNoiseForTwoRings)) return plan;  // also NaN: no estimate, keep the 1-ring
  plan.rings = noise > kNoiseForThreeRings ? 3 : 2;
  plan.gaussian = true;
  plan.jet_rings = plan.rings + 1;
  plan.jet_degree = 2;
  return plan;
}

RecommendedPlan recommended_plan(PositionsRef V, FacesRef F, int threads) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "recommended_plan");
  if (threads < 0) throw InvalidInput("recommended_plan: threads must be >= 0");
  const Context c = make_context(V, F, threads);
  const JetNormals jets = local_jets(c, 2, 3);
  return recommended_plan_for_noise(finite_median(jets.residual) / c.edge_length);
}

RecommendedResult estimate_curvature_recommended_full(PositionsRef V, FacesRef F, NormalsRef N,
                                                      int threads) {
  const bool has_normals = N.rows() > 0;
  if (has_normals && N.rows() != V.rows())
    throw InvalidInput("estimate_curvature_recommended: " + std::to_string(N.rows()) +
                       " normals for " + std::to_string(V.rows()) + " vertices");
  validate_mesh_arrays(V, F, N, "estimate_curvature_recommended");
  if (threads < 0) throw InvalidInput("estimate_curvature_recommended: threads must be >= 0");
  Context c = make_context(V, F, threads);
  RecommendedResult out;
  choose_normals(c, N, out);
  out.curvature = two_slit_fit(c, out.N, out.plan.rings, out.plan.gaussian);
  if (out.plan.rings == 1) {
    // Memory the per-triangle pass can use (the peak of a run is in it).
    c.one_ring = Neighbourhoods{};
    c.max.resize(0, 3);
    prefer_triangles(V, F, out.N, threads, out.curvature);
  }
  return out;
}

CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F, NormalsRef N,
                                               int threads) {
  if (N.rows() != V.rows())
    throw InvalidInput("estimate_curvature_recommended: " + std::to_string(N.rows()) +
                       " normals for " + std::to_string(V.rows()) + " vertices");
  return estimate_curvature_recommended_full(V, F, N, threads).curvature;
}

CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F, int threads) {
  return estimate_curvature_recommended_full(V, F, RowMatrixX3d(0, 3), threads).curvature;
}

}  // namespace focal
