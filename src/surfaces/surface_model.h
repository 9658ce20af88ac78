#pragma once
// The analytic surfaces as parametrisations X(u, v) with exact differential geometry, shared by
// the triangulations and the public API of surfaces.h.

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "focal/surfaces/surfaces.h"

namespace focal::detail {

using Face = std::array<int, 3>;
constexpr double kPi = std::numbers::pi;

/// Uniform in [0, 1) from the 53 high bits of one draw: std::uniform_real_distribution differs
/// between standard libraries, this mapping does not.
inline double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * uniform01(rng);
}

/// X(u, v) and its first and second partial derivatives.
struct Derivatives {
  Eigen::Vector3d x, xu, xv, xuu, xuv, xvv;
};

/// Closed-form truth from the first and second fundamental forms (curvature positive where the
/// surface bends away from the outward normal; sphere +1/r).
SurfacePoint point_from_derivatives(const Derivatives& d);

class Parametrisation {
 public:
  Parametrisation() = default;
  Parametrisation(const Parametrisation&) = delete;
  Parametrisation& operator=(const Parametrisation&) = delete;
  virtual ~Parametrisation() = default;

  [[nodiscard]] virtual ParameterDomain domain() const = 0;
  [[nodiscard]] virtual Derivatives derivatives(double u, double v) const = 0;
  /// Truth at the north (u = u_min) or south (u = u_max) pole; only for domains with poles.
  [[nodiscard]] virtual SurfacePoint pole(bool north) const = 0;
  /// A planar chart close to conformal in which the irregular samples are Delaunay-triangulated:
  /// the closer to conformal, the fewer edge flips in space are needed afterwards.
  [[nodiscard]] virtual Eigen::Vector2d chart(double u, double v) const = 0;
  /// Chart translation of one period of u (x) and of v (y); 0 where not periodic.
  [[nodiscard]] virtual Eigen::Vector2d chart_period() const { return Eigen::Vector2d::Zero(); }
  /// Length in space of the shortest closed parameter line along a periodic direction (0 when
  /// there is none): the irregular sampling must put several points around it.
  [[nodiscard]] virtual double shortest_loop() const { return 0.0; }
};

/// The parametrisation selected by the options, with defaults filled in.
/// \throw InvalidInput for invalid shape parameters.
std::unique_ptr<Parametrisation> make_parametrisation(const SurfaceOptions& o);

/// The truth at parameters uv (poles handled by the surface's pole()).
SurfacePoint evaluate(const Parametrisation& s, const ParameterDomain& d,
                      const Eigen::Vector2d& uv);

}  // namespace focal::detail
