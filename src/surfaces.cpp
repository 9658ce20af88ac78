#include "focal/surfaces.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <unordered_map>
#include <utility>

#include "focal/error.h"
#include "planar_delaunay.h"

namespace focal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Face = std::array<int, 3>;
constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------------
// Random numbers

/// Uniform in [0, 1) from the 53 high bits of one draw: std::uniform_real_distribution differs
/// between standard libraries, this mapping does not.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * uniform01(rng);
}

// ---------------------------------------------------------------------------------------------
// Differential geometry of a parametrisation

/// X(u, v) and its first and second partial derivatives.
struct Derivatives {
  Vector3d x, xu, xv, xuu, xuv, xvv;
};

/// Principal curvatures and directions of the symmetric 2x2 shape operator [p q; q r] given in
/// the orthonormal tangent frame (e1, e2) with normal n.
SurfacePoint principal_frame(const Vector3d& x, const Vector3d& n, const Vector3d& e1,
                             const Vector3d& e2, double p, double q, double r) {
  SurfacePoint out;
  out.position = x;
  out.normal = n;
  const double mean = 0.5 * (p + r);
  const double half_gap = std::hypot(0.5 * (p - r), q);
  out.k1 = mean + half_gap;
  out.k2 = mean - half_gap;
  // atan2(0, 0) = 0 picks e1 at an umbilic: any orthonormal pair is right there.
  const double theta = 0.5 * std::atan2(2.0 * q, p - r);
  out.d1 = std::cos(theta) * e1 + std::sin(theta) * e2;
  out.d2 = n.cross(out.d1);
  return out;
}

/// Closed-form truth from the first and second fundamental forms. The second fundamental form
/// is taken against -N, II_ij = -X_ij . N, which makes curvature positive where the surface
/// bends away from the outward normal (sphere: +1/r) and dN = +S dX.
SurfacePoint point_from_derivatives(const Derivatives& d) {
  const Vector3d n = d.xu.cross(d.xv).normalized();
  const Vector3d e1 = d.xu.normalized();
  const Vector3d e2 = n.cross(e1);
  // J maps parameter steps to tangent-frame coordinates; S = J^-T II J^-1 is the shape
  // operator in the orthonormal frame, hence symmetric.
  Eigen::Matrix2d jac;
  jac << e1.dot(d.xu), e1.dot(d.xv), 0.0, e2.dot(d.xv);
  Eigen::Matrix2d second;
  second << -d.xuu.dot(n), -d.xuv.dot(n), -d.xuv.dot(n), -d.xvv.dot(n);
  const Eigen::Matrix2d jac_inv = jac.inverse();
  const Eigen::Matrix2d s = jac_inv.transpose() * second * jac_inv;
  return principal_frame(d.x, n, e1, e2, s(0, 0), 0.5 * (s(0, 1) + s(1, 0)), s(1, 1));
}

/// The truth at a pole with normal n = +-z and curvature kx along x, ky along y.
SurfacePoint pole_point(const Vector3d& x, const Vector3d& n, double kx, double ky) {
  // In the frame (x, n x x) = (x, +-y) the shape operator is diag(kx, ky).
  return principal_frame(x, n, Vector3d::UnitX(), n.cross(Vector3d::UnitX()), kx, 0.0, ky);
}

// ---------------------------------------------------------------------------------------------
// The surfaces

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
  [[nodiscard]] virtual Vector2d chart(double u, double v) const = 0;
  /// Chart translation of one period of u (x) and of v (y); 0 where not periodic.
  [[nodiscard]] virtual Vector2d chart_period() const { return Vector2d::Zero(); }
  /// Length in space of the shortest closed parameter line along a periodic direction (0 when
  /// there is none): the irregular sampling must put several points around it.
  [[nodiscard]] virtual double shortest_loop() const { return 0.0; }
};

/// Surfaces without poles.
class PoleFreeSurface : public Parametrisation {
 public:
  [[nodiscard]] SurfacePoint pole(bool /*north*/) const override {
    throw InvalidInput("surfaces: this surface has no poles");
  }
};

/// D(u, v) = (sin u cos v, sin u sin v, cos u) and its derivatives.
Derivatives unit_sphere(double u, double v) {
  const double su = std::sin(u), cu = std::cos(u), sv = std::sin(v), cv = std::cos(v);
  Derivatives d;
  d.x = {su * cv, su * sv, cu};
  d.xu = {cu * cv, cu * sv, -su};
  d.xv = {-su * sv, su * cv, 0.0};
  d.xuu = -d.x;
  d.xuv = {-cu * sv, cu * cv, 0.0};
  d.xvv = {-su * cv, -su * sv, 0.0};
  return d;
}

/// Closed genus-0 surfaces over the sphere's (polar angle, azimuth) domain.
class PolarSurface : public Parametrisation {
 public:
  [[nodiscard]] ParameterDomain domain() const override {
    ParameterDomain d;
    d.u_max = kPi;
    d.v_max = 2.0 * kPi;
    d.periodic_v = true;
    d.poles = true;
    return d;
  }
  /// Stereographic projection of the direction D(u, v) from the south pole: exactly conformal
  /// for the sphere, and Delaunay there is Delaunay on the sphere.
  [[nodiscard]] Vector2d chart(double u, double v) const override {
    return std::tan(0.5 * u) * Vector2d(std::cos(v), std::sin(v));
  }
};

/// X = r(u) D(u, v), r(u) = a (1 - b cos u + c cos 2u): the sphere (b = c = 0) and the pear.
class RadialSurface : public PolarSurface {
 public:
  RadialSurface(double a, double b, double c) : a_(a), b_(b), c_(c) {}

  [[nodiscard]] Derivatives derivatives(double u, double v) const override {
    const auto [r, r1, r2] = radius(u);
    const Derivatives s = unit_sphere(u, v);
    Derivatives d;
    d.x = r * s.x;
    d.xu = r1 * s.x + r * s.xu;
    d.xv = r * s.xv;
    d.xuu = r2 * s.x + 2.0 * r1 * s.xu + r * s.xuu;
    d.xuv = r1 * s.xv + r * s.xuv;
    d.xvv = r * s.xvv;
    return d;
  }

