#pragma once
// kernels::Vec3<double> to and from Eigen, for the CPU code that calls the kernels' formulas
// (kernels/local_shape.h) from Eigen data. Host only: nvcc never sees Eigen.

#include <Eigen/Core>

#include "kernels/vec3.h"

namespace focal::kernels {

inline Vec3<double> vec3_of(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

inline Eigen::Vector3d eigen_of(const Vec3<double>& v) { return {v.x, v.y, v.z}; }

}  // namespace focal::kernels
