#include "focal/curvature/cloud_curvature.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/spatial_order.h"
#include "curvature/corrected_step.h"
#include "curvature/normal_choice.h"
#include "curvature/robust_fit.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/normals/vertex_normals.h"
#include "focal/points/neighbours.h"
#include "mesh/prepared_access.h"
#include "normals/cloud_jets.h"
#include "normals/vertex_normals_from.h"
#include "points/measured_neighbours.h"
#include "points/natural_ring.h"

namespace focal {
namespace {

/// Radius neighbourhoods keep at most this many (the nearest): a radius far larger than the
/// spacing would otherwise make the lists, and the fit, quadratic in the density.
constexpr int kMaxRadiusNeighbours = 1024;

/// The default's plan (cloud_curvature.h; measured in docs/POINTS.md): above this noise (median
/// jet residual / mean spacing) positions are noisy and the neighbourhood grows by this factor
/// (16 -> 64: on 10% noise, the H error of 64 neighbours was 1.2-9x below that of 16 on sphere,
/// ellipsoid, torus and saddle; 2.2x above on the helix tube) ...
constexpr double kNoisyPositions = 0.03;
constexpr int kNoisyNeighbourFactor = 4;
/// ... and the cloud's normals are used when their median angle to the jet normals is at most
/// this many times the noise.
constexpr double kFileAgreement = 2.5;

/// The default's plan runs when no neighbourhood is given.
bool uses_plan(const CloudOptions& o) {
  return o.k == 0 && o.radius == 0.0 && o.adaptive_radius == 0.0;
}

void validate(PositionsRef V, std::optional<NormalsRef> N, const CloudOptions& o) {
  if (o.k < 0) throw InvalidInput("cloud curvature: k must be >= 0, got " + std::to_string(o.k));
  if (!(o.radius >= 0.0)) throw InvalidInput("cloud curvature: radius must be >= 0");
  if (!(o.adaptive_radius >= 0.0) || !std::isfinite(o.adaptive_radius)) {
    throw InvalidInput("cloud curvature: adaptive_radius must be finite and >= 0");
  }
  if (!(o.outlier_ratio == 0.0 || (o.outlier_ratio > 1.0 && std::isfinite(o.outlier_ratio)))) {
    throw InvalidInput("cloud curvature: outlier_ratio must be 0 (off) or finite and > 1, got " +
                       std::to_string(o.outlier_ratio));
  }
  if (!(o.off_surface_ratio == 0.0 ||
        (o.off_surface_ratio > 1.0 && std::isfinite(o.off_surface_ratio)))) {
    throw InvalidInput(
        "cloud curvature: off_surface_ratio must be 0 (off) or finite and > 1, got " +
        std::to_string(o.off_surface_ratio));
  }
  if (N && N->rows() != V.rows()) {
    throw InvalidInput("cloud curvature: " + std::to_string(N->rows()) + " normals for " +
                       std::to_string(V.rows()) + " points");
  }
}

/// The neighbourhoods the options select, leaving out the `excluded` points (or none). The k
/// nearest of a cloud's spatially ordered copy order their ties by `tie_rows` (the copy's rows
/// in the cloud: detail::nearest_neighbours); the radius ones are never asked for on a copy.
Neighbourhoods neighbourhoods_without(PositionsRef V, const CloudOptions& options,
                                      const std::vector<char>& excluded,
                                      const std::vector<int>& tie_rows = {}) {
  if (options.k < 0 || !(options.radius >= 0.0)) {
    throw InvalidInput("cloud neighbourhoods: k and radius must be >= 0");
  }
  if (options.radius > 0.0) {
    return radius_neighbours(V, options.radius, kMaxRadiusNeighbours, excluded);
  }
  const int k = options.k > 0 ? options.k : default_cloud_neighbours;
  if (options.adaptive_radius > 0.0) {
    return adaptive_radius_neighbours(V, k, options.adaptive_radius, kMaxRadiusNeighbours,
                                      excluded);
  }
  return detail::nearest_neighbours(V, k, excluded, 0, tie_rows);
}

bool any_flag(const std::vector<char>& flags) {
  return std::find(flags.begin(), flags.end(), 1) != flags.end();
}

bool tests_on(const CloudOptions& o) { return o.outlier_ratio > 0.0 || o.off_surface_ratio > 0.0; }

/// The outlier tests of the options over `nearest16`, the 16 nearest of every point (with their
/// measures, points/measured_neighbours.h): statistical outliers, then points off the surface of
/// their 16 nearest among the rest. Empty when both tests are off. `tie_rows` as
/// neighbourhoods_without.
std::vector<char> outlier_flags(PositionsRef V, const detail::MeasuredNeighbours& nearest16,
                                const CloudOptions& o, const std::vector<int>& tie_rows = {}) {
  std::vector<char> flags;
  if (o.outlier_ratio > 0.0) {
    flags = detail::outlier_points(V, nearest16.neighbours, nearest16.measures.reach,
                                   o.outlier_ratio, 0);
  }
  if (o.off_surface_ratio == 0.0) return flags;
  // The planes without the isolated outliers, which would tilt them.
  std::vector<char> off;
  if (any_flag(flags)) {
    const detail::MeasuredNeighbours rest =
        detail::measured_nearest_neighbours(V, default_cloud_neighbours, flags, 0, tie_rows);
    off = detail::off_surface_points(V, rest.neighbours, rest.measures, o.off_surface_ratio, 0);
  } else {
    off = detail::off_surface_points(V, nearest16.neighbours, nearest16.measures,
                                     o.off_surface_ratio, 0);
  }
  if (flags.empty()) return off;
  for (std::size_t i = 0; i < flags.size(); ++i) flags[i] = flags[i] || off[i];
  return flags;
}

CloudNormalOptions normal_options(const CloudOptions& o) {
  CloudNormalOptions normals = o.normals;
  return normals;
}

/// Neighbours as given (k or radius), with the outlier tests and the spacing: every field of the
/// plan but N. `tie_rows` as neighbourhoods_without (only with k nearest: in_spatial_order).
CloudCurvature given_lists(PositionsRef V, const CloudOptions& options,
                           const std::vector<int>& tie_rows = {}) {
  CloudCurvature out;
  // The tests are over the 16 nearest (where their ratios were measured): the lists asked for
  // when they are those, else a query of their own.
  const bool sixteen = options.radius == 0.0 && options.adaptive_radius == 0.0 &&
                       options.k == default_cloud_neighbours;
  const auto nearest16 = [&] {
    return detail::measured_nearest_neighbours(V, default_cloud_neighbours, {}, 0, tie_rows);
  };
  if (!tests_on(options)) {
    out.neighbours = neighbourhoods_without(V, options, {}, tie_rows);
  } else if (sixteen) {
    detail::MeasuredNeighbours measured = nearest16();
    out.outlier = outlier_flags(V, measured, options, tie_rows);
    out.neighbours = any_flag(out.outlier)
                         ? neighbourhoods_without(V, options, out.outlier, tie_rows)
                         : std::move(measured.neighbours);
  } else {
    out.neighbours = neighbourhoods_without(V, options, {}, tie_rows);
    out.outlier = outlier_flags(V, nearest16(), options, tie_rows);
    if (any_flag(out.outlier))
      out.neighbours = neighbourhoods_without(V, options, out.outlier, tie_rows);
  }
  out.spacing = detail::mean_spacing(V, out.neighbours, 0, tie_rows);
  out.k = options.radius > 0.0 || options.adaptive_radius > 0.0 ? 0 : options.k;
  return out;
}

/// Neighbours as given, the cloud's normals or cloud_normals over them.
CloudCurvature given_neighbours(PositionsRef V, std::optional<NormalsRef> N,
                                const CloudOptions& options) {
  CloudCurvature out = given_lists(V, options);
  out.file_normals_used = N.has_value();
  out.normals_estimated = !N;
  out.N = N ? RowMatrixX3d(*N) : cloud_normals(V, out.neighbours, normal_options(options));
  return out;
}

double median_of(std::vector<double> values) {
  std::erase_if(values, [](double x) { return !std::isfinite(x); });
  if (values.empty()) return NAN;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// Median angle (radians) between the lines of N and M, where both are finite.
double median_angle(NormalsRef N, const RowMatrixX3d& M) {
  std::vector<double> angles(static_cast<std::size_t>(N.rows()));
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double c = std::abs(N.row(i).normalized().dot(M.row(i)));
    angles[static_cast<std::size_t>(i)] = std::acos(std::min(1.0, c));
  }
  return median_of(std::move(angles));
}

/// Clean positions, the file's normals not used (the plan's step 3): the jets' normals `jets`,
/// or Max's normals over the point's fan in its local triangulation (points/natural_ring.h)
/// where those are clearly smoother (select_normal: their two-slit residual over the point's
/// neighbours below half the jets'), as the mesh default picks between the jets and Max's
/// normals: Max's weights are exact on a sphere (Max 1999), cubic jets are not.
RowMatrixX3d with_max_normals(PositionsRef V, RowMatrixX3d jets, const Neighbourhoods& neighbours,
                              double spacing, int threads) {
  std::vector<char> ok, max_ok;
  const RowMatrixX3d J = detail::unit_rows(jets, ok, threads);
  RowMatrixX3d max;
  {
    // The fans (about 16 bytes a triangle, 9 triangles a point) let go before Max's normals are
    // made unit: together they were the default's peak of memory.
    const detail::NaturalFans fans = detail::natural_fans(V, J, ok, neighbours, threads);
    max = detail::vertex_normals_from(V, fans.F, fans.own, NormalWeighting::max, threads);
  }
  const RowMatrixX3d M = detail::unit_rows(max, max_ok, threads);
  max = RowMatrixX3d();
  CurvatureOptions fit;
  const Eigen::VectorXd rj = detail::fit_roughness({V, J, ok, neighbours, spacing}, fit);
  const Eigen::VectorXd rm = detail::fit_roughness({V, M, max_ok, neighbours, spacing}, fit);
  detail::parallel_for(V.rows(), threads, [&](std::int64_t i) {
    // Only where the jets gave a normal: a point without one has no fan either.
    if (!ok[static_cast<std::size_t>(i)]) return;
    jets.row(i) =
        detail::select_normal(J.row(i).transpose(), rj[i], M.row(i).transpose(), rm[i], true)
            .first.transpose();
  });
  return jets;
}

/// The default's plan (cloud_curvature.h, steps 1-3).
/// `copy_of`: null, or V and N are a permuted copy of the cloud (in_spatial_order), whose lists
/// take their ties and the spacing its sum by the cloud's rows, and whose MST runs over the cloud
/// in its own order.
CloudCurvature adaptive_plan(PositionsRef V, std::optional<NormalsRef> N,
                             const CloudOptions& options,
                             const detail::CloudCopy* copy_of = nullptr) {
  static const std::vector<int> own_order;
  const std::vector<int>& tie_rows = copy_of ? copy_of->permutation.order : own_order;
  const auto nearest = [&](int k, const std::vector<char>& excluded) {
    return detail::nearest_neighbours(V, k, excluded, 0, tie_rows);
  };
  CloudCurvature out;
  out.k = default_cloud_neighbours;
  if (tests_on(options)) {
    detail::MeasuredNeighbours nearest16 =
        detail::measured_nearest_neighbours(V, out.k, {}, 0, tie_rows);
    out.outlier = outlier_flags(V, nearest16, options, tie_rows);
    out.neighbours =
        any_flag(out.outlier) ? nearest(out.k, out.outlier) : std::move(nearest16.neighbours);
  } else {
    out.neighbours = nearest(out.k, {});
  }
  out.spacing = detail::mean_spacing(V, out.neighbours, 0, tie_rows);
  CloudNormalOptions normals = normal_options(options);
  // With the file's normals, the jets start on their side: the noise and the agreement below
  // need no orientation, and the MST (serial) runs only if the file's normals are not used.
  const auto fit_jets = [&] {
    return N ? detail::cloud_jets_sided(V, out.neighbours, normals, *N, copy_of)
             : detail::cloud_jets(V, out.neighbours, normals, copy_of);
  };
  // The global orientation only on the fit that is kept: the first fit, whose residuals may
  // call for another, starts from the tree's signs (the residuals do not depend on them).
  const bool deferred = !N && normals.orientation == CloudOrientation::global && !normals.viewpoint;
  RowMatrixX3d start;
  JetNormals jets;
  if (deferred) {
    CloudNormalOptions by_tree = normals;
    by_tree.orientation = CloudOrientation::mst;
    jets = detail::cloud_jets(V, out.neighbours, by_tree, copy_of, &start);
  } else {
    jets = fit_jets();
  }
  out.noise = median_of({jets.residual.begin(), jets.residual.end()}) / out.spacing;
  if (out.noise > kNoisyPositions) {
    // The first fit gave its noise only: its jets and start let go before the wider lists and
    // the second fit (at 1M points their 36 B a point stood at the global orientation's peak).
    jets = JetNormals();
    start = RowMatrixX3d();
    out.k = kNoisyNeighbourFactor * default_cloud_neighbours;
    out.neighbours = Neighbourhoods();
    out.neighbours = nearest(out.k, out.outlier);
    normals.jet_degree = 2;
    jets = fit_jets();
  } else if (deferred) {
    detail::orient_jets_globally(V, out.neighbours, normals, std::move(start), jets, copy_of);
  }
  // Without jets (CloudNormalMethod::pca) there is no noise to judge by: the file's are kept.
  // 1e-9 rad: exact normals of an exactly fitted cloud (noise 0) still agree.
  out.file_normals_used = N && (!std::isfinite(out.noise) ||
                                median_angle(*N, jets.N) <= kFileAgreement * out.noise + 1e-9);
  if (N && !out.file_normals_used) {
    detail::orient_sided_jets(V, out.neighbours, normals, *N, jets, copy_of);
  }
  out.normals_estimated = !out.file_normals_used;
  out.N = std::move(jets.N);
  jets = JetNormals();  // the residuals and degrees let go before Max's normals
  if (out.k == default_cloud_neighbours && !out.file_normals_used) {
    out.N = with_max_normals(V, std::move(out.N), out.neighbours, out.spacing, 0);
  }
  if (N && !out.file_normals_used) {
    for (Eigen::Index i = 0; i < out.N.rows(); ++i) {
      if (out.N.row(i).dot(N->row(i)) < 0.0) out.N.row(i) *= -1.0;  // the file's side
    }
  }
  if (out.file_normals_used) out.N = *N;
  // The corrected step (step 5) on clean positions, and only where no point was left out as an
  // outlier: outliers too near the surface to be flagged (docs/notes/points-log.md, "Outliers")
  // enter the local triangulations, and the corrected measures, unlike the robust fit, take them
  // in.
  out.corrected = out.k == default_cloud_neighbours &&
                  std::find(out.outlier.begin(), out.outlier.end(), 1) == out.outlier.end();
  return out;
}

}  // namespace

Neighbourhoods cloud_neighbourhoods(PositionsRef V, const CloudOptions& options) {
  return neighbourhoods_without(V, options, {});
}

Neighbourhoods cloud_fit_neighbourhoods(PositionsRef V, const CloudOptions& options, int k,
                                        const std::vector<char>& excluded) {
  CloudOptions o = options;
  if (o.radius == 0.0) o.k = k;
  // No point left out: the lists of no exclusion (the same lists, as a whole run takes them).
  const bool any = std::find(excluded.begin(), excluded.end(), 1) != excluded.end();
  return neighbourhoods_without(V, o, any ? excluded : std::vector<char>{});
}

CloudCurvature plan_cloud_curvature(PositionsRef V, std::optional<NormalsRef> N,
                                    const CloudOptions& options) {
  validate(V, N, options);
  return uses_plan(options) ? adaptive_plan(V, N, options) : given_neighbours(V, N, options);
}

namespace {

/// fit_cloud_curvature; `spatial_rows`: V's rows are in a spatial order already (in_spatial_order's
/// copy), which the default's later steps then visit them in.
void fit_plan(PositionsRef V, CloudCurvature& out, const CloudOptions& options, bool spatial_rows) {
  std::vector<char> ok;
  out.N = detail::unit_rows(out.N, ok, 0);
  CurvatureOptions fit;
  fit.solver = options.solver;
  fit.levenberg_marquardt = options.levenberg_marquardt;
  fit.tolerances = options.tolerances;
  detail::validate_curvature_options(fit);
  // A spacing of 0 (a single point, or all duplicates) would make every |k| "not zero"; 1 keeps
  // the tolerance finite, and such points are undefined anyway (fewer than two rays).
  const double scale = out.spacing > 0.0 ? out.spacing : 1.0;
  const detail::VertexFitInput input{V, out.N, ok, out.neighbours, scale};
  out.curvature = detail::fit_vertices(input, fit);
  if (uses_plan(options)) {
    // Both steps below visit the points along a spatial order: each reads its neighbours' rows,
    // mostly those its predecessors have just read, where a cloud's rows often come in no order;
    // each point writes its own row only, so no bit changes.
    std::vector<int> order(static_cast<std::size_t>(V.rows()));
    if (spatial_rows) {
      std::iota(order.begin(), order.end(), 0);
    } else {
      order = detail::morton_order(V, 0);
    }
    // The default, as the mesh default on noisy positions: where rays lie far off the fit
    // (a neighbour off the surface, or with a normal bent by one), it is repeated without them
    // (curvature/robust_fit.h; clean fits keep every ray, bit for bit).
    detail::robust_fit_vertices({input, {}, 0.0}, order, detail::class_tolerances(fit, scale), 0,
                                true, out.curvature);
    if (out.corrected) {
      // Clean positions without outliers: the corrected step on each point's local
      // triangulation where the fit is not exact (corrected_step.h; docs/notes/points-log.md, "The
      // corrected step on clouds").
      detail::cloud_corrected_measures(V, out.N, ok, out.neighbours, {}, fit, scale, order,
                                       out.curvature);
    }
  }
}

}  // namespace

void fit_cloud_curvature(PositionsRef V, CloudCurvature& out, const CloudOptions& options) {
  fit_plan(V, out, options, false);
}

namespace {

/// The default's plan, and the k nearest with the cloud's own normals (`focal curvature --k 16`
/// on a scan with normals): the steps read each point's and its neighbours' rows, and the one
/// that does not, the MST, runs over the cloud in its own order. Not the k nearest without
/// normals (cloud_normals' MST) nor radius neighbourhoods.
bool runs_in_spatial_order(std::optional<NormalsRef> N, const CloudOptions& o) {
  return uses_plan(o) || (N && o.k > 0 && o.radius == 0.0 && o.adaptive_radius == 0.0);
}

/// M's rows taken in the order `from` (detail::rows_from), in place: one field at a time, so that
/// a cloud's results are not held twice.
template <class Matrix>
void take_rows(Matrix& M, const std::vector<int>& from, int threads) {
  M = detail::rows_from(M, from, threads);
}

void take_rows(CurvatureResult& r, const std::vector<int>& from, int threads) {
  for (Eigen::VectorXd* v : {&r.k1, &r.k2, &r.H, &r.K, &r.residual}) take_rows(*v, from, threads);
  take_rows(r.d1, from, threads);
  take_rows(r.d2, from, threads);
  take_rows(r.point_class, from, threads);
  take_rows(r.rays_used, from, threads);
  take_rows(r.rays_excluded, from, threads);
}

/// adaptive_plan of the cloud V (normals N) run on `copy`, its rows p.order.
CloudCurvature plan_on_copy(PositionsRef V, std::optional<NormalsRef> N, PositionsRef copy,
                            const detail::RowPermutation& p, const CloudOptions& options) {
  std::optional<RowMatrixX3d> sided;  // the jets start on the side of N's rows
  if (N) sided = detail::rows_from(*N, p.order, 0);
  const detail::CloudCopy copy_of{p, V};
  return adaptive_plan(copy, sided ? std::optional<NormalsRef>(*sided) : std::nullopt, options,
                       &copy_of);
}

/// estimate_cloud_curvature on a copy of the cloud in Morton order, its results taken back to the
/// cloud's rows. The lists, the tests and the fit read each point's neighbours' rows: on a cloud
/// whose rows come in no spatial order (scanners' and generators' files often do) each read
/// is a cache miss, on the copy mostly a hit.
/// The same bits (docs/notes/points-log.md, "The whole cloud in Morton order"): every list is that
/// of the cloud's own order renamed, in the same order (ties by the cloud's rows,
/// detail::nearest_neighbours); mean_spacing sums, and the jets sum each neighbourhood, in the
/// cloud's row order; the MST runs over the cloud in its own order (adaptive_plan's copy_of);
/// every other step reads a point's own and its list's rows only.
CloudCurvature in_spatial_order(PositionsRef V, std::optional<NormalsRef> N,
                                const CloudOptions& options) {
  const detail::RowPermutation p = detail::morton_permutation(V, 0);
  RowMatrixX3d copy = detail::rows_from(V, p.order, 0);
  CloudCurvature c;
  if (uses_plan(options)) {
    c = plan_on_copy(V, N, copy, p, options);
  } else {
    c = given_lists(copy, options, p.order);
    c.file_normals_used = true;
    c.N = detail::rows_from(*N, p.order, 0);
  }
  fit_plan(copy, c, options, true);
  copy = RowMatrixX3d();
  // Each field's copy is let go as it is taken back: the results are held once, as without the
  // copy, but for the one field in flight (docs/POINTS.md, "Speed and memory").
  c.neighbours = options.keep_neighbours ? detail::unpermuted_neighbours(c.neighbours, p, 0)
                                         : Neighbourhoods();
  take_rows(c.curvature, p.position, 0);
  take_rows(c.N, p.position, 0);
  if (!c.outlier.empty()) {
    std::vector<char> outlier(c.outlier.size());
    for (std::size_t i = 0; i < outlier.size(); ++i)
      outlier[i] = c.outlier[static_cast<std::size_t>(p.position[i])];
    c.outlier = std::move(outlier);
  }
  return c;
}

}  // namespace

CloudCurvature estimate_cloud_curvature(PositionsRef V, std::optional<NormalsRef> N,
                                        const CloudOptions& options) {
  validate(V, N, options);
  if (runs_in_spatial_order(N, options)) return in_spatial_order(V, N, options);
  CloudCurvature out = plan_cloud_curvature(V, N, options);
  fit_cloud_curvature(V, out, options);
  if (!options.keep_neighbours) out.neighbours = Neighbourhoods();
  return out;
}

RowMatrixX3d estimate_cloud_normals(PositionsRef V, std::optional<NormalsRef> N,
                                    const CloudOptions& options) {
  validate(V, N, options);
  if (!uses_plan(options)) {
    // Neighbourhoods as given: every point's estimate over them, on the side of its given normal.
    CloudNormalOptions normals = normal_options(options);
    RowMatrixX3d out = cloud_normals(V, cloud_neighbourhoods(V, options), normals);
    if (N && !normals.viewpoint) {
      for (Eigen::Index i = 0; i < out.rows(); ++i) {
        if (out.row(i).dot(N->row(i)) < 0.0) out.row(i) *= -1.0;
      }
    }
    return out;
  }
  // The plan on the cloud's copy in Morton order, as estimate_cloud_curvature runs it.
  const detail::RowPermutation p = detail::morton_permutation(V, 0);
  CloudCurvature plan = plan_on_copy(V, N, detail::rows_from(V, p.order, 0), p, options);
  if (!plan.file_normals_used) {  // jet normals: unit or NaN rows
    return detail::rows_from(plan.N, p.position, 0);
  }
  std::vector<char> ok;
  RowMatrixX3d out = detail::unit_rows(plan.N, ok, 0);
  for (Eigen::Index i = 0; i < out.rows(); ++i) {
    if (!ok[static_cast<std::size_t>(i)]) out.row(i).setConstant(NAN);
  }
  return detail::rows_from(out, p.position, 0);
}

}  // namespace focal
