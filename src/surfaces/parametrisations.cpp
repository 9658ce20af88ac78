// The analytic surfaces of surfaces.h: parametrisations and their closed-form truth.
#include <functional>

#include "focal/core/error.h"
#include "surfaces/surface_model.h"

namespace focal::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

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

}  // namespace

// The second fundamental form is taken against -N, II_ij = -X_ij . N, which makes curvature
// positive where the surface bends away from the outward normal (sphere: +1/r) and dN = +S dX.

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

namespace {

/// The truth at a pole with normal n = +-z and curvature kx along x, ky along y.
SurfacePoint pole_point(const Vector3d& x, const Vector3d& n, double kx, double ky) {
  // In the frame (x, n x x) = (x, +-y) the shape operator is diag(kx, ky).
  return principal_frame(x, n, Vector3d::UnitX(), n.cross(Vector3d::UnitX()), kx, 0.0, ky);
}

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

}  // namespace

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

}  // namespace focal::detail
