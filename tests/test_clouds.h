#pragma once
// Point clouds with exact truth for the cloud tests: the vertices of an irregular (Poisson-disk,
// uniform density) analytic surface, without its faces.

#include <cmath>

#include "focal/core/fields.h"
#include "focal/surfaces/surfaces.h"

namespace focal::test {

inline AnalyticSurface cloud_of(SurfaceKind kind, int points, std::uint64_t seed = 1) {
  AnalyticSurface s = make_surface({.kind = kind,
                                    .triangulation = Triangulation::irregular,
                                    .target_vertices = points,
                                    .seed = seed});
  s.mesh.F.resize(0, 3);
  return s;
}

/// sqrt(mean (H - H_true)^2) / max |k| over the points with a defined H; NaN counted apart.
struct HError {
  double relative_rms = 0.0;
  int undefined = 0;
};

inline HError h_error(const AnalyticSurface& s, const CurvatureResult& r) {
  const Eigen::VectorXd h_true = 0.5 * (s.k1 + s.k2);
  const double scale = std::max(s.k1.cwiseAbs().maxCoeff(), s.k2.cwiseAbs().maxCoeff());
  HError e;
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index i = 0; i < r.H.size(); ++i) {
    if (std::isnan(r.H[i])) {
      ++e.undefined;
      continue;
    }
    sum += (r.H[i] - h_true[i]) * (r.H[i] - h_true[i]);
    ++count;
  }
  e.relative_rms = std::sqrt(sum / std::max(count, 1)) / scale;
  return e;
}

}  // namespace focal::test
