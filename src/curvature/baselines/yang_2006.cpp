// YLHP06: integral invariants (Yang, Lai, Hu, Pottmann, SGP 2006), the surface-patch form.
//
// Derivation of the closed forms in baselines.h: in the frame of the principal directions with
// the outward normal n as z, the surface is z = -(k1 x^2 + k2 y^2) / 2 + O(rho^3). Integrating
// over the patch inside the ball of radius r (its rim at rho = r (1 - O(r^2 k^2))):
//   area        A          = pi r^2 (1 + O(r^2)),
//   centroid    <m - x, n> = -r^2 (k1 + k2) / 8 + O(r^4),
//   variance    n^T C n    = pi r^6 (3 k1^2 - 2 k1 k2 + 3 k2^2) / 192 + O(r^8),
//   tangential  C_xx - C_yy = -pi r^6 (k1^2 - k2^2) / 48 + O(r^8),
// with C = int (x - m)(x - m)^T dA. The odd (cubic) terms of the surface cancel over the disc,
// so the error is O(r^2) relative; on a sphere (a cap of height r^2 / (2R), uniform in height by
// Archimedes) the first two relations are exact. k1 + k2 and k1 k2 follow from the centroid and
// the variance; the tangential difference only orders the directions.
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "curvature/baselines/ball.h"
#include "curvature/vertex_rows.h"
#include "focal/curvature/baselines.h"
#include "mesh/prepared_access.h"

namespace focal::baselines {
namespace {

/// Area, first and second moments of a region, in coordinates relative to the ball's centre.
struct Moments {
  double area = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();

  /// Adds a triangle: int x dA = A s / 3, int x x^T dA = A (sum v v^T + s s^T) / 12, s = a + b + c.
  void add_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const double A = 0.5 * (b - a).cross(c - a).norm();
    const Eigen::Vector3d s = a + b + c;
    area += A;
    first += A / 3.0 * s;
    second +=
        A / 12.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
};

/// The polygon of triangle (p0, p1, p2) (relative to the centre) inside the ball |x| <= r, the
/// sphere's arcs replaced by chords between the crossings of the edges; up to 9 corners.
int clip_to_ball(const std::array<Eigen::Vector3d, 3>& p, double r,
                 std::array<Eigen::Vector3d, 9>& out) {
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& a = p[k];
    const Eigen::Vector3d d = p[(k + 1) % 3] - a;
    if (a.squaredNorm() <= r * r) out[n++] = a;
    // |a + t d|^2 = r^2: the crossings with t in (0, 1), in order along the edge.
    const double dd = d.squaredNorm(), ad = a.dot(d),
                 disc = ad * ad - dd * (a.squaredNorm() - r * r);
    if (!(dd > 0.0) || !(disc > 0.0)) continue;
    const double root = std::sqrt(disc);
    for (double t : {(-ad - root) / dd, (-ad + root) / dd}) {
      if (t > 0.0 && t < 1.0) out[n++] = a + t * d;
    }
  }
  return n;
}

Moments ball_moments(PositionsRef V, FacesRef F, const std::vector<int>& faces,
                     const Eigen::Vector3d& centre, double r) {
  Moments m;
  std::array<Eigen::Vector3d, 3> corners;
  std::array<Eigen::Vector3d, 9> polygon;
  for (int f : faces) {
    for (int c = 0; c < 3; ++c) corners[c] = V.row(F(f, c)).transpose() - centre;
    const int n = clip_to_ball(corners, r, polygon);
    for (int k = 1; k + 1 < n; ++k) m.add_triangle(polygon[0], polygon[k], polygon[k + 1]);
  }
  return m;
}

/// The area-weighted normal of vertex i (sum of its finite faces' cross products), not normalised.
Eigen::Vector3d area_normal(PositionsRef V, FacesRef F, const focal::detail::VertexFaces& inc,
                            std::int64_t i) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int k = inc.begin(i); k < inc.end(i); ++k) {
    const int f = inc.faces[k];
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (cross.allFinite())
      n += cross;  // a non-finite corner leaves its faces out, as the clip does
  }
  return n;
}

/// The curvature read from the patch's moments (see the top of this file).
struct PatchCurvature {
  TangentFrame frame;  ///< n: the covariance's eigenvector of the smallest eigenvalue
  focal::detail::Principal2 principal;
  double residual;  ///< how far the variance is from any real pair (k1, k2); 0 when consistent
};

std::optional<PatchCurvature> patch_curvature(const Moments& m, const Eigen::Vector3d& orientation,
                                              double r) {
  const Eigen::Vector3d centroid = m.first / m.area;
  const Eigen::Matrix3d C = m.second - m.area * centroid * centroid.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);  // ascending: n, then tangents
  if (eig.info() != Eigen::Success) return std::nullopt;
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  if (n.dot(orientation) < 0.0) n = -n;
  const double r2 = r * r, r6 = r2 * r2 * r2;
  const double sum = -8.0 * centroid.dot(n) / r2;  // k1 + k2
  const double product =
      (3.0 * sum * sum - 192.0 * eig.eigenvalues()[0] / (std::numbers::pi * r6)) / 8.0;
  const double disc = sum * sum - 4.0 * product;
  const double half_gap = 0.5 * std::sqrt(std::max(disc, 0.0));
  PatchCurvature out{tangent_frame(n), {}, std::sqrt(std::max(-disc, 0.0))};
  out.principal.k1 = 0.5 * sum + half_gap;
  out.principal.k2 = 0.5 * sum - half_gap;
  // The larger |k| bends the patch most along its direction: the smaller tangent variance.
  const bool k1_steeper = std::abs(out.principal.k1) >= std::abs(out.principal.k2);
  const Eigen::Vector3d d1 = eig.eigenvectors().col(k1_steeper ? 1 : 2);
  out.principal.d1 = out.frame.to_plane(d1).normalized();
  out.principal.d2 = Eigen::Vector2d(-out.principal.d1.y(), out.principal.d1.x());
  return out;
}

}  // namespace

CurvatureResult yang_2006(PositionsRef V, FacesRef F, const BallOptions& ball,
                          const CurvatureOptions& options) {
  const PreparedMesh mesh = focal::detail::PreparedAccess::make(V, F, std::nullopt, {}, "YLHP06");
  const double r = ball::radius(ball, 4.0, mesh.mean_edge_length(), "YLHP06");
  const auto incidence = focal::detail::incidence(mesh);
  const focal::detail::ClassTolerances tol =
      focal::detail::class_tolerances(options, mesh.mean_edge_length());
  CurvatureResult result = focal::detail::undefined_result(V.rows(), 0);
  ball::for_each_ball(mesh, r, 0, [&](std::int64_t i, const std::vector<int>& faces) {
    const Moments m = ball_moments(V, F, faces, V.row(i), r);
    const Eigen::Vector3d orientation = area_normal(V, F, *incidence, i);
    if (!(m.area > 0.0) || !(r > 0.0) || !(orientation.norm() > 0.0)) return;
    const std::optional<PatchCurvature> c = patch_curvature(m, orientation, r);
    if (!c) return;
    focal::detail::store_vertex(result, i, c->frame, c->principal, c->residual, tol);
    result.rays_used[i] = static_cast<int>(faces.size());  // faces reached
  });
  return result;
}

}  // namespace focal::baselines
