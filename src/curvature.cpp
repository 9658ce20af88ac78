#include "focal/curvature.h"

#include <cmath>
#include <string>
#include <vector>

#include "curvature_detail.h"
#include "focal/error.h"
#include "focal/neighbourhood.h"
#include "focal/normal_rays.h"
#include "parallel.h"

namespace focal {

// Implemented in triangle_curvature.cpp: Method::triangle.
CurvatureResult vertex_curvature_from_triangles(PositionsRef V, FacesRef F, NormalsRef N,
                                                const CurvatureOptions& options);

namespace {

void validate_options(const CurvatureOptions& o) {
  if (o.rings < 1)
    throw InvalidInput("curvature: rings must be >= 1, got " + std::to_string(o.rings));
  if (!(o.gaussian_width >= 0.0)) throw InvalidInput("curvature: gaussian_width must be >= 0");
  if (!(o.zero_tolerance >= 0.0)) throw InvalidInput("curvature: zero_tolerance must be >= 0");
  if (!(o.umbilic_tolerance >= 0.0))
    throw InvalidInput("curvature: umbilic_tolerance must be >= 0");
  if (o.threads < 0) throw InvalidInput("curvature: threads must be >= 0");
}

/// Everything one vertex's fit reads, shared by all vertices.
struct FitContext {
  PositionsRef V;
  const RowMatrixX3d& N;
  const std::vector<char>& normal_ok;
  const Neighbourhoods& rings;
  const CurvatureOptions& options;
  double inverse_two_width_squared;  // Gaussian weights: exp(-d^2 * this)
  detail::ClassTolerances tolerances;
};

SlitFit run_solver(const CurvatureOptions& o, std::span<const NormalRay> rays,
                   std::span<const double> weights) {
  return o.solver == Solver::closed_form
             ? fit_two_slits_closed_form(rays, weights)
             : fit_two_slits_levenberg_marquardt(rays, weights, o.levenberg_marquardt);
}

void fit_vertex(const FitContext& c, Eigen::Index i, CurvatureResult& r) {
  thread_local std::vector<NormalRay> rays;
  thread_local std::vector<double> weights;
  rays.clear();
  weights.clear();
  const Eigen::Vector3d p = c.V.row(i).transpose();
  const TangentFrame frame = tangent_frame(c.N.row(i).transpose());
  int excluded = 0;
  for (const int* j = c.rings.begin(static_cast<int>(i)); j != c.rings.end(static_cast<int>(i));
       ++j) {
    const Eigen::Vector3d q = c.V.row(*j).transpose();
    const auto ray =
        c.normal_ok[*j] ? normal_ray(frame, p, q, c.N.row(*j).transpose()) : std::nullopt;
    if (!ray) {
      ++excluded;
      continue;
    }
    rays.push_back(*ray);
    if (c.options.weighting == RayWeighting::gaussian) {
      weights.push_back(std::exp(-(q - p).squaredNorm() * c.inverse_two_width_squared));
    }
  }
  r.rays_used[i] = static_cast<int>(rays.size());
  r.rays_excluded[i] = excluded;
  const SlitFit fit = run_solver(c.options, rays, weights);
  if (!fit.valid) return;  // stays undefined with NaN fields
  double weight_sum = static_cast<double>(rays.size());
  if (!weights.empty()) {
    weight_sum = 0.0;
    for (double w : weights) weight_sum += w;
  }
  detail::store_vertex(r, i, frame, {fit.k1, fit.k2, fit.d1, fit.d2},
                       std::sqrt(fit.energy / weight_sum), c.tolerances);
}

CurvatureResult vertex_curvature_from_rays(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options) {
  std::vector<char> normal_ok;
  const RowMatrixX3d unit = detail::unit_rows(N, normal_ok);
  const Neighbourhoods one_ring = vertex_adjacency(static_cast<int>(V.rows()), F);
  const Neighbourhoods rings = options.rings == 1 ? one_ring : k_ring(one_ring, options.rings);
  const double h = mean_edge_length(V, F);
  const double width = options.gaussian_width > 0.0 ? options.gaussian_width : h * options.rings;
  const FitContext context{V,
                           unit,
                           normal_ok,
                           rings,
                           options,
                           0.5 / (width * width),
                           detail::class_tolerances(options, h)};
  CurvatureResult result = detail::undefined_result(V.rows());
  detail::parallel_for(V.rows(), options.threads, [&](std::int64_t i) {
    if (normal_ok[static_cast<std::size_t>(i)]) fit_vertex(context, i, result);
  });
  return result;
}

}  // namespace

std::string_view class_name(PointClass c) {
  switch (c) {
    case PointClass::elliptic:
      return "elliptic";
    case PointClass::hyperbolic:
      return "hyperbolic";
    case PointClass::parabolic:
      return "parabolic";
    case PointClass::umbilic:
      return "umbilic";
    case PointClass::flat:
      return "flat";
    case PointClass::undefined:
      return "undefined";
  }
  return "undefined";
}

PointClass classify(double k1, double k2, double zero_tolerance, double umbilic_tolerance) {
  if (!std::isfinite(k1) || !std::isfinite(k2)) return PointClass::undefined;
  const bool zero1 = std::abs(k1) <= zero_tolerance, zero2 = std::abs(k2) <= zero_tolerance;
  if (zero1 && zero2) return PointClass::flat;
  if (zero1 || zero2) return PointClass::parabolic;
  if (k1 - k2 <= umbilic_tolerance * std::max(std::abs(k1), std::abs(k2)))
    return PointClass::umbilic;
  return k1 * k2 > 0.0 ? PointClass::elliptic : PointClass::hyperbolic;
}

CurvatureResult estimate_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                   const CurvatureOptions& options) {
  validate_options(options);
  if (N.rows() != V.rows()) {
    throw InvalidInput("curvature: " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(V.rows()) +
                       " vertices (normals are required; estimate "
                       "them with vertex_normals)");
  }
  validate_mesh_arrays(V, F, N, "curvature");
  if (options.method == Method::triangle) return vertex_curvature_from_triangles(V, F, N, options);
  return vertex_curvature_from_rays(V, F, N, options);
}

}  // namespace focal
