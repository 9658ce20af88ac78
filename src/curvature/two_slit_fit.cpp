#include "focal/curvature/two_slit_fit.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <numbers>

#include "curvature/two_slit_detail.h"

namespace focal {
namespace {

using detail::weight_at;

// ---- The paper's Levenberg-Marquardt on (t, k1, k2). d1 = (-sin t, cos t), d2 = (cos t, sin t).

struct Params {
  double t = 0.0, k1 = 0.0, k2 = 0.0;
};

/// The closed-form k1, k2 for a fixed t: E separates into two one-dimensional least squares.
bool curvatures_at_angle(std::span<const NormalRay> rays, std::span<const double> weights, double t,
                         Params& p) {
  const double s = std::sin(t), c = std::cos(t);
  double aa = 0, ab = 0, cc = 0, ce = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double w = weight_at(weights, i);
    const NormalRay& r = rays[i];
    const double a = r.u * s - r.v * c, b = r.sigma * s - r.tau * c;
    const double cu = r.u * c + r.v * s, e = r.sigma * c + r.tau * s;
    aa += w * a * a;
    ab += w * a * b;
    cc += w * cu * cu;
    ce += w * cu * e;
  }
  if (!(aa > 0.0) || !(cc > 0.0)) return false;
  p = {t, ab / aa, ce / cc};
  return true;
}

double energy_of(std::span<const NormalRay> rays, std::span<const double> weights,
                 const Params& p) {
  return two_slit_energy(rays, weights, p.t, p.k1, p.k2);
}

/// One Levenberg-Marquardt system J^T J, J^T r for the residuals of eq. 14.
void lm_system(std::span<const NormalRay> rays, std::span<const double> weights, const Params& p,
               Eigen::Matrix3d& jtj, Eigen::Vector3d& jtr) {
  const double s = std::sin(p.t), c = std::cos(p.t);
  jtj.setZero();
  jtr.setZero();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double w = weight_at(weights, i);
    const NormalRay& r = rays[i];
    const double p1 = r.u * p.k1 - r.sigma, q1 = r.v * p.k1 - r.tau;
    const double p2 = r.u * p.k2 - r.sigma, q2 = r.v * p.k2 - r.tau;
    const double r1 = p1 * s - q1 * c, r2 = p2 * c + q2 * s;
    const Eigen::Vector3d j1(p1 * c + q1 * s, r.u * s - r.v * c, 0.0);
    const Eigen::Vector3d j2(-p2 * s + q2 * c, 0.0, r.u * c + r.v * s);
    jtj += w * (j1 * j1.transpose() + j2 * j2.transpose());
    jtr += w * (j1 * r1 + j2 * r2);
  }
}

Params levenberg_marquardt(std::span<const NormalRay> rays, std::span<const double> weights,
                           Params p, const LevenbergMarquardtOptions& options) {
  double energy = energy_of(rays, weights, p);
  double damping = 1e-3;
  for (int it = 0; it < options.max_iterations && energy > 0.0; ++it) {
    Eigen::Matrix3d jtj;
    Eigen::Vector3d jtr;
    lm_system(rays, weights, p, jtj, jtr);
    bool improved = false;
    while (damping < 1e12) {
      Eigen::Matrix3d a = jtj;
      a.diagonal() += damping * jtj.diagonal().cwiseMax(1e-300);
      const Eigen::Vector3d step = a.ldlt().solve(-jtr);
      const Params next{p.t + step[0], p.k1 + step[1], p.k2 + step[2]};
      const double e = energy_of(rays, weights, next);
      if (std::isfinite(e) && e < energy) {
        const double decrease = (energy - e) / energy;
        p = next;
        energy = e;
        damping = std::max(damping * 0.1, 1e-12);
        improved = decrease > options.tolerance;
        break;
      }
      damping *= 10.0;
    }
    if (!improved) break;
  }
  return p;
}

/// Converts the paper's (t, k1, k2) into a SlitFit with k1 >= k2: swapping the curvatures
/// swaps the roles of the two directions.
SlitFit to_fit(const Params& p, double energy) {
  SlitFit fit;
  fit.valid = true;
  Eigen::Vector2d d1(-std::sin(p.t), std::cos(p.t));
  double k1 = p.k1, k2 = p.k2;
  if (k1 < k2) {
    std::swap(k1, k2);
    d1 = Eigen::Vector2d(std::cos(p.t), std::sin(p.t));
  }
  fit.k1 = k1;
  fit.k2 = k2;
  fit.d1 = d1;
  fit.d2 = Eigen::Vector2d(-d1.y(), d1.x());
  fit.energy = energy;
  return fit;
}

}  // namespace

double two_slit_energy(std::span<const NormalRay> rays, std::span<const double> weights, double t,
                       double k1, double k2) {
  const double s = std::sin(t), c = std::cos(t);
  double e = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const NormalRay& r = rays[i];
    const double e1 = (r.u * k1 - r.sigma) * s - (r.v * k1 - r.tau) * c;
    const double e2 = (r.u * k2 - r.sigma) * c + (r.v * k2 - r.tau) * s;
    e += weight_at(weights, i) * (e1 * e1 + e2 * e2);
  }
  return e;
}

SlitFit fit_two_slits_closed_form(std::span<const NormalRay> rays,
                                  std::span<const double> weights) {
  return detail::closed_form_fit(rays, weights);
}

SlitFit fit_two_slits_levenberg_marquardt(std::span<const NormalRay> rays,
                                          std::span<const double> weights,
                                          const LevenbergMarquardtOptions& options) {
  // Same well-posedness test as the closed form, so both solvers flag the same vertices.
  kernels::SlitSolution<double> unused;
  if (!detail::solve_well_conditioned(detail::accumulate(rays, weights), unused)) {
    return detail::invalid_fit();
  }
  Params best;
  double best_energy = std::numeric_limits<double>::infinity();
  const int starts = std::max(options.initial_angles, 1);
  for (int k = 0; k < starts; ++k) {
    Params p;
    if (!curvatures_at_angle(rays, weights, std::numbers::pi * k / starts, p)) continue;
    const double e = energy_of(rays, weights, p);
    if (e < best_energy) {
      best_energy = e;
      best = p;
    }
  }
  if (!std::isfinite(best_energy)) return detail::invalid_fit();
  best = levenberg_marquardt(rays, weights, best, options);
  return to_fit(best, energy_of(rays, weights, best));
}

}  // namespace focal
