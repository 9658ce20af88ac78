#pragma once
/// \file point_class.h
/// The classes of a point by its principal curvatures, and the classification's default
/// thresholds. Eigen-free: the kernels that nvcc compiles (src/kernels/) write these codes too.

#include <cstdint>
#include <string_view>

namespace focal {

/// Classification of a vertex (or face) from its principal curvatures. The codes are stable:
/// they are written to PLY files as a uchar property.
enum class PointClass : std::uint8_t {
  elliptic = 0,    ///< K > 0 and not umbilic
  hyperbolic = 1,  ///< K < 0
  parabolic = 2,   ///< exactly one principal curvature near zero
  umbilic = 3,     ///< k1 ~ k2, not near zero (sphere-like)
  flat = 4,        ///< both principal curvatures near zero
  undefined = 5,  ///< no estimate: too few usable rays, singular fit or invalid input at the vertex
};

/// Lower-case name of a class (`elliptic`, ..., `undefined`).
[[nodiscard]] std::string_view class_name(PointClass c);

/// Default of Tolerances::zero (and of jet_curvature's classes): |k| x (mean edge length) at or
/// below it counts as zero, a curvature radius over 1000 edge lengths.
inline constexpr double default_zero_tolerance = 1e-3;
/// Default of Tolerances::umbilic: k1 - k2 <= 1e-2 max(|k1|, |k2|) is umbilic.
inline constexpr double default_umbilic_tolerance = 1e-2;

/// The tolerances of the classes, one struct shared by every estimator's options
/// (CurvatureOptions, RecommendedOptions, CloudOptions).
struct Tolerances {
  /// A principal curvature counts as zero when |k| x (mean edge length, or a cloud's mean
  /// spacing) <= zero: scale-free, so the classes do not depend on the units of the input.
  double zero = default_zero_tolerance;
  /// k1 - k2 <= umbilic x max(|k1|, |k2|) is umbilic.
  double umbilic = default_umbilic_tolerance;
};

}  // namespace focal