  /// Umbilic; the profile's curvature in polar form, (r^2 + 2 r'^2 - r r'') / (r^2 + r'^2)^1.5,
  /// with r' = 0 there.
  [[nodiscard]] SurfacePoint pole(bool north) const override {
    const auto [r, r1, r2] = radius(north ? 0.0 : kPi);
    (void)r1;
    const double k = (r - r2) / (r * r);
    const double side = north ? 1.0 : -1.0;
    return pole_point({0.0, 0.0, side * r}, {0.0, 0.0, side}, k, k);
  }

 private:
  /// r, r', r''.
  [[nodiscard]] std::array<double, 3> radius(double u) const {
    const double cu = std::cos(u), su = std::sin(u);
    const double c2u = std::cos(2.0 * u), s2u = std::sin(2.0 * u);
    return {a_ * (1.0 - b_ * cu + c_ * c2u), a_ * (b_ * su - 2.0 * c_ * s2u),
            a_ * (b_ * cu - 4.0 * c_ * c2u)};
  }

  double a_, b_, c_;
};

/// X = diag(a, b, c) D(u, v).
class Ellipsoid : public PolarSurface {
 public:
  Ellipsoid(double a, double b, double c) : axes_(a, b, c) {}

  [[nodiscard]] Derivatives derivatives(double u, double v) const override {
    Derivatives d = unit_sphere(u, v);
    for (Vector3d* w : {&d.x, &d.xu, &d.xv, &d.xuu, &d.xuv, &d.xvv}) *w = w->cwiseProduct(axes_);
    return d;
  }

  /// Near (0, 0, c) the surface is z = c (1 - x^2 / 2a^2 - y^2 / 2b^2): curvature c / a^2 along
  /// x and c / b^2 along y, at both poles.
  [[nodiscard]] SurfacePoint pole(bool north) const override {
    const double side = north ? 1.0 : -1.0;
    const double kx = axes_.z() / (axes_.x() * axes_.x());
    const double ky = axes_.z() / (axes_.y() * axes_.y());
    return pole_point({0.0, 0.0, side * axes_.z()}, {0.0, 0.0, side}, kx, ky);
  }

 private:
  Vector3d axes_;
};

class Torus : public PoleFreeSurface {
 public:
  Torus(double a, double b) : a_(a), b_(b) {}

  [[nodiscard]] ParameterDomain domain() const override {
    ParameterDomain d;
    d.u_max = d.v_max = 2.0 * kPi;
    d.periodic_u = d.periodic_v = true;
    return d;
  }

  [[nodiscard]] Derivatives derivatives(double u, double v) const override {
    const double su = std::sin(u), cu = std::cos(u), sv = std::sin(v), cv = std::cos(v);
    const double r = a_ + b_ * cv;
    Derivatives d;
    d.x = {r * cu, r * su, b_ * sv};
    d.xu = {-r * su, r * cu, 0.0};
    d.xv = {-b_ * sv * cu, -b_ * sv * su, b_ * cv};
    d.xuu = {-r * cu, -r * su, 0.0};
    d.xuv = {b_ * sv * su, -b_ * sv * cu, 0.0};
    d.xvv = {-b_ * cv * cu, -b_ * cv * su, -b_ * sv};
    return d;
  }

  /// (a u, a w(v)) with dw/dv = b / (a + b cos v): the metric becomes
  /// (a + b cos v)^2 (du^2 + dw^2), conformal.
  [[nodiscard]] Vector2d chart(double u, double v) const override {
    const double root = std::sqrt(a_ * a_ - b_ * b_);
    const double centred = std::remainder(v, 2.0 * kPi);  // in [-pi, pi]
    const double turns = std::round((v - centred) / (2.0 * kPi));
    const double w =
        2.0 * b_ / root * std::atan(std::sqrt((a_ - b_) / (a_ + b_)) * std::tan(0.5 * centred));
    return {a_ * u, a_ * (w + turns * period_w())};
  }

  [[nodiscard]] Vector2d chart_period() const override { return {2.0 * kPi * a_, a_ * period_w()}; }
  [[nodiscard]] double shortest_loop() const override { return 2.0 * kPi * std::min(b_, a_ - b_); }

 private:
  [[nodiscard]] double period_w() const { return 2.0 * kPi * b_ / std::sqrt(a_ * a_ - b_ * b_); }

  double a_, b_;
};

class Cylinder : public PoleFreeSurface {
 public:
  Cylinder(double a, double b) : a_(a), b_(b) {}

  [[nodiscard]] ParameterDomain domain() const override {
    ParameterDomain d;
    d.u_max = 2.0 * kPi;
    d.periodic_u = true;
    d.v_min = -0.5 * b_;
    d.v_max = 0.5 * b_;
    return d;
  }

  [[nodiscard]] Derivatives derivatives(double u, double v) const override {
    const double su = std::sin(u), cu = std::cos(u);
    Derivatives d;
    d.x = {a_ * cu, a_ * su, v};
    d.xu = {-a_ * su, a_ * cu, 0.0};
    d.xv = Vector3d::UnitZ();
    d.xuu = {-a_ * cu, -a_ * su, 0.0};
    d.xuv = d.xvv = Vector3d::Zero();
    return d;
  }

  /// Unrolled: isometric.
  [[nodiscard]] Vector2d chart(double u, double v) const override { return {a_ * u, v}; }
  [[nodiscard]] Vector2d chart_period() const override { return {2.0 * kPi * a_, 0.0}; }
  [[nodiscard]] double shortest_loop() const override { return 2.0 * kPi * a_; }

 private:
  double a_, b_;
};

/// z = f(x, y) over a square or a disc; the normal is on the +z side.
class GraphSurface : public PoleFreeSurface {
 public:
  [[nodiscard]] Derivatives derivatives(double u, double v) const override {
    const Eigen::Matrix<double, 6, 1> f = height(u, v);  // f, fu, fv, fuu, fuv, fvv
    Derivatives d;
    d.x = {u, v, f[0]};
    d.xu = {1.0, 0.0, f[1]};
    d.xv = {0.0, 1.0, f[2]};
    d.xuu = {0.0, 0.0, f[3]};
    d.xuv = {0.0, 0.0, f[4]};
    d.xvv = {0.0, 0.0, f[5]};
    return d;
  }
  [[nodiscard]] Vector2d chart(double u, double v) const override { return {u, v}; }

 protected:
  [[nodiscard]] virtual Eigen::Matrix<double, 6, 1> height(double u, double v) const = 0;
};

