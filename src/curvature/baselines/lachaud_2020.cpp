// LRTC20: interpolated corrected curvature measures (Lachaud, Romon, Thibert, Coeurjolly, SGP
// 2020; Lachaud et al., DCG 2022), written from the papers' per-triangle closed forms.
//
// A triangle with corners x_i, x_j, x_k and corrected normals u_i, u_j, u_k interpolated
// linearly across it (u_m = (u_i + u_j + u_k) / 3) carries the measures (LRTC20, the closed
// forms of the interpolated corrected measures for a triangle; the equation numbers of the
// papers are not cited here because the papers are not in the repository to check them against)
//
//   mu0 = 1/2 <u_m, (x_j - x_i) x (x_k - x_i)>                                   area
//   mu1 = 1/2 <u_m, (u_k - u_j) x x_i + (u_i - u_k) x x_j + (u_j - u_i) x x_k>   mean (2 H dA)
//   mu2 = 1/2 <u_i, u_j x u_k>                                                   Gauss (K dA)
//   muXY(X, Y) = 1/2 <u_m, <Y, u_k - u_i> X x (x_j - x_i) - <Y, u_j - u_i> X x (x_k - x_i)>
//
// for X, Y in the canonical basis (a 3 x 3 matrix). Checks of the signs against focal's
// convention: with u = x on the unit sphere, mu1 = 2 mu0 exactly, so H = mu1 / (2 mu0) = +1;
// with u varying linearly, u = u_i + A (x - x_i), the bracket of muXY reduces to
// -2 area (X^T A^T Y), so muXY = -mu0 A^T to first order: the principal curvatures are the
// eigenvalues of -sym(muXY) / mu0 (on the tangent plane), with their eigenvectors as directions.
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "curvature/baselines/ball.h"
#include "curvature/baselines/corrected_curvature.h"
#include "curvature/vertex_rows.h"
#include "focal/curvature/baselines.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/prepared_access.h"

namespace focal::baselines {
namespace {

/// The four measures of one triangle (or their weighted sum over a ball).
struct Measures {
  double mu0 = 0.0, mu1 = 0.0, mu2 = 0.0;
  Eigen::Matrix3d muXY = Eigen::Matrix3d::Zero();

  void add(const Measures& m, double weight) {
    mu0 += weight * m.mu0;
    mu1 += weight * m.mu1;
    mu2 += weight * m.mu2;
    muXY += weight * m.muXY;
  }
};

Measures triangle_measures(const std::array<Eigen::Vector3d, 3>& x,
                           const std::array<Eigen::Vector3d, 3>& u) {
  const Eigen::Vector3d um = (u[0] + u[1] + u[2]) / 3.0;
  const Eigen::Vector3d x01 = x[1] - x[0], x02 = x[2] - x[0];
  const Eigen::Vector3d u01 = u[1] - u[0], u02 = u[2] - u[0];
  Measures m;
  m.mu0 = 0.5 * um.dot(x01.cross(x02));
  m.mu1 = 0.5 *
          um.dot((u[2] - u[1]).cross(x[0]) + (u[0] - u[2]).cross(x[1]) + (u[1] - u[0]).cross(x[2]));
  m.mu2 = 0.5 * u[0].dot(u[1].cross(u[2]));
  // <u_m, X x a> = <X, a x u_m>: column Y of muXY is the bracket's X-components.
  const Eigen::Vector3d a = x01.cross(um), b = x02.cross(um);
  m.muXY = 0.5 * (a * u02.transpose() - b * u01.transpose());
  return m;
}

/// The fraction of a face's area inside the ball of radius r (docs in baselines.h) from its
/// nearest and farthest corners' distances to the centre: linear in the distance.
double fraction_of(double near, double far, double r) {
  if (far <= r) return 1.0;
  if (near >= r) return 0.0;
  return (r - near) / (far - near);
}

/// The fraction of face f's area inside the ball.
double fraction_in_ball(PositionsRef V, FacesRef F, int f, const Eigen::Vector3d& centre,
                        double r) {
  double near = INFINITY, far = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double d = (V.row(F(f, c)).transpose() - centre).norm();
    near = std::min(near, d);
    far = std::max(far, d);
  }
  return fraction_of(near, far, r);
}

/// The measures of the ball: the faces reached, each weighted by its fraction inside.
Measures ball_measures(PositionsRef V, FacesRef F, const std::vector<Measures>& face,
                       const std::vector<int>& reached, const Eigen::Vector3d& centre, double r) {
  Measures sum;
  for (int f : reached) {
    const Measures& m = face[static_cast<std::size_t>(f)];
    if (std::isfinite(m.mu0)) sum.add(m, fraction_in_ball(V, F, f, centre, r));
  }
  return sum;
}

/// k1, k2, d1, d2 of -sym(muXY) / mu0 on the plane of `frame`.
focal::detail::Principal2 principal_of(const Measures& sum, const TangentFrame& frame) {
  const Eigen::Matrix<double, 3, 2> P =
      (Eigen::Matrix<double, 3, 2>() << frame.x, frame.y).finished();
  const Eigen::Matrix2d S =
      -P.transpose() * (0.5 * (sum.muXY + sum.muXY.transpose())) * P / sum.mu0;
  return focal::detail::principal_from_symmetric(S(0, 0), S(0, 1), S(1, 1));
}

/// Unit rows of the given normals, or Max's face-weighted normals.
RowMatrixX3d corrected_normals(const PreparedMesh& mesh, std::optional<NormalsRef> N) {
  RowMatrixX3d u = N ? RowMatrixX3d(*N) : vertex_normals(mesh, NormalWeighting::max);
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    const double length = u.row(i).norm();
    u.row(i) = length > 0.0 && std::isfinite(length) ? Eigen::RowVector3d(u.row(i) / length)
                                                     : Eigen::RowVector3d::Constant(NAN);
  }
  return u;
}

