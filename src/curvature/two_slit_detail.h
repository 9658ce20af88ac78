#pragma once
// The closed-form two-slit fit of one ray set in double, inline, on kernels/two_slit.h's
// arithmetic (the per-vertex estimator's lane kernel runs the same): two_slit_fit.cpp wraps it as
// fit_two_slits_closed_form and shares the well-posedness test with the Levenberg-Marquardt
// solver.

#include <Eigen/Core>
#include <limits>
#include <span>

#include "curvature/vertex_rows.h"
#include "focal/curvature/two_slit_fit.h"
#include "kernels/two_slit.h"

namespace focal::detail {

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