class Saddle : public GraphSurface {
 public:
  explicit Saddle(double a) : a_(a) {}
  [[nodiscard]] ParameterDomain domain() const override {
    ParameterDomain d;
    d.u_min = d.v_min = -a_;
    d.u_max = d.v_max = a_;
    return d;
  }

 protected:
  [[nodiscard]] Eigen::Matrix<double, 6, 1> height(double u, double v) const override {
    Eigen::Matrix<double, 6, 1> f;
    f << 0.5 * (u * u - v * v), u, -v, 1.0, 0.0, -1.0;
    return f;
  }

 private:
  double a_;
};

class MonkeySaddle : public GraphSurface {
 public:
  explicit MonkeySaddle(double a) : a_(a) {}
  [[nodiscard]] ParameterDomain domain() const override {
    ParameterDomain d;
    d.u_min = d.v_min = -a_;
    d.u_max = d.v_max = a_;
    d.disc = true;
    return d;
  }

 protected:
  [[nodiscard]] Eigen::Matrix<double, 6, 1> height(double u, double v) const override {
    Eigen::Matrix<double, 6, 1> f;
    f << 0.5 * (u * u * u - 3.0 * u * v * v), 1.5 * (u * u - v * v), -3.0 * u * v, 3.0 * u,
        -3.0 * v, -3.0 * u;
    return f;
  }

 private:
  double a_;
};

/// X = h(t) + b (cos u n(t) + sin u B(t)) with u the angle around the tube and v = t. With
/// s = |h'| = sqrt(a^2 + c^2), n = (-cos t, -sin t, 0) and B = (c sin t, -c cos t, a) / s, so
/// X = (alpha cos t + beta sin t, alpha sin t - beta cos t, c t + (a b / s) sin u) with
/// alpha = a - b cos u and beta = (b c / s) sin u.
class HelixTube : public PoleFreeSurface {
 public:
  HelixTube(double a, double b, double c) : a_(a), b_(b), c_(c), s_(std::hypot(a, c)) {}

  [[nodiscard]] ParameterDomain domain() const override {
    ParameterDomain d;
    d.u_max = 2.0 * kPi;
    d.periodic_u = true;
    d.v_max = 4.0 * kPi;
    return d;
  }

  [[nodiscard]] Derivatives derivatives(double u, double t) const override {
    const double su = std::sin(u), cu = std::cos(u), st = std::sin(t), ct = std::cos(t);
    const double g = a_ * b_ / s_;
    // alpha, beta and their u-derivatives.
    const double al = a_ - b_ * cu, al1 = b_ * su, al2 = b_ * cu;
    const double be = b_ * c_ / s_ * su, be1 = b_ * c_ / s_ * cu, be2 = -be;
    Derivatives d;
    d.x = {al * ct + be * st, al * st - be * ct, c_ * t + g * su};
    d.xu = {al1 * ct + be1 * st, al1 * st - be1 * ct, g * cu};
    d.xv = {-al * st + be * ct, al * ct + be * st, c_};
    d.xuu = {al2 * ct + be2 * st, al2 * st - be2 * ct, -g * su};
    d.xuv = {-al1 * st + be1 * ct, al1 * ct + be1 * st, 0.0};
    d.xvv = {-al * ct - be * st, -al * st + be * ct, 0.0};
    return d;
  }

  /// Tube circumference by arc length of the helix: isometric on the helix itself.
  [[nodiscard]] Vector2d chart(double u, double t) const override { return {b_ * u, s_ * t}; }
  [[nodiscard]] Vector2d chart_period() const override { return {2.0 * kPi * b_, 0.0}; }
  [[nodiscard]] double shortest_loop() const override { return 2.0 * kPi * b_; }

 private:
  double a_, b_, c_, s_;
};

// ---------------------------------------------------------------------------------------------
// Options: defaults and validation

/// The value, or `fallback` for 0; throws unless the result is finite (and positive if asked).
double parameter(double value, double fallback, const char* surface, const char* name,
                 bool positive) {
  const double x = value == 0.0 ? fallback : value;
  if (!std::isfinite(x) || (positive && !(x > 0.0))) {
    throw InvalidInput(std::string("surfaces: ") + surface + " parameter " + name + " = " +
                       std::to_string(x) +
                       (positive ? " must be finite and positive" : " must be finite"));
  }
  return x;
}

std::unique_ptr<Parametrisation> make_helix_tube(const SurfaceOptions& o) {
  const double a = parameter(o.a, 1.0, "helix-tube", "a", true);
  const double b = parameter(o.b, 0.25, "helix-tube", "b", true);
  const double c = parameter(o.c, 0.3, "helix-tube", "c", true);
  const double s = std::hypot(a, c);
  if (b * a >= s * s) {
    throw InvalidInput("surfaces: helix-tube radius b must be below (a^2 + c^2) / a = " +
                       std::to_string(s * s / a) + " (the tube would fold)");
  }
  if (b * s >= kPi * a * c) {
    throw InvalidInput("surfaces: helix-tube radius b must be below pi a c / sqrt(a^2 + c^2) = " +
                       std::to_string(kPi * a * c / s) + " (consecutive turns would touch)");
  }
  return std::make_unique<HelixTube>(a, b, c);
}

std::unique_ptr<Parametrisation> make_pear(const SurfaceOptions& o) {
  const double a = parameter(o.a, 1.0, "pear", "a", true);
  const double b = parameter(o.b, 0.3, "pear", "b", false);
  const double c = parameter(o.c, 0.3, "pear", "c", false);
  // r / a = (1 - c) - b x + 2 c x^2 with x = cos u in [-1, 1]: check the ends and the vertex.
  const auto r = [&](double x) { return 1.0 - c - b * x + 2.0 * c * x * x; };
  double r_min = std::min(r(-1.0), r(1.0));
  if (c != 0.0 && std::abs(b / (4.0 * c)) < 1.0) r_min = std::min(r_min, r(b / (4.0 * c)));
  if (!(r_min > 1e-3)) {
    throw InvalidInput("surfaces: pear radius 1 - b cos u + c cos 2u must stay positive; b = " +
                       std::to_string(b) + ", c = " + std::to_string(c) + " give " +
                       std::to_string(r_min));
  }
  return std::make_unique<RadialSurface>(a, b, c);
}

