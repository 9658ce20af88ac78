#include "focal/evaluation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "focal/neighbourhood.h"

namespace focal {
namespace {

/// Running sums of squared errors and squared truth of one quantity.
struct Rms {
  double error = 0, truth = 0;
  void add(double estimate, double exact) {
    error += (estimate - exact) * (estimate - exact);
    truth += exact * exact;
  }
  [[nodiscard]] double absolute(int n) const { return n > 0 ? std::sqrt(error / n) : NAN; }
  /// NaN where the truth's RMS is below 1e-9 of the error scale (a zero field).
  [[nodiscard]] double relative() const {
    return truth > 1e-18 * (error + 1.0) ? std::sqrt(error / truth) : NAN;
  }
};

double line_angle_degrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = std::min(1.0, std::abs(a.dot(b)) / (a.norm() * b.norm()));
  return std::acos(c) * 180.0 / std::numbers::pi;
}

ErrorMetrics measure(const AnalyticSurface& t, const CurvatureResult& e, const std::vector<int>& at,
                     double umbilic_gap) {
  ErrorMetrics m;
  Rms h, k, k1, k2;
  std::vector<double> angles;
  double sum_h = 0, sum_h2 = 0;
  int defined = 0;
  for (int i : at) {
    ++m.vertices;
    if (e.class_of(i) == PointClass::undefined || !std::isfinite(e.k1[i]) ||
        !std::isfinite(e.k2[i])) {
      ++m.undefined;
      continue;
    }
    ++defined;
    h.add(e.H[i], 0.5 * (t.k1[i] + t.k2[i]));
    k.add(e.K[i], t.k1[i] * t.k2[i]);
    k1.add(e.k1[i], t.k1[i]);
    k2.add(e.k2[i], t.k2[i]);
    sum_h += e.H[i];
    sum_h2 += e.H[i] * e.H[i];
    if (t.k1[i] - t.k2[i] > umbilic_gap)
      angles.push_back(line_angle_degrees(e.d1.row(i), t.d1.row(i)));
  }
  m.relative_H = h.relative(), m.relative_K = k.relative();
  m.relative_k1 = k1.relative(), m.relative_k2 = k2.relative();
  m.rms_H = h.absolute(defined), m.rms_K = k.absolute(defined);
  m.rms_k1 = k1.absolute(defined), m.rms_k2 = k2.absolute(defined);
  m.variance_H = defined > 0 ? sum_h2 / defined - (sum_h / defined) * (sum_h / defined) : NAN;
  m.median_angle_d1 = m.mean_angle_d1 = NAN;
  if (!angles.empty()) {
    std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
    m.median_angle_d1 = angles[angles.size() / 2];
    double sum = 0;
    for (double a : angles) sum += a;
    m.mean_angle_d1 = sum / static_cast<double>(angles.size());
  }
  return m;
}

}  // namespace

Evaluation evaluate(const AnalyticSurface& truth, const CurvatureResult& estimate,
                    int boundary_rings) {
  const int n = static_cast<int>(truth.mesh.V.rows());
  const Neighbourhoods one_ring = vertex_adjacency(n, truth.mesh.F);
  const Eigen::VectorXi distance =
      rings_to_boundary(one_ring, boundary_vertices(n, truth.mesh.F), boundary_rings);
  std::vector<int> interior, near;
  for (int i = 0; i < n; ++i) (distance[i] > boundary_rings ? interior : near).push_back(i);
  double kappa = 0;
  for (int i = 0; i < n; ++i)
    kappa = std::max({kappa, std::abs(truth.k1[i]), std::abs(truth.k2[i])});
  return {measure(truth, estimate, interior, 0.2 * kappa),
          measure(truth, estimate, near, 0.2 * kappa)};
}

}  // namespace focal
