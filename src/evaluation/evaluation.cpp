#include "focal/evaluation/evaluation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <string>
#include <utility>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/neighbourhood.h"

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

bool on_crease(const AnalyticSurface& truth, int i) {
  return truth.crease.size() > 0 && truth.crease[i] != 0;
}

/// The umbilic gap of the direction error: 0.2 max |k| over the surface.
double umbilic_gap(const AnalyticSurface& truth) {
  double kappa = 0;
  for (Eigen::Index i = 0; i < truth.k1.size(); ++i)
    kappa = std::max({kappa, std::abs(truth.k1[i]), std::abs(truth.k2[i])});
  return 0.2 * kappa;
}

void check_sizes(const AnalyticSurface& truth, const CurvatureResult& estimate, const char* what) {
  const Eigen::Index n = truth.mesh.V.rows();
  if (estimate.k1.size() != n || estimate.k2.size() != n || estimate.H.size() != n ||
      estimate.K.size() != n || estimate.d1.rows() != n || estimate.point_class.size() != n)
    throw InvalidInput(std::string(what) + ": the estimate has not one row per vertex");
  if (truth.crease.size() != 0 && truth.crease.size() != n)
    throw InvalidInput(std::string(what) + ": the crease flags have not one entry per vertex");
}

}  // namespace

Evaluation evaluate(const AnalyticSurface& truth, const CurvatureResult& estimate,
                    int boundary_rings) {
  check_sizes(truth, estimate, "evaluate");
  const int n = static_cast<int>(truth.mesh.V.rows());
  const VectorXu8 mask = interior_mask(n, truth.mesh.F, boundary_rings);
  std::vector<int> interior, near;
  for (int i = 0; i < n; ++i) {
    if (!on_crease(truth, i)) (mask[i] ? interior : near).push_back(i);
  }
  const double gap = umbilic_gap(truth);
  return {measure(truth, estimate, interior, gap), measure(truth, estimate, near, gap)};
}

ErrorMetrics evaluate_at(const AnalyticSurface& truth, const CurvatureResult& estimate,
                         const VectorXu8& scored) {
  check_sizes(truth, estimate, "evaluate_at");
  const int n = static_cast<int>(truth.mesh.V.rows());
  if (scored.size() != n) throw InvalidInput("evaluate_at: `scored` needs one flag per vertex");
  std::vector<int> at;
  for (int i = 0; i < n; ++i) {
    if (scored[i] && !on_crease(truth, i)) at.push_back(i);
  }
  return measure(truth, estimate, at, umbilic_gap(truth));
}

namespace {

/// Rings from the boundary per vertex (0 on it), counted up to `max_rings` (beyond: more), after
/// `what`'s checks of F against vertex_count.
Eigen::VectorXi rings_from_boundary(int vertex_count, FacesRef F, int max_rings, const char* what) {
  const RowMatrixX3d no_normals(0, 3);
  validate_mesh_arrays(RowMatrixX3d::Zero(vertex_count, 3), F, no_normals, what);
  const Neighbourhoods one_ring = vertex_adjacency(vertex_count, F);
  return rings_to_boundary(one_ring, boundary_vertices(vertex_count, F), max_rings);
}

}  // namespace

VectorXu8 boundary_band_mask(int vertex_count, FacesRef F, int first_ring, int last_ring) {
  if (first_ring < 0 || last_ring < first_ring || vertex_count < 0)
    throw InvalidInput("boundary_band_mask: need 0 <= first_ring <= last_ring");
  const Eigen::VectorXi distance =
      rings_from_boundary(vertex_count, F, last_ring, "boundary_band_mask");
  VectorXu8 mask(vertex_count);
  for (int i = 0; i < vertex_count; ++i)
    mask[i] = distance[i] >= first_ring && distance[i] <= last_ring ? 1 : 0;
  return mask;
}

VectorXu8 interior_mask(int vertex_count, FacesRef F, int boundary_rings) {
  if (boundary_rings < 0 || vertex_count < 0)
    throw InvalidInput("interior_mask: boundary_rings and vertex_count must be >= 0");
  const Eigen::VectorXi distance =
      rings_from_boundary(vertex_count, F, boundary_rings, "interior_mask");
  VectorXu8 mask(vertex_count);
  for (int i = 0; i < vertex_count; ++i) mask[i] = distance[i] > boundary_rings ? 1 : 0;
  return mask;
}

const std::vector<std::string>& truth_field_names() {
  static const std::vector<std::string> names = {"k1",  "k2",  "H",   "K",   "d1x",     "d1y",
                                                 "d1z", "d2x", "d2y", "d2z", "interior"};
  return names;
}