std::unique_ptr<Parametrisation> make_parametrisation(const SurfaceOptions& o) {
  switch (o.kind) {
    case SurfaceKind::sphere:
      return std::make_unique<RadialSurface>(parameter(o.a, 1.0, "sphere", "a", true), 0.0, 0.0);
    case SurfaceKind::ellipsoid:
      return std::make_unique<Ellipsoid>(parameter(o.a, 1.0, "ellipsoid", "a", true),
                                         parameter(o.b, 0.8, "ellipsoid", "b", true),
                                         parameter(o.c, 0.6, "ellipsoid", "c", true));
    case SurfaceKind::torus: {
      const double a = parameter(o.a, 1.0, "torus", "a", true);
      const double b = parameter(o.b, 0.4, "torus", "b", true);
      if (b >= a) {
        throw InvalidInput("surfaces: torus needs minor radius b < major radius a, got a = " +
                           std::to_string(a) + ", b = " + std::to_string(b));
      }
      return std::make_unique<Torus>(a, b);
    }
    case SurfaceKind::cylinder:
      return std::make_unique<Cylinder>(parameter(o.a, 1.0, "cylinder", "a", true),
                                        parameter(o.b, 2.0, "cylinder", "b", true));
    case SurfaceKind::saddle:
      return std::make_unique<Saddle>(parameter(o.a, 1.0, "saddle", "a", true));
    case SurfaceKind::monkey_saddle:
      return std::make_unique<MonkeySaddle>(parameter(o.a, 1.0, "monkey-saddle", "a", true));
    case SurfaceKind::helix_tube:
      return make_helix_tube(o);
    case SurfaceKind::pear:
      return make_pear(o);
  }
  throw InvalidInput("surfaces: unknown SurfaceKind " + std::to_string(static_cast<int>(o.kind)));
}

SurfacePoint evaluate(const Parametrisation& s, const ParameterDomain& d, const Vector2d& uv) {
  if (d.poles && uv.x() == d.u_min) return s.pole(true);
  if (d.poles && uv.x() == d.u_max) return s.pole(false);
  return point_from_derivatives(s.derivatives(uv.x(), uv.y()));
}

// ---------------------------------------------------------------------------------------------
// Triangulations

/// Vertices by parameters and outward (counter-clockwise) triangles.
struct Triangulated {
  std::vector<Vector2d> uv;
  std::vector<Face> faces;
};

/// Area and shape of a domain, by the midpoint rule on a fixed grid.
struct DomainStats {
  double area = 0.0;
  double max_area_element = 0.0;  ///< max |X_u x X_v| over the grid
  /// Area-weighted mean of log(|X_u| (u_max - u_min) / (|X_v| (v_max - v_min))): the ratio of
  /// u to v grid intervals that makes cells square in space.
  double log_aspect = 0.0;
  double max_curvature = 0.0;  ///< max(|k1|, |k2|) over the grid
};

bool in_domain(const ParameterDomain& d, const Vector2d& uv) {
  return !d.disc || uv.squaredNorm() <= d.u_max * d.u_max;
}

DomainStats domain_stats(const Parametrisation& s, const ParameterDomain& d) {
  constexpr int kSamples = 128;
  const double du = (d.u_max - d.u_min) / kSamples, dv = (d.v_max - d.v_min) / kSamples;
  DomainStats out;
  for (int i = 0; i < kSamples; ++i) {
    for (int j = 0; j < kSamples; ++j) {
      const Vector2d uv(d.u_min + (i + 0.5) * du, d.v_min + (j + 0.5) * dv);
      if (!in_domain(d, uv)) continue;
      const Derivatives x = s.derivatives(uv.x(), uv.y());
      const double element = x.xu.cross(x.xv).norm();
      out.area += element * du * dv;
      out.max_area_element = std::max(out.max_area_element, element);
      out.log_aspect +=
          element * du * dv *
          std::log(x.xu.norm() * (d.u_max - d.u_min) / (x.xv.norm() * (d.v_max - d.v_min)));
      const SurfacePoint p = point_from_derivatives(x);
      out.max_curvature = std::max({out.max_curvature, std::abs(p.k1), std::abs(p.k2)});
    }
  }
  out.log_aspect /= out.area;
  return out;
}

/// Fraction of the plane covered by random sequential adsorption at jamming (0.547) in terms
/// of the exclusion radius r: n = kPacking * area / r^2, tuned for the finite candidate pool.
constexpr double kPacking = 0.62;
/// Largest sample spacing times the largest |curvature|. Coarser meshes cannot follow the
/// surface: a face then spans so much of the normal's turning that it need not agree with the
/// exact normals at its corners. At this bound the worst face . corner normal measured over 30
/// seeds of every surface was 0.33 (torus) and 0.36 (helix tube), 0.5 or more elsewhere.
constexpr double kMaxSpacingCurvature = 0.8;
constexpr int kMaxTarget = 100'000'000;

/// target, raised where the surface is too curved for that few vertices (see above).
int effective_target(const DomainStats& stats, int target) {
  if (stats.max_curvature <= 0.0) return target;
  const double spacing = kMaxSpacingCurvature / stats.max_curvature;
  const double needed = std::ceil(kPacking * stats.area / (spacing * spacing));
  if (needed > kMaxTarget) {
    throw InvalidInput(
        "make_surface: the shape parameters need " + std::to_string(needed) +
        " vertices to be followed (spacing 0.8 / max |curvature|), above the limit " +
        std::to_string(kMaxTarget));
  }
  return std::max(target, static_cast<int>(needed));
}

int grid_vertex_count(const ParameterDomain& d, int nu, int nv) {
  const int columns = d.periodic_v ? nv : nv + 1;
  if (d.poles) return 2 + (nu - 1) * columns;
  return (d.periodic_u ? nu : nu + 1) * columns;
}

/// Intervals (nu, nv) closest to `target` vertices with cells close to square in space.
std::pair<int, int> grid_size(const ParameterDomain& d, int target, double log_aspect) {
  const int min_u = d.periodic_u ? 3 : (d.poles ? 2 : 1);
  const int min_v = d.periodic_v ? 3 : 1;
  const int max_u = 4 * static_cast<int>(std::sqrt(target * std::exp(std::abs(log_aspect)))) + 8;
  std::pair<int, int> best{min_u, min_v};
  double best_score = 1e300;
  for (int nu = min_u; nu <= max_u; ++nu) {
    const int guess = std::max(min_v, target / nu);
    for (int nv = std::max(min_v, guess - 2); nv <= guess + 2; ++nv) {
      const double count = grid_vertex_count(d, nu, nv);
      const double score = std::abs(std::log(count / target)) +
                           0.5 * std::abs(std::log(static_cast<double>(nu) / nv) - log_aspect);
      if (score < best_score) {
        best_score = score;
        best = {nu, nv};
      }
    }
  }
  return best;
}

