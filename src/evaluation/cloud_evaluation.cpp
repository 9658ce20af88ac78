#include "focal/evaluation/cloud_evaluation.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace focal {

std::vector<CloudCase> cloud_cases(int points, std::uint64_t seed) {
  struct Variant {
    const char* name;
    CloudSampleOptions sample;
  };
  const Variant variants[] = {
      {"exact normals", {}},
      {"no normals", {.normals = false}},
      {"position noise 0.1, no normals", {.position_noise = 0.1, .normals = false}},
      {"normal noise 0.05", {.normal_noise = 0.05}},
      {"graded density 0.5, no normals", {.graded = 0.5, .normals = false}},
      {"2% outliers, no normals", {.outliers = 0.02, .normals = false}},
  };
  std::vector<CloudCase> cases;
  for (const SurfaceKind kind : all_surfaces()) {
    for (const Variant& v : variants) {
      CloudCase c{std::string(surface_name(kind)) + "/" + v.name, v.sample};
      c.sample.surface.kind = kind;
      c.sample.surface.target_vertices = points;
      c.sample.surface.seed = seed;
      cases.push_back(c);
    }
  }
  return cases;
}

CloudCaseResult evaluate_cloud_case(const CloudCase& c, const CloudOptions& options) {
  const AnalyticSurface s = sample_cloud(c.sample);
  const CloudCurvature estimate = estimate_cloud_curvature(s.mesh.V, s.mesh.normals(), options);
  const CurvatureResult& r = estimate.curvature;
  double scale = 0.0, h_sum = 0.0, k_sum = 0.0;
  int count = 0;
  CloudCaseResult out{c.name, static_cast<int>(s.mesh.V.rows())};
  for (Eigen::Index i = 0; i < s.k1.size(); ++i) {
    if (!std::isfinite(s.k1[i])) continue;  // an outlier: no truth
    scale = std::max({scale, std::abs(s.k1[i]), std::abs(s.k2[i])});
    if (!std::isfinite(r.H[i])) {
      ++out.undefined;
      continue;
    }
    const double h = r.H[i] - 0.5 * (s.k1[i] + s.k2[i]);
    const double k = r.K[i] - s.k1[i] * s.k2[i];
    h_sum += h * h, k_sum += k * k, ++count;
  }
  const double n = std::max(count, 1);
  out.h_relative_rms = std::sqrt(h_sum / n) / scale;
  out.k_relative_rms = std::sqrt(k_sum / n) / (scale * scale);
  out.noise = estimate.noise;
  out.k = estimate.k;
  return out;
}

}  // namespace focal
