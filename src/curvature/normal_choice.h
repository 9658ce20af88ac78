#pragma once
// The choice between two normal fields at one vertex by the roughness of the two-slit fit they
// give: the recommended estimator's and the cloud estimator's per-vertex normals.

#include <Eigen/Core>
#include <cmath>
#include <utility>

namespace focal::detail {

/// select_normal: how much smoother (two-slit residual) the secondary normal must be.
constexpr double kSmootherRatio = 0.5;

/// A vertex's normal: the primary `a` unless the secondary `b` is clearly smoother there: its
/// two-slit residual `rb` (RMS misfit of the rays, slope units, over the neighbourhood of the
/// fit: a mesh vertex's 1-ring, a cloud point's nearest) below kSmootherRatio times the
/// primary's `ra`. On clean data the two residuals measure the same truncation error
/// and the primary is kept; 10% vertex noise makes jets 5 to 10 times rougher than exact
/// normals. Only where `may_replace` holds is the secondary considered. Returns the chosen unit
/// normal and its residual.
[[gnu::always_inline]] inline std::pair<Eigen::Vector3d, double> select_normal(
    const Eigen::Vector3d& primary, double ra, const Eigen::Vector3d& secondary, double rb,
    bool may_replace) {
  const Eigen::Vector3d a = primary.normalized(), b = secondary.normalized();
  // A field without a fit at i (too few rays, invalid normal) never wins over one with a fit.
  const bool b_fits = std::isfinite(rb), a_fits = std::isfinite(ra);
  const bool smoother = b_fits && (!a_fits || rb < kSmootherRatio * ra);
  const bool take_b = b.allFinite() && (!a.allFinite() || (smoother && may_replace));
  return take_b ? std::pair{b, rb} : std::pair{a, ra};
}

}  // namespace focal::detail
