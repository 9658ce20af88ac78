#pragma once
// Inline bodies of tangent_frame() and normal_ray(): the per-vertex fit calls them once per vertex
// and once per neighbour, and out of line (with std::optional in between) they were a fifth of
// its time. normal_rays.cpp wraps them, so the public functions and the fit share one formula.

#include <Eigen/Core>
#include <cmath>

#include "focal/curvature/normal_rays.h"

namespace focal::detail {

inline TangentFrame frame_of(const Eigen::Vector3d& n) {
  // Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017): continuous everywhere
  // except across n.z = 0's sign flip, branch-free and exactly orthonormal up to rounding.
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  TangentFrame frame;
  frame.x = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  frame.y = Eigen::Vector3d(b, sign + n.y() * n.y() * a, -n.y());
  frame.n = n;
  return frame;
}

/// normal_ray() without std::optional: false where it would be empty (normal outside the
/// hemisphere of frame.n, or a non-finite ray), and `ray` is then unspecified.
inline bool ray_of(const TangentFrame& frame, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& position, const Eigen::Vector3d& normal,
                   NormalRay& ray) {
  const double mz = frame.n.dot(normal);
  if (!(mz > 0.0)) return false;  // also rejects NaN
  const Eigen::Vector3d q = position - origin;
  const double qz = frame.n.dot(q);
  ray.sigma = frame.x.dot(normal) / mz;
  ray.tau = frame.y.dot(normal) / mz;
  ray.u = frame.x.dot(q) - qz * ray.sigma;
  ray.v = frame.y.dot(q) - qz * ray.tau;
  // A NaN or infinite position or normal yields no ray rather than poisoning the fit.
  return std::isfinite(ray.sigma + ray.tau + ray.u + ray.v);
}

}  // namespace focal::detail
