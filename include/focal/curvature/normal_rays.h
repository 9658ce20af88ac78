#pragma once
/// \file normal_rays.h
/// The normal-ray parametrisation of the paper, section 4.1.
///
/// At a vertex P with unit normal N take an orthonormal frame (x, y, N) with origin P. A
/// neighbour Q with unit normal M, both expressed in that frame and with M.z > 0, is the ray
/// through (u, v, 0) and (u + sigma, v + tau, 1):
///     sigma = M.x / M.z,  tau = M.y / M.z,  u = Q.x - Q.z sigma,  v = Q.y - Q.z tau.
/// The vertex's own ray is [0, 0, 0, 0].

#include <Eigen/Core>
#include <optional>

namespace focal {

/// A right-handed orthonormal frame (x, y, n) at a surface point.
struct TangentFrame {
  Eigen::Vector3d x;
  Eigen::Vector3d y;
  Eigen::Vector3d n;

  /// Tangent-plane coordinates of a 3D direction (its x and y components).
  [[nodiscard]] Eigen::Vector2d to_plane(const Eigen::Vector3d& w) const {
    return {x.dot(w), y.dot(w)};
  }
  /// The 3D direction of tangent-plane coordinates.
  [[nodiscard]] Eigen::Vector3d from_plane(const Eigen::Vector2d& p) const {
    return p.x() * x + p.y() * y;
  }
};

/// A frame whose n is the given unit normal; x and y are chosen deterministically and smoothly
/// away from n = -z (the branch-free construction of Duff et al. 2017).
[[nodiscard]] TangentFrame tangent_frame(const Eigen::Vector3d& unit_normal);

/// A normal ray in two-plane coordinates (paper eq. 3): slopes (sigma, tau) towards z = 1 and the
/// intersection (u, v) with the tangent plane z = 0.
struct NormalRay {
  double sigma = 0.0;
  double tau = 0.0;
  double u = 0.0;
  double v = 0.0;
};

/// The ray of the neighbour at `position` with unit `normal`, seen from the vertex at `origin`
/// with frame `frame`. Empty when the neighbour's normal is not in the open hemisphere of
/// frame.n (M.z <= 0), where the ray cannot be parametrised.
[[nodiscard]] std::optional<NormalRay> normal_ray(const TangentFrame& frame,
                                                  const Eigen::Vector3d& origin,
                                                  const Eigen::Vector3d& position,
                                                  const Eigen::Vector3d& normal);

}  // namespace focal
