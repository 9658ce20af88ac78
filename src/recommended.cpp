#include "focal/recommended.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "curvature_detail.h"
#include "focal/error.h"
#include "focal/neighbourhood.h"
#include "focal/normal_estimation.h"
#include "focal/normals.h"
#include "parallel.h"

namespace focal {
namespace {

/// Everything the steps share: the mesh, its 1-ring (built once) and its edge length.
struct Context {
  PositionsRef V;
  FacesRef F;
  Neighbourhoods one_ring;
  double edge_length;
  int threads;
};

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
  return jet_normals(c.V, c.F, c.one_ring, o);
}

/// Per vertex, the primary normal unless the secondary field is clearly smoother there: its
/// 1-ring two-slit residual (RMS misfit of the rays, slope units) below kSmootherRatio times the
/// primary's. On clean data the two residuals measure the same truncation error and the primary
/// is kept (so exact normals stay exact); 5% normal noise makes file normals 5 to 50 times
/// rougher than jets, 10% vertex noise makes jets 5 to 10 times rougher than exact normals.
/// `roughness` receives the chosen field's residual per vertex.
RowMatrixX3d select_normals(NormalsRef primary, const Eigen::VectorXd& primary_roughness,
                            NormalsRef secondary, const Eigen::VectorXd& secondary_roughness,
                            int threads, Eigen::VectorXd& roughness) {
  RowMatrixX3d out(primary.rows(), 3);
  roughness.resize(primary.rows());
  detail::parallel_for(primary.rows(), threads, [&](std::int64_t i) {
    const Eigen::Vector3d a = primary.row(i).normalized().transpose();
    const Eigen::Vector3d b = secondary.row(i).normalized().transpose();
    const double ra = primary_roughness[i], rb = secondary_roughness[i];
    // A field without a fit at i (too few rays, invalid normal) never wins over one with a fit.
    const bool b_fits = std::isfinite(rb), a_fits = std::isfinite(ra);
    const bool take_b =
        b.allFinite() && (!a.allFinite() || (b_fits && (!a_fits || rb < kSmootherRatio * ra)));
    out.row(i) = (take_b ? b : a).transpose();
    roughness[i] = take_b ? rb : ra;
  });
  return out;
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
  const Context c{V, F, vertex_adjacency(static_cast<int>(V.rows()), F), mean_edge_length(V, F),
                  threads};
  const JetNormals jets = local_jets(c, 2, 3);
  return recommended_plan_for_noise(finite_median(jets.residual) / c.edge_length);
}

RecommendedResult estimate_curvature_recommended_full(PositionsRef V, FacesRef F, NormalsRef N,
                                                      int threads) {
  const bool file_normals = N.rows() > 0;
  if (file_normals && N.rows() != V.rows())
    throw InvalidInput("estimate_curvature_recommended: " + std::to_string(N.rows()) +
                       " normals for " + std::to_string(V.rows()) + " vertices");
  validate_mesh_arrays(V, F, N, "estimate_curvature_recommended");
  if (threads < 0) throw InvalidInput("estimate_curvature_recommended: threads must be >= 0");
  const Context c{V, F, vertex_adjacency(static_cast<int>(V.rows()), F), mean_edge_length(V, F),
                  threads};
  JetNormals jets = local_jets(c, 2, 3);
  RecommendedResult out;
  out.plan = recommended_plan_for_noise(finite_median(jets.residual) / c.edge_length);
  if (!file_normals && out.plan.rings > 1) {
    // Noisy positions: normals from wider, lower-degree jets that average the noise.
    out.N = local_jets(c, out.plan.jet_rings, out.plan.jet_degree).N;
  } else {
    // The file's normals where the jets' are not clearly smoother (two-slit residuals), so
    // that exact normals stay exact and noisy ones are replaced. Without file normals, the jets
    // where Max's normals are not clearly smoother: Max's are exact on spheres, but first-order
    // (rough) on irregular meshes.
    const RowMatrixX3d max = vertex_normals(V, F, NormalWeighting::max);
    const CurvatureResult with_max = two_slit_fit(c, max, 1, false);
    const CurvatureResult with_jets = two_slit_fit(c, jets.N, 1, false);
    Eigen::VectorXd roughness;
    out.N = select_normals(jets.N, with_jets.residual, max, with_max.residual, threads, roughness);
    if (file_normals) {
      // The file's normals unless the positions' (jets or Max) are clearly smoother.
      const CurvatureResult with_file = two_slit_fit(c, N, 1, false);
      Eigen::VectorXd unused;
      out.N = select_normals(N, with_file.residual, out.N, roughness, threads, unused);
    }
  }
  out.curvature = two_slit_fit(c, out.N, out.plan.rings, out.plan.gaussian);
  if (out.plan.rings == 1) prefer_triangles(V, F, out.N, threads, out.curvature);
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
