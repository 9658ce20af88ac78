#pragma once
// tangent_frame() and normal_ray() inline, as Eigen adapters of kernels/local_shape.h's frame_of
// and normal_ray (the formulas every estimator shares): the per-vertex fit calls them once per
// vertex and once per neighbour, so they are inlined there, without a std::optional in between.
// normal_rays.cpp wraps them as the public functions.

#include <Eigen/Core>

#include "focal/curvature/normal_rays.h"
#include "kernels/eigen.h"
#include "kernels/local_shape.h"
#include "kernels/vec3.h"

namespace focal::detail {

using kernels::eigen_of;
using kernels::vec3_of;

inline TangentFrame frame_of(const Eigen::Vector3d& n) {
  const kernels::Frame<double> f = kernels::frame_of(vec3_of(n));
  return {eigen_of(f.x), eigen_of(f.y), n};
}

/// normal_ray() without std::optional: false where it would be empty (normal outside the
/// hemisphere of frame.n, or a non-finite ray: a NaN or infinite position or normal yields no
/// ray rather than poisoning the fit), and `ray` is then unspecified. The slopes are divided
/// exactly (kernels::Quotient), as this path always has.
inline bool ray_of(const TangentFrame& frame, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& position, const Eigen::Vector3d& normal, NormalRay& ray) {
  const kernels::Frame<double> f{vec3_of(frame.x), vec3_of(frame.y), vec3_of(frame.n)};
  const kernels::Vec3<double> m = vec3_of(normal);
  return kernels::normal_ray<kernels::Quotient::exact>(f, vec3_of(position - origin), m, m, ray);
}

}  // namespace focal::detail