void add_triangle(std::vector<Face>& faces, int a, int b, int c) {
  if (a != b && b != c && c != a) faces.push_back({a, b, c});
}

/// A (u, v) grid: rows of constant u, periodic directions wrapped, pole rows collapsed.
Triangulated regular_grid(const ParameterDomain& d, int target, double log_aspect) {
  // Plain ints, not a structured binding: the lambda below captures them, which clang before 16
  // rejects for bindings (the fuzz build uses clang 14).
  const std::pair<int, int> size = grid_size(d, target, log_aspect);
  const int nu = size.first, nv = size.second;
  const int columns = d.periodic_v ? nv : nv + 1;
  const int rows = d.periodic_u ? nu : nu + 1;
  const double du = (d.u_max - d.u_min) / nu, dv = (d.v_max - d.v_min) / nv;
  Triangulated t;
  const int last_row = d.poles ? nu - 1 : rows - 1;
  if (d.poles) t.uv.emplace_back(d.u_min, 0.0);
  for (int i = d.poles ? 1 : 0; i <= last_row; ++i) {
    for (int j = 0; j < columns; ++j) t.uv.emplace_back(d.u_min + i * du, d.v_min + j * dv);
  }
  if (d.poles) t.uv.emplace_back(d.u_max, 0.0);
  const int south = static_cast<int>(t.uv.size()) - 1;
  const auto index = [&](int i, int j) {
    const int jj = d.periodic_v ? j % nv : j;
    if (d.poles) return i == 0 ? 0 : (i == nu ? south : 1 + (i - 1) * columns + jj);
    return (d.periodic_u ? i % nu : i) * columns + jj;
  };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const int p00 = index(i, j), p10 = index(i + 1, j);
      const int p11 = index(i + 1, j + 1), p01 = index(i, j + 1);
      add_triangle(t.faces, p00, p10, p11);
      add_triangle(t.faces, p00, p11, p01);
    }
  }
  return t;
}

/// Concentric rings of 6k vertices, k = 0..m, stitched ring to ring in angular order: the
/// hexagonal triangulation of a disc bent onto its circle.
Triangulated regular_disc(double radius, int target) {
  const int m = std::max(
      1, static_cast<int>(std::lround((-3.0 + std::sqrt(9.0 + 12.0 * (target - 1))) / 6.0)));
  Triangulated t;
  t.uv.emplace_back(0.0, 0.0);
  for (int k = 1; k <= m; ++k) {
    for (int j = 0; j < 6 * k; ++j) {
      const double angle = 2.0 * kPi * j / (6 * k);
      t.uv.push_back(radius * k / m * Vector2d(std::cos(angle), std::sin(angle)));
    }
  }
  const auto start = [](int k) { return k == 0 ? 0 : 1 + 3 * k * (k - 1); };
  for (int k = 1; k <= m; ++k) {
    const int ni = std::max(1, 6 * (k - 1)), no = 6 * k;
    const auto inner = [&](int i) { return start(k - 1) + i % ni; };
    const auto outer = [&](int o) { return start(k) + o % no; };
    int i = 0, o = 0;
    while (i < ni || o < no) {
      // Advance on the ring whose next vertex comes first in angle; k = 1 is a fan.
      const bool step_outer = k == 1 || i == ni || (o < no && (o + 1) * ni <= (i + 1) * no);
      if (step_outer) {
        add_triangle(t.faces, inner(i), outer(o), outer(o + 1));
        ++o;
        if (k == 1 && o == no) i = ni;
      } else {
        add_triangle(t.faces, inner(i), outer(o), inner(i + 1));
        ++i;
      }
    }
  }
  return t;
}

// --- irregular ---

/// Point sets with a minimum distance r in space: a hash grid of cells of size 2r, so that the
/// ball of radius r around a point meets only 2 x 2 x 2 cells.
class PoissonGrid {
 public:
  PoissonGrid(double r, std::size_t expected_points) : r_(r) { cells_.reserve(expected_points); }

  [[nodiscard]] bool far_from_all(const Vector3d& x) const {
    const Vector3d scaled = x / (2.0 * r_);
    std::array<std::array<std::int64_t, 2>, 3> range{};
    for (int axis = 0; axis < 3; ++axis) {
      const double f = std::floor(scaled[axis]);
      const auto c = static_cast<std::int64_t>(f);
      range[axis] = {c, scaled[axis] - f < 0.5 ? c - 1 : c + 1};
    }
    for (const std::int64_t cx : range[0]) {
      for (const std::int64_t cy : range[1]) {
        for (const std::int64_t cz : range[2]) {
          const auto it = cells_.find(key(cx, cy, cz));
          if (it == cells_.end()) continue;
          for (const Vector3d& y : it->second) {
            if ((x - y).squaredNorm() < r_ * r_) return false;
          }
        }
      }
    }
    return true;
  }

  void add(const Vector3d& x) {
    const Vector3d scaled = x / (2.0 * r_);
    cells_[key(static_cast<std::int64_t>(std::floor(scaled.x())),
               static_cast<std::int64_t>(std::floor(scaled.y())),
               static_cast<std::int64_t>(std::floor(scaled.z())))]
        .push_back(x);
  }

 private:
  static std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    constexpr std::int64_t kOffset = std::int64_t{1} << 20;
    return (x + kOffset) | ((y + kOffset) << 21) | ((z + kOffset) << 42);
  }

  double r_;
  std::unordered_map<std::int64_t, std::vector<Vector3d>> cells_;
};

/// One boundary curve c(t), t in [0, 1), of an open surface in the parameter plane.
struct BoundaryPiece {
  std::function<Vector2d(double)> curve;
  int min_count;  ///< fewest points on it (3 on a closed loop, so that it stays a loop)
};

