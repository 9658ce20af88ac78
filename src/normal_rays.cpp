#include "focal/normal_rays.h"

#include <cmath>

namespace focal {

TangentFrame tangent_frame(const Eigen::Vector3d& n) {
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

std::optional<NormalRay> normal_ray(const TangentFrame& frame, const Eigen::Vector3d& origin,
                                    const Eigen::Vector3d& position,
                                    const Eigen::Vector3d& normal) {
  const double mz = frame.n.dot(normal);
  if (!(mz > 0.0)) return std::nullopt;  // also rejects NaN
  const Eigen::Vector3d q = position - origin;
  const double qz = frame.n.dot(q);
  NormalRay ray;
  ray.sigma = frame.x.dot(normal) / mz;
  ray.tau = frame.y.dot(normal) / mz;
  ray.u = frame.x.dot(q) - qz * ray.sigma;
  ray.v = frame.y.dot(q) - qz * ray.tau;
  // A NaN or infinite position or normal yields no ray rather than poisoning the fit.
  if (!std::isfinite(ray.sigma + ray.tau + ray.u + ray.v)) return std::nullopt;
  return ray;
}

}  // namespace focal
