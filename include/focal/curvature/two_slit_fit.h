#pragma once
/// \file two_slit_fit.h
/// The two-slit fit of the paper, section 5 (eqs. 10-14), on one vertex's set of normal rays.
///
/// With x_i = (u_i, v_i) and g_i = (sigma_i, tau_i) the paper minimises over (t, k1, k2)
///     E = sum_i w_i [ ((u_i k1 - sigma_i) sin t - (v_i k1 - tau_i) cos t)^2
///                   + ((u_i k2 - sigma_i) cos t + (v_i k2 - tau_i) sin t)^2 ].
/// With d1 = (-sin t, cos t), d2 = (cos t, sin t) and W = k1 d1 d1^T + k2 d2 d2^T this is exactly
///     E = sum_i w_i |W x_i - g_i|^2,
/// a linear least-squares problem in the three entries of the symmetric 2x2 matrix W, solved in
/// closed form (3x3 normal equations). The eigen-decomposition of W gives k1 >= k2 and d1, d2.
/// The slit at depth lambda_1 = -1/k1 runs along d2 (and the one at lambda_2 along d1).

#include <Eigen/Core>
#include <span>

#include "focal/curvature/normal_rays.h"

namespace focal {

/// Result of fitting two slits to one ray set. Directions are in the tangent plane of the frame
/// the rays were expressed in.
struct SlitFit {
  bool valid = false;            ///< false: under-determined (fewer than 2 rays or singular)
  double k1 = 0.0;               ///< larger principal curvature
  double k2 = 0.0;               ///< smaller principal curvature
  Eigen::Vector2d d1{1.0, 0.0};  ///< unit principal direction of k1
  Eigen::Vector2d d2{0.0, 1.0};  ///< unit principal direction of k2, d1 rotated by +90 degrees
  double energy = 0.0;           ///< E at the solution (weighted sum of squared residuals)
};

/// The paper's objective E(t, k1, k2) for rays with weights (empty weights: all 1).
[[nodiscard]] double two_slit_energy(std::span<const NormalRay> rays,
                                     std::span<const double> weights, double t, double k1,
                                     double k2);

/// Global minimum of E by the closed form. Rays with zero weight are ignored; valid only when
/// the normal equations are well conditioned (relative pivot above 1e-12).
[[nodiscard]] SlitFit fit_two_slits_closed_form(std::span<const NormalRay> rays,
                                                std::span<const double> weights = {});

/// Options of the paper's Levenberg-Marquardt solver.
struct LevenbergMarquardtOptions {
  int initial_angles = 8;    ///< sampled starting angles t in [0, pi)
  int max_iterations = 50;   ///< per start
  double tolerance = 1e-14;  ///< relative decrease of E that stops the iteration
};

/// The paper's method as written: for each sampled t the closed-form k1, k2 at that fixed t
/// (E is quadratic in them), the best start refined by Levenberg-Marquardt on (t, k1, k2).
[[nodiscard]] SlitFit fit_two_slits_levenberg_marquardt(
    std::span<const NormalRay> rays, std::span<const double> weights = {},
    const LevenbergMarquardtOptions& options = {});

}  // namespace focal