/// The boundary curves: the disc's circle, the square's four sides (one by one, so that every
/// corner is a vertex), the two end circles of a surface periodic in u.
std::vector<BoundaryPiece> boundary_pieces(const ParameterDomain& d) {
  const double u0 = d.u_min, u1 = d.u_max, v0 = d.v_min, v1 = d.v_max;
  if (d.poles || (d.periodic_u && d.periodic_v)) return {};
  if (d.disc) {
    return {{[=](double t) -> Vector2d {
               return u1 * Vector2d(std::cos(2.0 * kPi * t), std::sin(2.0 * kPi * t));
             },
             6}};
  }
  if (d.periodic_u) {
    return {{[=](double t) { return Vector2d(u0 + t * (u1 - u0), v0); }, 3},
            {[=](double t) { return Vector2d(u0 + t * (u1 - u0), v1); }, 3}};
  }
  return {{[=](double t) { return Vector2d(u0 + t * (u1 - u0), v0); }, 1},
          {[=](double t) { return Vector2d(u1, v0 + t * (v1 - v0)); }, 1},
          {[=](double t) { return Vector2d(u1 - t * (u1 - u0), v1); }, 1},
          {[=](double t) { return Vector2d(u0, v1 - t * (v1 - v0)); }, 1}};
}

/// Cumulative arc length in space of a piece at t = k / kFine, k = 0..kFine.
constexpr int kFine = 2048;
std::vector<double> arc_length(const Parametrisation& s, const BoundaryPiece& piece) {
  std::vector<double> length(kFine + 1, 0.0);
  Vector3d previous = s.derivatives(piece.curve(0.0).x(), piece.curve(0.0).y()).x;
  for (int k = 1; k <= kFine; ++k) {
    const Vector2d uv = piece.curve(static_cast<double>(k) / kFine);
    const Vector3d x = s.derivatives(uv.x(), uv.y()).x;
    length[k] = length[k - 1] + (x - previous).norm();
    previous = x;
  }
  return length;
}

double boundary_length(const Parametrisation& s, const ParameterDomain& d) {
  double total = 0.0;
  for (const BoundaryPiece& piece : boundary_pieces(d)) total += arc_length(s, piece).back();
  return total;
}

/// Points of a piece at equal arc length, spacing at most r; its end c(1) is left to the next
/// piece.
void sample_piece(const Parametrisation& s, const BoundaryPiece& piece, double r,
                  std::vector<Vector2d>& out) {
  const std::vector<double> length = arc_length(s, piece);
  const int count = std::max(piece.min_count, static_cast<int>(std::ceil(length.back() / r)));
  int k = 0;
  for (int j = 0; j < count; ++j) {
    const double target = length.back() * j / count;
    while (length[k + 1] < target) ++k;
    const double span = length[k + 1] - length[k];
    const double f = span > 0.0 ? (target - length[k]) / span : 0.0;
    out.push_back(piece.curve((k + f) / kFine));
  }
}

/// Poles, and evenly spaced points on the boundary curves of open surfaces.
std::vector<Vector2d> fixed_points(const Parametrisation& s, const ParameterDomain& d, double r) {
  std::vector<Vector2d> out;
  if (d.poles) {
    out.emplace_back(d.u_min, 0.0);
    out.emplace_back(d.u_max, 0.0);
  }
  for (const BoundaryPiece& piece : boundary_pieces(d)) sample_piece(s, piece, r, out);
  return out;
}

/// Candidates per target vertex: enough to come close to a maximal sampling (no hole that
/// could take another point), which bounds the Delaunay circumradii by about r.
constexpr int kCandidatesPerVertex = 30;
/// Vertices a boundary of length L adds at spacing r, beyond kPacking * area / r^2: about
/// kBoundaryExcess * L / r (measured on the saddle: 0.55 to 0.59 for 100 to 2000 vertices).
constexpr double kBoundaryExcess = 0.55;

/// Minimum distance between samples for about `target` of them, from
/// target = kPacking area / r^2 + kBoundaryExcess L / r. On periodic surfaces at least
/// kLoopSamples fit around the shortest loop: with fewer, the Delaunay triangulation of the
/// replicated chart can join a point to its own copy, and no triangulation follows the surface.
double sample_spacing(const Parametrisation& s, const ParameterDomain& d, const DomainStats& stats,
                      int target) {
  constexpr double kLoopSamples = 5.0;
  const double b = kBoundaryExcess * boundary_length(s, d);
  const double r = (b + std::sqrt(b * b + 4.0 * target * kPacking * stats.area)) / (2.0 * target);
  const double loop = s.shortest_loop();
  return loop > 0.0 ? std::min(r, loop / kLoopSamples) : r;
}

/// Fixed points, then random points of uniform density in area, each kept only when at least
/// r (in space) from all points kept so far.
std::vector<Vector2d> poisson_samples(const Parametrisation& s, const ParameterDomain& d,
                                      const DomainStats& stats, double r, int target,
                                      std::uint64_t seed) {
  std::vector<Vector2d> samples = fixed_points(s, d, r);
  const auto expected = static_cast<std::int64_t>(std::ceil(kPacking * stats.area / (r * r)));
  PoissonGrid grid(r, static_cast<std::size_t>(expected));
  for (const Vector2d& uv : samples) grid.add(evaluate(s, d, uv).position);
  std::mt19937_64 rng(seed);
  // The grid maximum misses peaks between samples by O(h^2); 10% covers that.
  const double bound = 1.1 * stats.max_area_element;
  // Scaled by the count r gives: more than target where sample_spacing had to shrink r.
  const std::int64_t candidates = kCandidatesPerVertex * std::max<std::int64_t>(target, expected);
  for (std::int64_t k = 0; k < candidates;) {
    const Vector2d uv(uniform(rng, d.u_min, d.u_max), uniform(rng, d.v_min, d.v_max));
    const double accept = uniform01(rng);
    if (!in_domain(d, uv)) continue;
    const Derivatives x = s.derivatives(uv.x(), uv.y());
    if (accept * bound >= x.xu.cross(x.xv).norm()) continue;
    ++k;
    if (!grid.far_from_all(x.x)) continue;
    grid.add(x.x);
    samples.push_back(uv);
  }
  return samples;
}

/// Closed genus 0: Delaunay of the stereographic chart without the south pole (index 1), whose
/// hull edges are closed by a fan around that pole.
std::vector<Face> triangulate_polar(const Parametrisation& s, const std::vector<Vector2d>& uv) {
  std::vector<Vector2d> chart;
  std::vector<int> original;
  for (int i = 0; i < static_cast<int>(uv.size()); ++i) {
    if (i == 1) continue;
    chart.push_back(s.chart(uv[i].x(), uv[i].y()));
    original.push_back(i);
  }
  const detail::PlanarDelaunay dt = detail::planar_delaunay(chart);
  std::vector<Face> faces;
  for (const auto& t : dt.triangles) {
    faces.push_back({original[t[0]], original[t[1]], original[t[2]]});
  }
  for (const auto& e : dt.hull_edges) faces.push_back({original[e[0]], original[e[1]], 1});
  return faces;
}

