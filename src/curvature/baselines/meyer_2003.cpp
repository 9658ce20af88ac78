// MDSB03: Meyer, Desbrun, Schroeder, Barr (2003), the paper's first baseline.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "curvature/vertex_rows.h"
#include "focal/curvature/baselines.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"

namespace focal::baselines {
namespace {

/// One edge (i, j) seen from vertex i: its neighbour and its share of i's Voronoi area weight.
struct EdgeWeight {
  int j;
  double weight;
};

/// What one vertex gathers from its incident faces.
struct VertexSums {
  Eigen::Vector3d laplace = Eigen::Vector3d::Zero();  ///< sum (cot a + cot b)(x_i - x_j)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   ///< area-weighted (2 x area) normal
  double mixed_area = 0.0;
  double angle_sum = 0.0;
};

double cotangent(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a.dot(b) / a.cross(b).norm();
}

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// Adds face f's contributions to vertex i (MDSB03 sections 3.3-3.4 and Fig. 4's mixed area).
void add_face(PositionsRef V, FacesRef F, int f, int i, VertexSums& s,
              std::vector<EdgeWeight>& edges) {
  int c = 0;
  while (F(f, c) != i) ++c;
  const int j = F(f, (c + 1) % 3), k = F(f, (c + 2) % 3);
  const Eigen::Vector3d a = V.row(i), b = V.row(j), d = V.row(k);
  if (detail::is_degenerate_triangle(a, b, d)) return;
  const double cot_j = cotangent(a - b, d - b), cot_k = cotangent(a - d, b - d);
  const double angle_i = angle_between(b - a, d - a);
  s.laplace += cot_k * (a - b) + cot_j * (a - d);
  s.normal += (b - a).cross(d - a);
  s.angle_sum += angle_i;
  const double area = 0.5 * (b - a).cross(d - a).norm();
  const double right = 0.5 * std::numbers::pi;
  if (angle_i > right) {
    s.mixed_area += area / 2;
  } else if (cot_j < 0.0 || cot_k < 0.0) {  // obtuse at j or k
    s.mixed_area += area / 4;
  } else {
    s.mixed_area += ((b - a).squaredNorm() * cot_k + (d - a).squaredNorm() * cot_j) / 8;
  }
  edges.push_back({j, (b - a).squaredNorm() * cot_k / 8});
  edges.push_back({k, (d - a).squaredNorm() * cot_j / 8});
}

/// Least-squares tensor B = [a b; b c] with a + c = 2H fitted to the edges' normal curvatures
/// (MDSB03 section 5): d^T B d = a (dx^2 - dy^2) + 2 b dx dy + 2H dy^2.
detail::Principal2 fit_directions(PositionsRef V, int i, const TangentFrame& frame, double H,
                                  std::vector<EdgeWeight>& edges, double& residual, int& used) {
  std::sort(edges.begin(), edges.end(), [](auto& x, auto& y) { return x.j < y.j; });
  Eigen::Matrix2d lhs = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector3d> rows;  // (row0, row1, target) per merged edge, with its weight
  for (std::size_t e = 0; e < edges.size();) {
    double w = 0.0;
    const int j = edges[e].j;
    for (; e < edges.size() && edges[e].j == j; ++e) w += edges[e].weight;
    const Eigen::Vector3d x = V.row(j) - V.row(i);
    const Eigen::Vector2d d = frame.to_plane(x).normalized();
    const double kappa = -2.0 * x.dot(frame.n) / x.squaredNorm();
    const Eigen::Vector2d row(d.x() * d.x() - d.y() * d.y(), 2 * d.x() * d.y());
    const double target = kappa - 2 * H * d.y() * d.y();
    // Unit weights: MDSB03 weights by the edges' Voronoi shares, but those vanish on the edges
    // opposite right angles (every diagonal of a square grid), which leaves the fit singular.
    w = 1.0;
    lhs += w * row * row.transpose();
    rhs += w * target * row;
    rows.emplace_back(row.x() * std::sqrt(w), row.y() * std::sqrt(w), target * std::sqrt(w));
  }
  const Eigen::Vector2d ab = lhs.ldlt().solve(rhs);
  double misfit = 0.0;
  for (const auto& r : rows) misfit += std::pow(r.x() * ab.x() + r.y() * ab.y() - r.z(), 2);
  residual = std::sqrt(misfit / std::max<std::size_t>(rows.size(), 1));
  used = static_cast<int>(rows.size());
  return detail::principal_from_symmetric(ab.x(), ab.y(), 2 * H - ab.x());
}

}  // namespace

CurvatureResult meyer_2003(PositionsRef V, FacesRef F, const CurvatureOptions& options) {
  const PreparedMesh mesh = detail::PreparedAccess::make(V, F, std::nullopt, {}, "MDSB03");
  const std::shared_ptr<const detail::VertexFaces> incidence = detail::incidence(mesh);
  const detail::VertexFaces& inc = *incidence;
  const std::vector<bool> boundary = boundary_vertices(static_cast<int>(V.rows()), F);
  const detail::ClassTolerances tol = detail::class_tolerances(options, mesh.mean_edge_length());
  CurvatureResult r = detail::undefined_result(V.rows(), 0);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t i) {
    thread_local std::vector<EdgeWeight> edges;
    edges.clear();
    VertexSums s;
    for (int k = inc.begin(i); k < inc.end(i); ++k)
      add_face(V, F, inc.faces[k], static_cast<int>(i), s, edges);
    if (!(s.mixed_area > 0.0) || !(s.normal.norm() > 0.0) || edges.size() < 4) return;
    const TangentFrame frame = tangent_frame(s.normal.normalized());
    const double H = 0.5 * s.laplace.dot(frame.n) / (2.0 * s.mixed_area);
    const double full =
        boundary[static_cast<std::size_t>(i)] ? std::numbers::pi : 2 * std::numbers::pi;
    const double K = (full - s.angle_sum) / s.mixed_area;
    double residual = 0.0;
    int used = 0;
    detail::Principal2 p = fit_directions(V, static_cast<int>(i), frame, H, edges, residual, used);
    const double root = std::sqrt(std::max(H * H - K, 0.0));
    p.k1 = H + root;
    p.k2 = H - root;
    detail::store_vertex(r, i, frame, p, residual, tol);
    r.K[i] = K;             // the angle defect itself, not k1 k2 (they differ where H^2 < K)
    r.rays_used[i] = used;  // edges in the direction fit
  });
  return r;
}

}  // namespace focal::baselines
