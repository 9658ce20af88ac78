#pragma once
/// \file recommended.h
/// The recommended estimator: what `focal curvature` runs when no estimator option is given,
/// and what `focal eval` reports as "focal default". Two entry points: the file gives normals
/// (which may be noisy), or it does not. Measured against the paper's method and the baselines
/// in docs/ESTIMATOR.md, "The recommended estimator".
///
/// Both run the paper's estimators (the closed-form two-slit fit, and on clean positions the
/// per-triangle characteristic equation) on better normals and, where the positions are noisy,
/// over a wider neighbourhood:
///  1. Jets (normal_estimation.h): a cubic height fit over the 2-ring of every vertex gives
///     third-order normals from the positions, and its residual measures the position noise:
///     noise = median residual / mean edge length (about 1e-4 on clean smooth meshes, 0.056 for
///     the paper's 10% vertex noise).
///  2. Neighbourhood (recommended_plan_for_noise): the 1-ring (the paper) on clean positions;
///     Gaussian-weighted 2 or 3 rings when the noise is above kNoiseForTwoRings or
///     kNoiseForThreeRings.
///  3. Normals. From the positions: per vertex the jets' normals, or Max's (exact on spheres)
///     where those are clearly smoother: the RMS misfit (residual) of their 1-ring two-slit fit
///     below half the jets'; on noisy positions instead those of wider quadratic jets (rings + 1
///     rings), which average the noise. The file's normals are judged as a whole by their median
///     angle to the jet normals: within twice the position noise (the jets' own error is about
///     the noise) they are used, and only outliers are replaced by the positions' choice (more
///     than 10 times the noise from the jet normal and half as rough); beyond it they are ignored
///     and the positions' normals are used, turned to the file's side. Measured ratio of that
///     median angle to the noise: 0.09 to 0.95 on clean meshes, 0.8 to 1.05 under 10% vertex
///     noise with exact normals (used), 5.3 to 4600 under 5% normal noise (ignored).
///  4. The two-slit fit of those normals over that neighbourhood. On clean positions (1 ring)
///     each vertex then takes the per-triangle characteristic equation averaged to the vertex
///     (Method::triangle; 1.3 to 1.8 times lower H error on irregular meshes), except where the
///     fit is exact (residual <= 1e-9: the rays meet two slits, as on spheres and cylinders) or
///     the triangles give no estimate.
/// The paper's method as written remains estimate_curvature with default CurvatureOptions.
///
/// Deterministic for any thread count. Vertices the fit cannot handle are `undefined` (NaN) as
/// in estimate_curvature.

#include <cmath>

#include "focal/curvature/curvature.h"

namespace focal {

/// Position noise (median jet residual / mean edge length) above which the fit uses 2 rings.
inline constexpr double kNoiseForTwoRings = 0.015;
/// ... and above which it uses 3 rings.
inline constexpr double kNoiseForThreeRings = 0.035;

/// What the recommended estimator does for a mesh, decided from its positions alone.
struct RecommendedPlan {
  double noise = NAN;     ///< median cubic-jet residual over the mean edge length; NaN: none
  int rings = 1;          ///< rings of the two-slit fit
  bool gaussian = false;  ///< Gaussian ray weights (width = mean edge length x rings)
  int jet_rings = 2;      ///< rings of the jets whose normals are used without file normals
  int jet_degree = 3;     ///< their degree
};

/// The plan for a given noise level (see the steps above).
[[nodiscard]] RecommendedPlan recommended_plan_for_noise(double noise);

/// The plan for a mesh: measures its noise (cubic jets over the 2-ring) and plans for it.
/// \throw InvalidInput when F indexes outside V or threads < 0.
[[nodiscard]] RecommendedPlan recommended_plan(PositionsRef V, FacesRef F, int threads = 0);

/// The recommended estimate with what it decided and the normals it fitted.
struct RecommendedResult {
  CurvatureResult curvature;
  RowMatrixX3d N;  ///< #V x 3 unit normals the two-slit fit used (NaN rows where there is none)
  RecommendedPlan plan;
  /// Median angle (radians) between the file's normals and the jet normals; NaN without normals.
  double file_disagreement = NAN;
  /// Whether the file's normals were used: they agree with the positions (file_disagreement at
  /// most twice the noise). Otherwise they are ignored as a whole, except for their side.
  bool file_normals_used = false;
};

/// Both cases in one: N with #V rows are the file's normals, N with 0 rows means none.
/// \throw InvalidInput when F indexes outside V, N has neither 0 nor #V rows, or threads < 0.
[[nodiscard]] RecommendedResult estimate_curvature_recommended_full(PositionsRef V, FacesRef F,
                                                                    NormalsRef N, int threads = 0);

/// With normals from the file (which may be noisy). \param N #V x 3 (need not be unit; zero or
/// non-finite rows take the jet normal).
/// \throw InvalidInput when F indexes outside V, N does not have #V rows, or threads < 0.
[[nodiscard]] CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F,
                                                             NormalsRef N, int threads = 0);

/// Without normals: they are estimated from the positions.
/// \throw InvalidInput when F indexes outside V or threads < 0.
[[nodiscard]] CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F,
                                                             int threads = 0);

}  // namespace focal
