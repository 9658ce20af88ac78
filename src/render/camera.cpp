// Cameras: look-at, orbit around a bounding sphere, and the OpenGL view-projection matrix.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "focal/render/render.h"

namespace focal {
namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

bool finite_vector(const Eigen::Vector3d& v) { return v.allFinite(); }

void check_camera(const Camera& c) {
  const Eigen::Vector3d forward = c.target - c.eye;
  if (!finite_vector(c.eye) || !finite_vector(c.target) || !finite_vector(c.up) ||
      forward.norm() == 0.0 || forward.cross(c.up).norm() <= 1e-12 * forward.norm() * c.up.norm()) {
    throw InvalidInput(
        "camera: eye, target and up must be finite, eye != target, and up not "
        "parallel to the viewing direction");
  }
  if (!(c.near > 0.0) || !(c.far > c.near) || !std::isfinite(c.far)) {
    throw InvalidInput("camera: need 0 < near < far < infinity, got near " +
                       std::to_string(c.near) + ", far " + std::to_string(c.far));
  }
  if (c.projection == Projection::perspective &&
      !(c.field_of_view > 0.0 && c.field_of_view < 180.0)) {
    throw InvalidInput("camera: field of view must be in (0, 180) degrees, got " +
                       std::to_string(c.field_of_view));
  }
  if (c.projection == Projection::orthographic &&
      !(c.half_extent > 0.0 && std::isfinite(c.half_extent))) {
    throw InvalidInput("camera: orthographic half extent must be finite and positive");
  }
}

/// Rows: camera right, up, backwards (OpenGL eye space looks down -z).
Eigen::Matrix4d view_matrix(const Camera& c) {
  const Eigen::Vector3d back = (c.eye - c.target).normalized();
  const Eigen::Vector3d right = c.up.cross(back).normalized();
  const Eigen::Vector3d up = back.cross(right);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = right.transpose();
  m.block<1, 3>(1, 0) = up.transpose();
  m.block<1, 3>(2, 0) = back.transpose();
  m(0, 3) = -right.dot(c.eye);
  m(1, 3) = -up.dot(c.eye);
  m(2, 3) = -back.dot(c.eye);
  return m;
}

/// Half extents of the view at unit distance (perspective) or in world units (orthographic),
/// the shorter image side getting the camera's value.
Eigen::Vector2d half_extents(const Camera& c, double aspect) {
  const double shorter = c.projection == Projection::perspective
                             ? std::tan(radians(c.field_of_view) / 2.0)
                             : c.half_extent;
  return aspect >= 1.0 ? Eigen::Vector2d(shorter * aspect, shorter)
                       : Eigen::Vector2d(shorter, shorter / aspect);
}

Eigen::Matrix4d projection_matrix(const Camera& c, double aspect) {
  const Eigen::Vector2d h = half_extents(c, aspect);
  const double n = c.near, f = c.far;
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  if (c.projection == Projection::perspective) {
    p(0, 0) = 1.0 / h.x();
    p(1, 1) = 1.0 / h.y();
    p(2, 2) = -(f + n) / (f - n);
    p(2, 3) = -2.0 * f * n / (f - n);
    p(3, 2) = -1.0;
  } else {
    p(0, 0) = 1.0 / h.x();
    p(1, 1) = 1.0 / h.y();
    p(2, 2) = -2.0 / (f - n);
    p(2, 3) = -(f + n) / (f - n);
    p(3, 3) = 1.0;
  }
  return p;
}

}  // namespace

Camera look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = up;
  return c;
}

Camera orbit_camera(const Eigen::Vector3d& centre, double radius, const OrbitView& view) {
  if (!(radius > 0.0) || !std::isfinite(radius) || !centre.allFinite()) {
    throw InvalidInput(
        "orbit_camera: centre must be finite and radius finite and positive, got "
        "radius " +
        std::to_string(radius));
  }
  if (!std::isfinite(view.azimuth) || !std::isfinite(view.elevation) || !(view.margin >= 1.0) ||
      !std::isfinite(view.margin)) {
    throw InvalidInput("orbit_camera: azimuth and elevation must be finite and margin >= 1");
  }
  const double elevation = radians(std::clamp(view.elevation, -89.9, 89.9));
  const double azimuth = radians(view.azimuth);
  const Eigen::Vector3d direction(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                                  std::cos(elevation) * std::cos(azimuth));
  const double fitted = radius * view.margin;
  Camera c;
  c.projection = view.projection;
  c.field_of_view = view.field_of_view;
  c.target = centre;
  double distance = 0.0;
  if (view.projection == Projection::perspective) {
    if (!(view.field_of_view > 0.0 && view.field_of_view < 180.0)) {
      throw InvalidInput("orbit_camera: field of view must be in (0, 180) degrees");
    }
    // The cone of half-angle fov/2 is tangent to the fitted sphere at this distance.
    distance = fitted / std::sin(radians(view.field_of_view) / 2.0);
  } else {
    c.half_extent = fitted;
    distance = 3.0 * fitted;  // any distance outside the sphere gives the same picture
  }
  c.eye = centre + distance * direction;
  // Near and far enclose the fitted sphere, with the near plane kept off 0 for depth precision.
  c.near = std::max(distance - fitted, 1e-3 * fitted);
  c.far = distance + fitted;
  return c;
}

Camera fit_camera(PositionsRef V, const OrbitView& view) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  bool any = false;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Eigen::Vector3d p = V.row(i).transpose();
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    any = true;
  }
  if (!any) throw InvalidInput("fit_camera: the mesh has no vertex with finite coordinates");
  const Eigen::Vector3d centre = (lo + hi) / 2.0;
  double radius = 0.0;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Eigen::Vector3d p = V.row(i).transpose();
    if (p.allFinite()) radius = std::max(radius, (p - centre).norm());
  }
  // A single point still gets a view (of unit size around it).
  if (!(radius > 0.0)) radius = 1.0;
  return orbit_camera(centre, radius, view);
}

Eigen::Matrix4d view_projection_matrix(const Camera& camera, double aspect) {
  check_camera(camera);
  if (!(aspect > 0.0) || !std::isfinite(aspect)) {
    throw InvalidInput("view_projection_matrix: aspect ratio must be finite and positive");
  }
  return projection_matrix(camera, aspect) * view_matrix(camera);
}

}  // namespace focal