/// Periodic directions: copies shifted by whole periods within `band` of the fundamental
/// domain are triangulated with the originals; of the two copies of a triangle across a seam
/// only the one whose centroid lies in the fundamental domain is kept, on original indices.
std::vector<Face> triangulate_periodic(const Parametrisation& s, const std::vector<Vector2d>& uv,
                                       double band) {
  const Vector2d period = s.chart_period();
  std::vector<Vector2d> chart;
  std::vector<int> original;
  const auto copies = [&](double p) { return p > 0.0 ? static_cast<int>(std::ceil(band / p)) : 0; };
  const int cx = copies(period.x()), cy = copies(period.y());
  const auto near_domain = [&](double x, double p) {
    return p == 0.0 || (x >= -band && x < p + band);
  };
  for (int sx = -cx; sx <= cx; ++sx) {
    for (int sy = -cy; sy <= cy; ++sy) {
      for (int i = 0; i < static_cast<int>(uv.size()); ++i) {
        const Vector2d c =
            s.chart(uv[i].x(), uv[i].y()) + Vector2d(sx * period.x(), sy * period.y());
        if ((sx != 0 || sy != 0) &&
            !(near_domain(c.x(), period.x()) && near_domain(c.y(), period.y()))) {
          continue;
        }
        chart.push_back(c);
        original.push_back(i);
      }
    }
  }
  const detail::PlanarDelaunay dt = detail::planar_delaunay(chart);
  const auto inside = [](double x, double p) { return p == 0.0 || (x >= 0.0 && x < p); };
  std::vector<Face> faces;
  for (const auto& t : dt.triangles) {
    const Vector2d centroid = (chart[t[0]] + chart[t[1]] + chart[t[2]]) / 3.0;
    if (!inside(centroid.x(), period.x()) || !inside(centroid.y(), period.y())) continue;
    faces.push_back({original[t[0]], original[t[1]], original[t[2]]});
  }
  return faces;
}

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
         static_cast<std::uint32_t>(std::max(a, b));
}

/// Smallest interior angle of a triangle in space, in radians (0 when degenerate).
double min_angle(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const std::array<Vector3d, 3> p{a, b, c};
  double smallest = kPi;
  for (int i = 0; i < 3; ++i) {
    const Vector3d e1 = p[(i + 1) % 3] - p[i], e2 = p[(i + 2) % 3] - p[i];
    smallest = std::min(smallest, std::atan2(e1.cross(e2).norm(), e1.dot(e2)));
  }
  return smallest;
}

/// Lawson flips in space: an interior edge is flipped when that raises the smaller of the two
/// triangles' minimum angles without making the faces disagree with the exact normals: the
/// worst face-normal . corner-normal must stay above cos 30 degrees or not drop (on a coarse
/// mesh a flip that only improves angles can cave the surface in). The sorted angle list rises
/// strictly with each flip, so this terminates; the planar Delaunay start leaves little to do.
void flip_to_max_min_angle(const std::vector<Vector3d>& x, const std::vector<Vector3d>& n,
                           std::vector<Face>& faces) {
  std::unordered_map<std::uint64_t, std::array<int, 2>> edge_faces;
  edge_faces.reserve(2 * faces.size());
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    for (int i = 0; i < 3; ++i) {
      auto [it, added] = edge_faces.try_emplace(edge_key(faces[f][i], faces[f][(i + 1) % 3]),
                                                std::array<int, 2>{f, -1});
      if (!added) it->second[1] = f;
    }
  }
  const auto agreement = [&](int a, int b, int c) {
    const Vector3d normal = (x[b] - x[a]).cross(x[c] - x[a]).normalized();
    return std::min({normal.dot(n[a]), normal.dot(n[b]), normal.dot(n[c])});
  };
  constexpr double kGoodAgreement = 0.866;  // cos 30 degrees
  const auto replace = [&](int a, int b, int from, int to) {
    auto& pair = edge_faces.at(edge_key(a, b));
    (pair[0] == from ? pair[0] : pair[1]) = to;
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
      for (int i = 0; i < 3; ++i) {
        const int a = faces[f][i], b = faces[f][(i + 1) % 3], c = faces[f][(i + 2) % 3];
        const auto& pair = edge_faces.at(edge_key(a, b));
        const int g = pair[0] == f ? pair[1] : pair[0];
        if (g < 0) continue;
        const int d = faces[g][0] + faces[g][1] + faces[g][2] - a - b;
        if (d == c || edge_faces.contains(edge_key(c, d))) continue;
        const double before = std::min(min_angle(x[a], x[b], x[c]), min_angle(x[b], x[a], x[d]));
        const double after = std::min(min_angle(x[c], x[a], x[d]), min_angle(x[d], x[b], x[c]));
        if (after <= before + 1e-12) continue;
        const double agree_before = std::min(agreement(a, b, c), agreement(b, a, d));
        const double agree_after = std::min(agreement(c, a, d), agreement(d, b, c));
        if (agree_after < std::min(agree_before, kGoodAgreement)) continue;
        faces[f] = {c, a, d};
        faces[g] = {d, b, c};
        edge_faces.erase(edge_key(a, b));
        edge_faces.emplace(edge_key(c, d), std::array<int, 2>{f, g});
        replace(a, d, g, f);
        replace(b, c, f, g);
        changed = true;
      }
    }
  }
}

Triangulated irregular_triangulation(const Parametrisation& s, const ParameterDomain& d,
                                     const DomainStats& stats, int target, std::uint64_t seed) {
  Triangulated t;
  const double r = sample_spacing(s, d, stats, target);
  t.uv = poisson_samples(s, d, stats, r, target, seed);
  if (d.poles) {
    t.faces = triangulate_polar(s, t.uv);
  } else if (d.periodic_u || d.periodic_v) {
    t.faces = triangulate_periodic(s, t.uv, 6.0 * r);
  } else {
    std::vector<Vector2d> chart;
    for (const Vector2d& uv : t.uv) chart.push_back(s.chart(uv.x(), uv.y()));
    for (const auto& f : detail::planar_delaunay(chart).triangles) t.faces.push_back(f);
  }
  std::vector<Vector3d> x, n;
  for (const Vector2d& uv : t.uv) {
    const SurfacePoint p = evaluate(s, d, uv);
    x.push_back(p.position);
    n.push_back(p.normal);
  }
  flip_to_max_min_angle(x, n, t.faces);
  return t;
}

