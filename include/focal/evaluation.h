#pragma once
/// \file evaluation.h
/// Error metrics of curvature estimates against analytic truth, as used by `focal eval`.

#include <vector>

#include "focal/curvature.h"
#include "focal/mesh.h"
#include "focal/surfaces.h"

namespace focal {

/// Errors over one set of vertices. Relative errors are RMS(error) / RMS(truth); where the truth
/// is (near) zero the relative value is NaN and the absolute RMS says it.
struct ErrorMetrics {
  int vertices = 0;   ///< vertices measured
  int undefined = 0;  ///< of which the estimate was undefined or not finite
  double relative_H = 0, relative_K = 0, relative_k1 = 0, relative_k2 = 0;
  double rms_H = 0, rms_K = 0, rms_k1 = 0, rms_k2 = 0;
  double median_angle_d1 = 0;  ///< degrees, lines (mod 180), at non-umbilic vertices
  double mean_angle_d1 = 0;
  double variance_H = 0;  ///< of the estimate (the paper's Fig. 7 smoothness figure)
};

/// Interior vertices (more than `boundary_rings` rings from a boundary) and the rest, measured
/// separately. Undefined vertices are counted, and left out of the error sums.
struct Evaluation {
  ErrorMetrics interior;
  ErrorMetrics near_boundary;
};

/// Compares an estimate with the truth of an analytic surface. A vertex counts as umbilic for the
/// direction error when k1 - k2 <= 0.2 max |k| over the surface.
[[nodiscard]] Evaluation evaluate(const AnalyticSurface& truth, const CurvatureResult& estimate,
                                  int boundary_rings = 2);

}  // namespace focal
