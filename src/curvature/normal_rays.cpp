#include "focal/curvature/normal_rays.h"

#include "curvature/normal_rays_detail.h"

namespace focal {

TangentFrame tangent_frame(const Eigen::Vector3d& n) { return detail::frame_of(n); }

std::optional<NormalRay> normal_ray(const TangentFrame& frame, const Eigen::Vector3d& origin,
                                    const Eigen::Vector3d& position,
                                    const Eigen::Vector3d& normal) {
  NormalRay ray;
  if (!detail::ray_of(frame, origin, position, normal, ray)) return std::nullopt;
  return ray;
}

}  // namespace focal