/// Row i of `result` from the measures `sum` of its ball (faces reached: `faces`), as the
/// baseline and the recommended estimator's corrected step write it; nothing where the ball's
/// area is not positive.
void store_measures(const Measures& sum, const Eigen::Vector3d& normal, std::int64_t i, int faces,
                    const focal::detail::ClassTolerances& tol, CurvatureResult& result) {
  if (!(sum.mu0 > 0.0)) return;
  const TangentFrame frame = tangent_frame(normal);
  const focal::detail::Principal2 p = principal_of(sum, frame);
  const double H = 0.5 * sum.mu1 / sum.mu0;
  // Residual: how far the anisotropic measure's mean curvature is from mu1's.
  focal::detail::store_vertex(result, i, frame, p, std::abs(0.5 * (p.k1 + p.k2) - H), tol);
  result.H[i] = H;  // the papers' H and K are mu1 / (2 mu0) and mu2 / mu0 themselves
  result.K[i] = sum.mu2 / sum.mu0;
  result.rays_used[i] = faces;  // faces reached
}

}  // namespace

namespace detail {

void corrected_curvature_of_faces(PositionsRef V, const RowMatrixX3d& u,
                                  const std::vector<std::array<int, 3>>& faces, std::int64_t i,
                                  double r, const focal::detail::ClassTolerances& tol,
                                  CurvatureResult& result) {
  const Eigen::Vector3d normal = u.row(i);
  if (!(r > 0.0) || !normal.allFinite()) return;
  const Eigen::Vector3d centre = V.row(i);
  Measures sum;
  for (const auto& t : faces) {
    std::array<Eigen::Vector3d, 3> x, n;
    double near = INFINITY, far = 0.0;
    for (int c = 0; c < 3; ++c) {
      x[c] = V.row(t[static_cast<std::size_t>(c)]);
      n[c] = u.row(t[static_cast<std::size_t>(c)]);
      const double d = (x[c] - centre).norm();
      near = std::min(near, d);
      far = std::max(far, d);
    }
    const Measures m = triangle_measures(x, n);
    if (std::isfinite(m.mu0)) sum.add(m, fraction_of(near, far, r));
  }
  store_measures(sum, normal, i, static_cast<int>(faces.size()), tol, result);
}

CurvatureResult corrected_curvature(const PreparedMesh& mesh, const RowMatrixX3d& u,
                                    const Eigen::VectorXd& radius, int max_rings,
                                    const CurvatureOptions& options) {
  const PositionsRef& V = mesh.V();
  const FacesRef& F = mesh.F();
  std::vector<Measures> face(static_cast<std::size_t>(F.rows()));
  focal::detail::parallel_for(F.rows(), 0, [&](std::int64_t f) {
    std::array<Eigen::Vector3d, 3> x, n;
    for (int c = 0; c < 3; ++c) {
      x[c] = V.row(F(f, c));
      n[c] = u.row(F(f, c));
    }
    face[static_cast<std::size_t>(f)] = triangle_measures(x, n);
  });
  const focal::detail::ClassTolerances tol =
      focal::detail::class_tolerances(options, mesh.mean_edge_length());
  CurvatureResult result = focal::detail::undefined_result(V.rows(), 0);
  const auto radius_of = [&](std::int64_t i) { return radius[i]; };
  ball::for_each_ball(mesh, radius_of, max_rings, 0,
                      [&](std::int64_t i, const std::vector<int>& faces) {
                        const Eigen::Vector3d normal = u.row(i);
                        if (!(radius[i] > 0.0) || !normal.allFinite()) return;
                        const Measures sum = ball_measures(V, F, face, faces, V.row(i), radius[i]);
                        store_measures(sum, normal, i, static_cast<int>(faces.size()), tol, result);
                      });
  return result;
}

}  // namespace detail

CurvatureResult lachaud_2020(PositionsRef V, FacesRef F, std::optional<NormalsRef> N,
                             const BallOptions& ball, const CurvatureOptions& options) {
  const PreparedMesh mesh = focal::detail::PreparedAccess::make(V, F, N, {}, "LRTC20");
  const double r = ball::radius(ball, 1.0, mesh.mean_edge_length(), "LRTC20");
  return detail::corrected_curvature(mesh, corrected_normals(mesh, N),
                                     Eigen::VectorXd::Constant(V.rows(), r), INT_MAX, options);
}

}  // namespace focal::baselines