void export_case(const std::filesystem::path& mesh_path, const std::filesystem::path& truth_path,
                 const AnalyticSurface& surface, int boundary_rings) {
  export_case(
      mesh_path, truth_path, surface,
      interior_mask(static_cast<int>(surface.mesh.V.rows()), surface.mesh.F, boundary_rings));
}

void export_case(const std::filesystem::path& mesh_path, const std::filesystem::path& truth_path,
                 const AnalyticSurface& surface, const VectorXu8& scored) {
  const Mesh& m = surface.mesh;
  const int n = static_cast<int>(m.V.rows());
  if (surface.k1.size() != n || surface.k2.size() != n || surface.d1.rows() != n ||
      surface.d2.rows() != n || scored.size() != n ||
      (surface.crease.size() != 0 && surface.crease.size() != n))
    throw InvalidInput("export_case: the truth or the flags have not one row per vertex");
  VectorXu8 mask = scored;
  for (int i = 0; i < n; ++i) {
    if (on_crease(surface, i)) mask[i] = 0;
  }
  const Eigen::VectorXd H = 0.5 * (surface.k1 + surface.k2);
  const Eigen::VectorXd K = surface.k1.cwiseProduct(surface.k2);
  const std::vector<std::string>& names = truth_field_names();
  const Eigen::VectorXd values[11] = {surface.k1,
                                      surface.k2,
                                      H,
                                      K,
                                      surface.d1.col(0),
                                      surface.d1.col(1),
                                      surface.d1.col(2),
                                      surface.d2.col(0),
                                      surface.d2.col(1),
                                      surface.d2.col(2),
                                      mask.cast<double>()};
  std::vector<CsvColumn> columns;
  for (int k = 0; k < 11; ++k) columns.push_back({names[k], values[k]});
  write_ply(mesh_path, m, {}, {.binary = true, .comments = {"focal eval --export case"}});
  write_csv(truth_path, columns);
}

namespace {

/// numpy.percentile's default ("linear"): position q (n - 1) in the sorted values, interpolated.
double percentile(const std::vector<double>& sorted, double q) {
  const double position = q * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double t = position - static_cast<double>(below);
  return sorted[below] + t * (sorted[above] - sorted[below]);
}

/// Each undirected edge of F once.
std::set<std::pair<int, int>> unique_edges(FacesRef F) {
  std::set<std::pair<int, int>> edges;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  return edges;
}

}  // namespace

FieldSmoothness field_smoothness(PositionsRef V, FacesRef F, const Eigen::VectorXd& H) {
  const RowMatrixX3d no_normals(0, 3);
  validate_mesh_arrays(V, F, no_normals, "field_smoothness");
  if (H.size() != V.rows()) throw InvalidInput("field_smoothness: H needs one value per vertex");
  FieldSmoothness s;
  s.vertices = static_cast<int>(V.rows());
  s.edge_length = mean_edge_length(V, F);
  std::vector<double> scaled;
  double sum = 0;
  for (Eigen::Index i = 0; i < H.size(); ++i) {
    if (!std::isfinite(H[i])) continue;
    scaled.push_back(H[i] * s.edge_length);
    sum += scaled.back();
  }
  s.undefined = s.vertices - static_cast<int>(scaled.size());
  s.min = s.max = s.percentile_1 = s.percentile_99 = s.variance = s.sign_change_fraction = NAN;
  if (scaled.empty()) return s;
  const double mean = sum / static_cast<double>(scaled.size());
  double squares = 0;
  for (double x : scaled) squares += (x - mean) * (x - mean);  // two-pass: no cancellation
  s.variance = squares / static_cast<double>(scaled.size());
  std::sort(scaled.begin(), scaled.end());
  s.min = scaled.front(), s.max = scaled.back();
  s.percentile_1 = percentile(scaled, 0.01), s.percentile_99 = percentile(scaled, 0.99);
  // |H h| <= kSignZero counts as no sign: on flat parts (fandisk) H is round-off, whose sign
  // would otherwise flip at random (1e-9 is far above double round-off, far below any shape).
  const auto sign = [&](double x) {
    return x * s.edge_length > kSignZero ? 1 : x * s.edge_length < -kSignZero ? -1 : 0;
  };
  for (const auto& [a, b] : unique_edges(F)) {
    if (!std::isfinite(H[a]) || !std::isfinite(H[b])) continue;
    ++s.edges;
    s.sign_changes += sign(H[a]) * sign(H[b]) < 0;
  }
  if (s.edges > 0) s.sign_change_fraction = static_cast<double>(s.sign_changes) / s.edges;
  return s;
}

}  // namespace focal
