#pragma once
// Internal: the recommended estimator's robust per-vertex two-slit fit (docs/notes/estimator-log.md,
// "Robust weights"): the closed-form fit of two_slit_detail.h, refitted without the
// rays far off the two slits (outlier normals, spikes, the far side of a crease) lose their pull.

#include <vector>

#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"

namespace focal::detail {

/// Rays whose misfit |W x - g| exceeds this many robust scales (1.4826 x the median misfit) are
/// left out and the fit repeated. The misfit of a ray is the length of a 2D residual: for
/// Gaussian residuals of deviation s its median is 1.18 s, so the cut lies at 5.2 s, beyond
/// which a clean ray falls with probability exp(-5.2^2 / 2) = 1e-6: clean data keep every ray
/// and the least-squares fit, bit for bit.
inline constexpr double kRejectionScales = 5.0;
/// Rejection rounds after the least-squares start (each recomputes the set from all rays).
inline constexpr int kRejectionRounds = 4;

/// What the robust fit reads besides VertexFitInput: rays are never taken from vertices flagged
/// in `skip` (#V flags, or empty), e.g. crease vertices whose normal belongs to no piece.
struct RobustFitInput {
  const VertexFitInput& fit;
  const std::vector<char>& skip;
  double gaussian_width;  ///< > 0: Gaussian weights of this width; 0: uniform
};

/// The robust fit of vertex i into row `row` of `r` (undefined where no fit is well posed).
/// Returns whether rays were rejected (otherwise the row is the plain least-squares fit).
bool robust_fit_vertex(const RobustFitInput& in, int i, const ClassTolerances& tolerances,
                       CurvatureResult& r, Eigen::Index row);

/// robust_fit_vertex of every listed vertex, in parallel (each row written once); with
/// `only_rejecting`, rows are written only where rays were rejected (the others keep the fit
/// they have).
void robust_fit_vertices(const RobustFitInput& in, const std::vector<int>& vertices,
                         const ClassTolerances& tolerances, int threads, bool only_rejecting,
                         CurvatureResult& r);

}  // namespace focal::detail
