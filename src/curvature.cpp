#include "focal/curvature.h"

#include <cmath>
#include <string>
#include <vector>

#include "curvature_detail.h"
#include "focal/error.h"
#include "focal/neighbourhood.h"
#include "focal/normal_rays.h"
#include "normal_rays_detail.h"
#include "parallel.h"
#include "two_slit_detail.h"

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
  const detail::VertexFitInput& in;
  const CurvatureOptions& options;
  double inverse_two_width_squared;  // Gaussian weights: exp(-d^2 * this)
  detail::ClassTolerances tolerances;
};

/// One vertex's rays and weights. Owned by a block of vertices, so that the loop over vertices
/// never touches the heap once the vectors have grown to the largest ring.
struct RayScratch {
  std::vector<NormalRay> rays;
  std::vector<double> weights;  // empty for uniform weights
};

SlitFit run_solver(const CurvatureOptions& o, std::span<const NormalRay> rays,
                   std::span<const double> weights) {
  return o.solver == Solver::closed_form
             ? detail::closed_form_fit(rays, weights)
             : fit_two_slits_levenberg_marquardt(rays, weights, o.levenberg_marquardt);
}

/// The rays of vertex i's neighbours in its tangent frame (paper 4.1); returns how many
/// neighbours had none (normal outside the hemisphere, or invalid).
int gather_rays(const FitContext& c, int i, const TangentFrame& frame, RayScratch& s) {
  const detail::VertexFitInput& in = c.in;
  const Eigen::Vector3d p = in.V.row(i).transpose();
  int excluded = 0;
  for (const int* j = in.rings.begin(i); j != in.rings.end(i); ++j) {
    const Eigen::Vector3d q = in.V.row(*j).transpose();
    // The ray is made in its slot: copying a just-written NormalRay into the vector stalled on
    // store forwarding (a fifth of the fit's time).
    NormalRay& ray = s.rays.emplace_back();
    if (!in.normal_ok[static_cast<std::size_t>(*j)] ||
        !detail::ray_of(frame, p, q, in.unit_normals.row(*j).transpose(), ray)) {
      s.rays.pop_back();
      ++excluded;
      continue;
    }
    if (c.options.weighting == RayWeighting::gaussian) {
      s.weights.push_back(std::exp(-(q - p).squaredNorm() * c.inverse_two_width_squared));
    }
  }
  return excluded;
}

void fit_vertex(const FitContext& c, int i, RayScratch& s, CurvatureResult& r) {
  s.rays.clear();
  s.weights.clear();
  r.rays_used[i] = r.rays_excluded[i] = 0;
  if (!c.in.normal_ok[static_cast<std::size_t>(i)]) return detail::store_undefined(r, i);
  const TangentFrame frame = detail::frame_of(c.in.unit_normals.row(i).transpose());
  r.rays_excluded[i] = gather_rays(c, i, frame, s);
  r.rays_used[i] = static_cast<int>(s.rays.size());
  const SlitFit fit = run_solver(c.options, s.rays, s.weights);
  if (!fit.valid) return detail::store_undefined(r, i);
  double weight_sum = static_cast<double>(s.rays.size());
  if (!s.weights.empty()) {
    weight_sum = 0.0;
    for (double w : s.weights) weight_sum += w;
  }
  detail::store_vertex(r, i, frame, {fit.k1, fit.k2, fit.d1, fit.d2},
                       std::sqrt(fit.energy / weight_sum), c.tolerances);
}

CurvatureResult vertex_curvature_from_rays(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options) {
  std::vector<char> normal_ok;
  const RowMatrixX3d unit = detail::unit_rows(N, normal_ok, options.threads);
  const Neighbourhoods one_ring = vertex_adjacency(static_cast<int>(V.rows()), F);
  const Neighbourhoods rings = options.rings == 1 ? one_ring : k_ring(one_ring, options.rings);
  return detail::fit_vertices({V, unit, normal_ok, rings, mean_edge_length(V, F)}, options);
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

namespace detail {

CurvatureResult fit_vertices(const VertexFitInput& in, const CurvatureOptions& options) {
  const double h = in.mean_edge_length;
  const double width = options.gaussian_width > 0.0 ? options.gaussian_width : h * options.rings;
  const FitContext context{in, options, 0.5 / (width * width), class_tolerances(options, h)};
  CurvatureResult result = unwritten_result(in.V.rows());
  // Blocks of vertices share one scratch; 256 vertices amortise its allocation and still give
  // each thread many blocks (static schedule, so the same split for any run).
  parallel_for_blocks(in.V.rows(), 256, options.threads, [&](std::int64_t begin, std::int64_t end) {
    RayScratch scratch;
    for (auto i = begin; i < end; ++i) fit_vertex(context, static_cast<int>(i), scratch, result);
  });
  return result;
}

}  // namespace detail
}  // namespace focal
