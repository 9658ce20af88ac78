#pragma once
/// \file recommended.h
/// The recommended estimator: what `focal curvature` runs when no method option is given, and
/// what `focal eval` reports as "focal default". Two entry points: the file gives normals, or it
/// does not.
///
/// CONTRACT DRAFT (issue 4, point 5): today both are the paper's 1-ring closed-form fit, with the
/// file's normals or with Max (1999) normals estimated from the faces; the accuracy work replaces
/// the bodies with measured improvements and documents them here.

#include "focal/curvature.h"

namespace focal {

/// With normals from the file (which may be noisy).
[[nodiscard]] CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F,
                                                             NormalsRef N, int threads = 0);

/// Without normals: they are estimated from the positions.
[[nodiscard]] CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F,
                                                             int threads = 0);

}  // namespace focal
