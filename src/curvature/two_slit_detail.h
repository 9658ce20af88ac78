#pragma once
// The closed-form two-slit fit, inline: the per-vertex estimator runs it once per vertex, where a
// call across translation units and its by-value SlitFit cost as much as the arithmetic.
// two_slit_fit.cpp wraps it as fit_two_slits_closed_form and shares the well-posedness test
// with the Levenberg-Marquardt solver.

#include <Eigen/Dense>
#include <limits>
#include <span>

#include "curvature/detail.h"
#include "focal/curvature/two_slit_fit.h"

namespace focal::detail {

inline double weight_at(std::span<const double> weights, std::size_t i) {
  return weights.empty() ? 1.0 : weights[i];
}

/// Normal equations of min sum_i w_i |W x_i - g_i|^2 in w = (a, b, c): the rows of one ray are
/// (u, v, 0) -> sigma and (0, u, v) -> tau.
struct NormalEquations {
  Eigen::Matrix3d lhs = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  int rays = 0;
};

inline NormalEquations accumulate(std::span<const NormalRay> rays,
                                  std::span<const double> weights) {
  NormalEquations eq;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double w = weight_at(weights, i);
    if (!(w > 0.0)) continue;
    const NormalRay& r = rays[i];
    const double uu = w * r.u * r.u, uv = w * r.u * r.v, vv = w * r.v * r.v;
    eq.lhs(0, 0) += uu;
    eq.lhs(0, 1) += uv;
    eq.lhs(1, 1) += uu + vv;
    eq.lhs(1, 2) += uv;
    eq.lhs(2, 2) += vv;
    eq.rhs += w * Eigen::Vector3d(r.u * r.sigma, r.v * r.sigma + r.u * r.tau, r.v * r.tau);
    ++eq.rays;
  }
  eq.lhs(1, 0) = eq.lhs(0, 1);
  eq.lhs(2, 1) = eq.lhs(1, 2);
  return eq;
}

/// Solves the 3x3 system when it is well conditioned: det relative to (trace/3)^3, which is
/// invariant to the scale of the mesh, above 1e-12.
inline bool solve_well_conditioned(const NormalEquations& eq, Eigen::Vector3d& w) {
  if (eq.rays < 2) return false;
  const double scale = eq.lhs.trace() / 3.0;
  const double det = eq.lhs.determinant();
  if (!(scale > 0.0) || !(det > 1e-12 * scale * scale * scale)) return false;
  w = eq.lhs.inverse() * eq.rhs;  // closed-form cofactor inverse for fixed 3x3 in Eigen
  return w.allFinite();
}

/// sum_i w_i |W x_i - g_i|^2 for W = [a b; b c]: the paper's E, evaluated directly (no
/// cancellation as in the expanded quadratic form).
inline double energy_of_matrix(std::span<const NormalRay> rays, std::span<const double> weights,
                               double a, double b, double c) {
  double e = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const NormalRay& r = rays[i];
    const double ru = a * r.u + b * r.v - r.sigma;
    const double rv = b * r.u + c * r.v - r.tau;
    e += weight_at(weights, i) * (ru * ru + rv * rv);
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
  Eigen::Vector3d w;
  if (!solve_well_conditioned(accumulate(rays, weights), w)) return invalid_fit();
  const Principal2 p = principal_from_symmetric(w[0], w[1], w[2]);
  SlitFit fit;
  fit.valid = true;
  fit.k1 = p.k1;
  fit.k2 = p.k2;
  fit.d1 = p.d1;
  fit.d2 = p.d2;
  fit.energy = energy_of_matrix(rays, weights, w[0], w[1], w[2]);
  return fit;
}

}  // namespace focal::detail
