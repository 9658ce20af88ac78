#pragma once
// The scalar driver of the two-slit fit (kernels/two_slit.h's arithmetic) in double, inline: the
// rays of one vertex's neighbours (gather_rays), the normal equations over them, their solve and
// the closed-form fit of one ray set. two_slit_fit.cpp wraps it as fit_two_slits_closed_form and
// shares the well-posedness test with the Levenberg-Marquardt solver; curvature.cpp's
// Levenberg-Marquardt path and robust_fit.cpp fit vertex by vertex on it. The closed form of
// every vertex runs in curvature.cpp's lane kernel instead, a tuned driver of the same formula
// (see there for what it must match).

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "curvature/normal_rays_detail.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/curvature/two_slit_fit.h"
#include "kernels/two_slit.h"

namespace focal::detail {

/// One vertex's rays and weights. Owned by a block of vertices (or a thread), so that the loop
/// over vertices never touches the heap once the vectors have grown to the largest ring.
struct VertexRays {
  std::vector<NormalRay> rays;
  std::vector<double> weights;  ///< empty for uniform weights
};

/// The rays of vertex i's neighbours in i's tangent frame (paper 4.1) into `out` (cleared
/// first), with the weights exp(-|q - p|^2 inverse_two_width_squared) where that factor is > 0
/// and none (uniform weights) where it is 0. A neighbour with an invalid normal, one flagged in
/// `skip` (#V flags, or empty) and one whose ray does not exist (ray_of) gives no ray; returns
/// how many gave none.
inline int gather_rays(const VertexFitInput& in, int i, const TangentFrame& frame,
                       double inverse_two_width_squared, std::span<const char> skip,
                       VertexRays& out) {
  out.rays.clear();
  out.weights.clear();
  const Eigen::Vector3d p = in.V.row(i).transpose();
  int excluded = 0;
  for (const int* j = in.rings.begin(i); j != in.rings.end(i); ++j) {
    const auto k = static_cast<std::size_t>(*j);
    const Eigen::Vector3d q = in.V.row(*j).transpose();
    // The ray is made in its slot: copying a just-written NormalRay into the vector stalls on
    // store forwarding.
    NormalRay& ray = out.rays.emplace_back();
    if (!in.normal_ok[k] || (!skip.empty() && skip[k]) ||
        !ray_of(frame, p, q, in.unit_normals.row(*j).transpose(), ray)) {
      out.rays.pop_back();
      ++excluded;
      continue;
    }
    if (inverse_two_width_squared > 0.0) {
      out.weights.push_back(std::exp(-(q - p).squaredNorm() * inverse_two_width_squared));
    }
  }
  return excluded;
}

inline double weight_at(std::span<const double> weights, std::size_t i) {
  return weights.empty() ? 1.0 : weights[i];
}

/// The fit's normal equations (kernels/two_slit.h) over the rays of positive weight, and how
/// many there are: a fit needs two.
struct NormalEquations {
  kernels::SlitSums<double> sums;
  int rays = 0;
};

inline NormalEquations accumulate(std::span<const NormalRay> rays,
                                  std::span<const double> weights) {
  NormalEquations eq;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double w = weight_at(weights, i);
    if (!(w > 0.0)) continue;
    const NormalRay& r = rays[i];
    kernels::add_ray(eq.sums, w, r.u, r.v, r.sigma, r.tau);
    ++eq.rays;
  }
  return eq;
}

/// det / (trace/3)^3 of the normal equations at or below which a fit is not well posed.
inline constexpr double kMinRelativeDeterminant = 1e-12;

/// Solves the normal equations; false where they are not well posed (fewer than two rays of
/// positive weight, or ill conditioned).
inline bool solve_well_conditioned(const NormalEquations& eq, kernels::SlitSolution<double>& w) {
  w = kernels::solve_slits(eq.sums, kMinRelativeDeterminant);
  return eq.rays >= 2 && w.valid;
}

/// sum_i w_i |W x_i - g_i|^2: the paper's E at the solution.
inline double energy_of(std::span<const NormalRay> rays, std::span<const double> weights,
                        const kernels::SlitSolution<double>& w) {
  double e = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const NormalRay& r = rays[i];
    e += weight_at(weights, i) * kernels::slit_misfit(w, r.u, r.v, r.sigma, r.tau);
  }
  return e;
}

inline SlitFit invalid_fit() {
  SlitFit fit;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fit.valid = false;
  fit.k1 = fit.k2 = fit.energy = nan;
  fit.d1 = fit.d2 = Eigen::Vector2d::Constant(nan);
  return fit;
}

inline SlitFit closed_form_fit(std::span<const NormalRay> rays, std::span<const double> weights) {
  kernels::SlitSolution<double> w;
  if (!solve_well_conditioned(accumulate(rays, weights), w)) return invalid_fit();
  const Principal2 p = principal_from_symmetric(w.a, w.b, w.c);
  SlitFit fit;
  fit.valid = true;
  fit.k1 = p.k1;
  fit.k2 = p.k2;
  fit.d1 = p.d1;
  fit.d2 = p.d2;
  fit.energy = energy_of(rays, weights, w);
  return fit;
}

}  // namespace focal::detail