AnalyticSurface assemble(const Parametrisation& s, const ParameterDomain& d,
                         const Triangulated& t) {
  const auto nv = static_cast<Eigen::Index>(t.uv.size());
  const auto nf = static_cast<Eigen::Index>(t.faces.size());
  AnalyticSurface out;
  out.mesh.V.resize(nv, 3);
  out.mesh.N.resize(nv, 3);
  out.d1.resize(nv, 3);
  out.d2.resize(nv, 3);
  out.k1.resize(nv);
  out.k2.resize(nv);
  out.uv.resize(nv, 2);
  for (Eigen::Index i = 0; i < nv; ++i) {
    const SurfacePoint p = evaluate(s, d, t.uv[i]);
    out.mesh.V.row(i) = p.position.transpose();
    out.mesh.N.row(i) = p.normal.transpose();
    out.d1.row(i) = p.d1.transpose();
    out.d2.row(i) = p.d2.transpose();
    out.k1[i] = p.k1;
    out.k2[i] = p.k2;
    out.uv.row(i) = t.uv[i].transpose();
  }
  out.mesh.F.resize(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) out.mesh.F(f, c) = t.faces[f][c];
  }
  out.mesh.face_source = Eigen::VectorXi::LinSpaced(nf, 0, static_cast<int>(nf) - 1);
  return out;
}

constexpr std::array<std::pair<SurfaceKind, std::string_view>, 8> kNames{{
    {SurfaceKind::sphere, "sphere"},
    {SurfaceKind::ellipsoid, "ellipsoid"},
    {SurfaceKind::torus, "torus"},
    {SurfaceKind::cylinder, "cylinder"},
    {SurfaceKind::saddle, "saddle"},
    {SurfaceKind::monkey_saddle, "monkey-saddle"},
    {SurfaceKind::helix_tube, "helix-tube"},
    {SurfaceKind::pear, "pear"},
}};

void check_amplitude(double amplitude, const char* what) {
  if (!std::isfinite(amplitude) || amplitude < 0.0) {
    throw InvalidInput(std::string(what) + ": amplitude must be finite and >= 0, got " +
                       std::to_string(amplitude));
  }
}

}  // namespace

std::string_view surface_name(SurfaceKind kind) {
  for (const auto& [k, name] : kNames) {
    if (k == kind) return name;
  }
  throw InvalidInput("surface_name: unknown SurfaceKind " + std::to_string(static_cast<int>(kind)));
}

SurfaceKind surface_from_name(std::string_view name) {
  std::string known;
  for (const auto& [kind, n] : kNames) {
    if (n == name) return kind;
    known += (known.empty() ? "" : ", ") + std::string(n);
  }
  throw InvalidInput("unknown surface '" + std::string(name) + "'; known surfaces: " + known);
}

std::vector<SurfaceKind> all_surfaces() {
  std::vector<SurfaceKind> out;
  for (const auto& [kind, name] : kNames) out.push_back(kind);
  return out;
}

AnalyticSurface make_surface(const SurfaceOptions& options) {
  if (options.target_vertices < 16 || options.target_vertices > kMaxTarget) {
    throw InvalidInput("make_surface: target_vertices must be in [16, " +
                       std::to_string(kMaxTarget) + "], got " +
                       std::to_string(options.target_vertices));
  }
  const auto surface = make_parametrisation(options);
  const ParameterDomain d = surface->domain();
  const DomainStats stats = domain_stats(*surface, d);
  const int target = effective_target(stats, options.target_vertices);
  switch (options.triangulation) {
    case Triangulation::regular:
      return assemble(
          *surface, d,
          d.disc ? regular_disc(d.u_max, target) : regular_grid(d, target, stats.log_aspect));
    case Triangulation::irregular:
      return assemble(*surface, d,
                      irregular_triangulation(*surface, d, stats, target, options.seed));
  }
  throw InvalidInput("make_surface: unknown Triangulation " +
                     std::to_string(static_cast<int>(options.triangulation)));
}

ParameterDomain surface_domain(const SurfaceOptions& options) {
  return make_parametrisation(options)->domain();
}

SurfacePoint evaluate_surface(const SurfaceOptions& options, double u, double v) {
  const auto surface = make_parametrisation(options);
  const ParameterDomain d = surface->domain();
  if (!std::isfinite(u) || !std::isfinite(v)) {
    throw InvalidInput("evaluate_surface: parameters must be finite");
  }
  if (d.poles && (u < d.u_min || u > d.u_max)) {
    throw InvalidInput("evaluate_surface: u = " + std::to_string(u) + " outside [" +
                       std::to_string(d.u_min) + ", " + std::to_string(d.u_max) + "]");
  }
  return evaluate(*surface, d, {u, v});
}

void add_position_noise(Mesh& mesh, double amplitude, std::uint64_t seed) {
  check_amplitude(amplitude, "add_position_noise");
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, "add_position_noise");
  const double scale = amplitude * mean_edge_length(mesh.V, mesh.F);
  std::mt19937_64 rng(seed);
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int c = 0; c < 3; ++c) mesh.V(i, c) += scale * uniform(rng, -1.0, 1.0);
  }
}

void add_normal_noise(Mesh& mesh, double amplitude, std::uint64_t seed) {
  check_amplitude(amplitude, "add_normal_noise");
  if (!mesh.has_normals()) throw InvalidInput("add_normal_noise: the mesh has no normals");
  std::mt19937_64 rng(seed);
  for (Eigen::Index i = 0; i < mesh.N.rows(); ++i) {
    // n + u can only vanish for amplitude >= 1/sqrt(3); draw again then rather than divide by 0.
    Vector3d noisy;
    do {
      const Vector3d u(uniform(rng, -amplitude, amplitude), uniform(rng, -amplitude, amplitude),
                       uniform(rng, -amplitude, amplitude));
      noisy = mesh.N.row(i).transpose() + u;
    } while (noisy.squaredNorm() == 0.0);
    mesh.N.row(i) = noisy.normalized().transpose();
  }
}

}  // namespace focal
