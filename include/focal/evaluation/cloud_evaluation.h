#pragma once
/// \file cloud_evaluation.h
/// Accuracy of the cloud estimator (curvature/cloud_curvature.h) on point samples of the analytic
/// surfaces (surfaces/cloud_samples.h) with exact truth: what `focal eval --points` reports.
#include <cstdint>
#include <string>
#include <vector>

#include "focal/curvature/cloud_curvature.h"
#include "focal/surfaces/cloud_samples.h"

namespace focal {

/// One evaluated cloud: a surface and a sampling case.
struct CloudCase {
  std::string name;  ///< "<surface>/<case>", e.g. "torus/no normals"
  CloudSampleOptions sample;
};

/// Every analytic surface x {exact normals, no normals, position noise 0.1 without normals,
/// normal noise 0.05, graded density 0.5 without normals, 2% outliers without normals}, about
/// `points` points each.
[[nodiscard]] std::vector<CloudCase> cloud_cases(int points, std::uint64_t seed);

/// Errors of one case against the truth, over the points with truth (outliers have none).
struct CloudCaseResult {
  std::string name;
  int points = 0;
  /// sqrt(mean (H - H_true)^2) / max |k_true| over points with an estimate and truth.
  double h_relative_rms = 0.0;
  /// The same for K, divided by max k_true^2.
  double k_relative_rms = 0.0;
  int undefined = 0;   ///< points with truth but no estimate
  double noise = 0.0;  ///< CloudCurvature::noise of the default's plan (NaN with k given)
  int k = 0;           ///< neighbours of the fit
};

/// Samples the case and runs estimate_cloud_curvature on it with `options`.
/// \throw InvalidInput as sample_cloud or estimate_cloud_curvature.
[[nodiscard]] CloudCaseResult evaluate_cloud_case(const CloudCase& c,
                                                  const CloudOptions& options = {});

}  // namespace focal
