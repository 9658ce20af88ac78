// The per-point formulas every estimator shares (src/kernels/local_shape.h): the tangent frame,
// the normal ray, the principal axes of a symmetric 2x2 operator and the classes, checked
// against exact values, and the lane types (src/core/simd_lanes.h) checked to run the very same
// formula as double, bit for bit, on every instruction set this CPU has.

#include "kernels/local_shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/simd_lanes.h"
#include "focal/core/point_class.h"
#include "focal/curvature/curvature.h"
#include "kernels/vec3.h"

namespace focal {
namespace {

using kernels::Quotient;
using kernels::Vec3;
using V3 = Vec3<double>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

double length(const V3& a) { return std::sqrt(kernels::dot(a, a)); }

TEST(LocalShape, FrameIsOrthonormalAndRightHanded) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  std::vector<V3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}, {1, 0, -0.0}};
  for (int k = 0; k < 1000; ++k) normals.push_back({g(rng), g(rng), g(rng)});
  for (V3 n : normals) {
    n = (1.0 / length(n)) * n;
    const kernels::Frame<double> f = kernels::frame_of(n);
    EXPECT_NEAR(length(f.x), 1.0, 1e-15);
    EXPECT_NEAR(length(f.y), 1.0, 1e-15);
    EXPECT_NEAR(kernels::dot(f.x, f.y), 0.0, 1e-15);
    EXPECT_NEAR(kernels::dot(f.x, n), 0.0, 1e-15);
    EXPECT_NEAR(kernels::dot(f.y, n), 0.0, 1e-15);
    const V3 z = kernels::cross(f.x, f.y);  // right-handed: x cross y = n
    EXPECT_NEAR(z.x, n.x, 1e-15);
    EXPECT_NEAR(z.y, n.y, 1e-15);
    EXPECT_NEAR(z.z, n.z, 1e-15);
  }
  // The poles: x, y are the coordinate axes (turned for the south pole).
  const kernels::Frame<double> up = kernels::frame_of(V3{0, 0, 1});
  EXPECT_EQ(up.x.x, 1.0);
  EXPECT_EQ(up.y.y, 1.0);
  const kernels::Frame<double> down = kernels::frame_of(V3{0, 0, -1});
  EXPECT_EQ(down.x.x, 1.0);
  EXPECT_EQ(down.y.y, -1.0);
}

TEST(LocalShape, NormalRayOfPaperEquation3) {
  const kernels::Frame<double> f = kernels::frame_of(V3{0, 0, 1});
  kernels::NormalRay<double> ray;
  // Neighbour at (1, 2, 0.5) with normal (0.6, 0, 0.8): sigma = 0.75, tau = 0, and the ray
  // crosses z = 0 at (1 - 0.5 * 0.75, 2).
  const V3 m{0.6, 0.0, 0.8};
  ASSERT_TRUE(kernels::normal_ray<Quotient::exact>(f, V3{1, 2, 0.5}, m, m, ray));
  EXPECT_DOUBLE_EQ(ray.sigma, 0.75);
  EXPECT_EQ(ray.tau, 0.0);
  EXPECT_DOUBLE_EQ(ray.u, 1.0 - 0.5 * 0.75);
  EXPECT_DOUBLE_EQ(ray.v, 2.0);
  // By one reciprocal: within an ulp of the exact quotient.
  kernels::NormalRay<double> by_reciprocal;
  ASSERT_TRUE(kernels::normal_ray<Quotient::reciprocal>(f, V3{1, 2, 0.5}, m, m, by_reciprocal));
  EXPECT_NEAR(by_reciprocal.sigma, ray.sigma, 2e-16);
  // A slope vector with the same tangential part gives the same ray (the CUDA fit's M - N).
  kernels::NormalRay<double> from_difference;
  ASSERT_TRUE(kernels::normal_ray<Quotient::exact>(f, V3{1, 2, 0.5}, m, m - f.n, from_difference));
  EXPECT_EQ(from_difference.sigma, ray.sigma);
  // No ray: normal on or below the tangent plane, NaN normal, infinite position.
  EXPECT_FALSE(kernels::normal_ray<Quotient::exact>(f, V3{1, 0, 0}, V3{1, 0, 0}, V3{1, 0, 0}, ray));
  EXPECT_FALSE(kernels::normal_ray<Quotient::exact>(f, V3{1, 0, 0}, V3{0, 0.6, -0.8},
                                                    V3{0, 0.6, -0.8}, ray));
  EXPECT_FALSE(
      kernels::normal_ray<Quotient::exact>(f, V3{1, 0, 0}, V3{0, 0, kNaN}, V3{0, 0, kNaN}, ray));
  EXPECT_FALSE(
      kernels::normal_ray<Quotient::exact>(f, V3{kInf, 0, 0}, V3{0, 0, 1}, V3{0, 0, 1}, ray));
}

template <class T>
void expect_principal(T a, T b, T c, T tolerance) {
  const kernels::Principal<T> p =
      kernels::principal_axes<Quotient::exact, Quotient::exact>(a, b, c);
  EXPECT_GE(p.k1, p.k2);
  EXPECT_NEAR(p.d1x * p.d1x + p.d1y * p.d1y, T(1), tolerance);
  // angle in (-pi/2, pi/2]
  EXPECT_TRUE(p.d1x > T(0) || (p.d1x == T(0) && p.d1y == T(1))) << a << " " << b << " " << c;
  // W d1 = k1 d1, and d2 = (-d1y, d1x) belongs to k2.
  const T scale = std::abs(a) + std::abs(b) + std::abs(c);
  EXPECT_NEAR(a * p.d1x + b * p.d1y, p.k1 * p.d1x, tolerance * scale);
  EXPECT_NEAR(b * p.d1x + c * p.d1y, p.k1 * p.d1y, tolerance * scale);
  EXPECT_NEAR(a * -p.d1y + b * p.d1x, p.k2 * -p.d1y, tolerance * scale);
  EXPECT_NEAR(p.k1 + p.k2, a + c, tolerance * scale);
}

/// principal_axes(a, b, c), each rounding, against exact values.
void expect_axes(double a, double b, double c, double k1, double k2, double d1x, double d1y,
                 bool isotropic) {
  for (const kernels::Principal<double>& p :
       {kernels::principal_axes<Quotient::exact, Quotient::exact>(a, b, c),
        kernels::principal_axes<Quotient::reciprocal, Quotient::exact>(a, b, c),
        kernels::principal_axes<Quotient::reciprocal, Quotient::reciprocal>(a, b, c)}) {
    EXPECT_DOUBLE_EQ(p.k1, k1);
    EXPECT_DOUBLE_EQ(p.k2, k2);
    EXPECT_DOUBLE_EQ(p.d1x, d1x);
    EXPECT_DOUBLE_EQ(p.d1y, d1y);
    EXPECT_EQ(p.isotropic, isotropic);
  }
}

TEST(LocalShape, PrincipalAxesOfSymmetricOperators) {
  expect_axes(3.0, 1.0, 3.0, 4.0, 2.0, std::sqrt(0.5), std::sqrt(0.5), false);
  expect_axes(3.0, -1.0, 3.0, 4.0, 2.0, std::sqrt(0.5), -std::sqrt(0.5), false);
  expect_axes(1.0, 0.0, 2.0, 2.0, 1.0, 0.0, 1.0, false);
  expect_axes(-1.0, 0.0, -2.0, -1.0, -2.0, 1.0, 0.0, false);
  expect_axes(2.0, 0.0, 2.0, 2.0, 2.0, 1.0, 0.0, true);  // isotropic: any direction, d1 = (1, 0)
  expect_axes(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, true);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> e(-30, 30);
  for (int k = 0; k < 2000; ++k) {
    const double m = std::ldexp(1.0, e(rng));  // scale-free: tiny and huge operators alike
    const double a = m * u(rng), b = m * u(rng), c = m * u(rng);
    expect_principal<double>(a, b, c, 1e-14);
    expect_principal<float>(static_cast<float>(a), static_cast<float>(b), static_cast<float>(c),
                            1e-6f);
  }
}

TEST(LocalShape, ClassifyTable) {
  const auto code = [](double k1, double k2) {
    return static_cast<PointClass>(kernels::classify(k1, k2, 0.1, 0.01));
  };
  EXPECT_EQ(code(2.0, 1.0), PointClass::elliptic);
  EXPECT_EQ(code(-1.0, -2.0), PointClass::elliptic);
  EXPECT_EQ(code(1.0, -1.0), PointClass::hyperbolic);
  EXPECT_EQ(code(1.0, 0.05), PointClass::parabolic);
  EXPECT_EQ(code(0.05, -1.0), PointClass::parabolic);
  EXPECT_EQ(code(0.05, -0.05), PointClass::flat);
  EXPECT_EQ(code(1.0, 0.995), PointClass::umbilic);
  EXPECT_EQ(code(-0.995, -1.0), PointClass::umbilic);
  EXPECT_EQ(code(kNaN, 1.0), PointClass::undefined);
  EXPECT_EQ(code(kInf, 1.0), PointClass::undefined);
  EXPECT_EQ(code(1.0, -kInf), PointClass::undefined);
  // focal::classify is this formula; float gives the same classes.
  for (double k1 : {2.0, 1.0, 0.05, -0.05, -1.0, kNaN}) {
    for (double k2 : {1.0, 0.995, 0.05, -0.05, -1.0, -2.0, kInf}) {
      EXPECT_EQ(classify(k1, k2, 0.1, 0.01), code(k1, k2));
      EXPECT_EQ(static_cast<PointClass>(
                    kernels::classify(static_cast<float>(k1), static_cast<float>(k2), 0.1f, 0.01f)),
                code(k1, k2));
    }
  }
}

// ---- Lanes: the same formula, the same bits, as double.

/// Same bits, or NaN on both sides (the sign of a NaN is the compiler's to choose).
bool same(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
}

/// Inputs: signed zeros, subnormals, huge, infinite and NaN values, isotropic operators (a = c,
/// b = 0), and random ones.
std::vector<double> awkward_values(int count) {
  std::vector<double> v = {0.0,    -0.0, 1.0,   -1.0, 0.5, 4.9e-324, -1e-300, 1e300,
                           -1e300, kInf, -kInf, kNaN, 2.0, 3.0,      1e-8,    -7.25};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> e(-20, 20);
  while (static_cast<int>(v.size()) < count) v.push_back(std::ldexp(u(rng), e(rng)));
  return v;
}

struct LaneMismatches {
  int frame = 0, ray = 0, principal = 0, classes = 0;
  int rays = 0;  ///< rays that exist (of the lanes compared)
};

/// The ray's inputs from (a, b, c): the unit normal n of (a, b, c) (raw where it has none), a
/// neighbour normal m near it (in n's hemisphere or not) and the offset (c, a, b).
void ray_inputs(double a, double b, double c, double n[3], double m[3], double o[3]) {
  const double length = std::sqrt(a * a + b * b + c * c);
  const double s = std::isfinite(length) && length > 0.0 ? 1.0 / length : 1.0;
  n[0] = a * s, n[1] = b * s, n[2] = c * s;
  const auto bounded = [](double x) { return x / (1.0 + std::abs(x)); };
  m[0] = n[0] + 0.7 * bounded(b), m[1] = n[1] + 0.7 * bounded(c), m[2] = n[2] + 0.7 * bounded(a);
  o[0] = c, o[1] = a, o[2] = b;
}

template <class L>
[[gnu::always_inline]] inline void check_lanes(const double* a, const double* b, const double* c,
                                               LaneMismatches& bad) {
  constexpr int W = detail::lane_count<L>;
  const L la = detail::load_lanes<L>(a), lb = detail::load_lanes<L>(b),
          lc = detail::load_lanes<L>(c);
  const kernels::Frame<L> fl = kernels::frame_of(Vec3<L>{la, lb, lc});
  const kernels::Principal<L> pl =
      kernels::principal_axes<Quotient::reciprocal, Quotient::reciprocal>(la, lb, lc);
  const auto classes = kernels::classify(la, lb, 0.25, 0.01);
  double n[3][W], m[3][W], o[3][W];
  for (int l = 0; l < W; ++l) {
    double nl[3], ml[3], ol[3];
    ray_inputs(a[l], b[l], c[l], nl, ml, ol);
    for (int k = 0; k < 3; ++k) n[k][l] = nl[k], m[k][l] = ml[k], o[k][l] = ol[k];
  }
  const auto lanes3 = [](const double(*x)[W]) FOCAL_LANE_LAMBDA {
    return Vec3<L>{detail::load_lanes<L>(x[0]), detail::load_lanes<L>(x[1]),
                   detail::load_lanes<L>(x[2])};
  };
  const kernels::Frame<L> rf = kernels::frame_of(lanes3(n));
  kernels::NormalRay<L> rl;
  const auto made =
      kernels::normal_ray<Quotient::reciprocal>(rf, lanes3(o), lanes3(m), lanes3(m), rl);
  for (int l = 0; l < W; ++l) {
    const kernels::Frame<double> f = kernels::frame_of(V3{a[l], b[l], c[l]});
    bad.frame += !(same(f.x.x, fl.x.x[l]) && same(f.x.y, fl.x.y[l]) && same(f.x.z, fl.x.z[l]) &&
                   same(f.y.x, fl.y.x[l]) && same(f.y.y, fl.y.y[l]) && same(f.y.z, fl.y.z[l]));
    const kernels::Principal<double> p =
        kernels::principal_axes<Quotient::reciprocal, Quotient::reciprocal>(a[l], b[l], c[l]);
    bad.principal += !(same(p.k1, pl.k1[l]) && same(p.k2, pl.k2[l]) && same(p.d1x, pl.d1x[l]) &&
                       same(p.d1y, pl.d1y[l]) && p.isotropic == (pl.isotropic[l] != 0));
    const V3 nl{n[0][l], n[1][l], n[2][l]}, ml{m[0][l], m[1][l], m[2][l]},
        ol{o[0][l], o[1][l], o[2][l]};
    kernels::NormalRay<double> r;
    const bool ok = kernels::normal_ray<Quotient::reciprocal>(kernels::frame_of(nl), ol, ml, ml, r);
    bad.rays += ok;
    bad.ray += ok != (made[l] != 0) || !(same(r.sigma, rl.sigma[l]) && same(r.tau, rl.tau[l]) &&
                                         same(r.u, rl.u[l]) && same(r.v, rl.v[l]));
    bad.classes += kernels::classify(a[l], b[l], 0.25, 0.01) != classes[l];
  }
}

template <class L>
[[gnu::always_inline]] inline LaneMismatches check_all(const std::vector<double>& v) {
  LaneMismatches bad;
  constexpr int W = detail::lane_count<L>;
  const auto n = static_cast<int>(v.size());
  // Triples (a, b, c) from three strides through the values: every pair of awkward values meets.
  std::vector<double> a(W), b(W), c(W);
  for (int i = 0; i + W <= n * 7; i += W) {
    for (int l = 0; l < W; ++l) {
      const int k = i + l;
      a[l] = v[k % n], b[l] = v[(k / n + k) % n], c[l] = k % 5 == 0 ? a[l] : v[(k * 7 + 3) % n];
      if (k % 11 == 0) b[l] = k % 2 ? 0.0 : -0.0;  // isotropic where a = c
    }
    check_lanes<L>(a.data(), b.data(), c.data(), bad);
  }
  return bad;
}

FOCAL_TARGET_AVX512 LaneMismatches check_avx512(const std::vector<double>& v) {
  return check_all<detail::Lanes8>(v);
}
FOCAL_TARGET_AVX2 LaneMismatches check_avx2(const std::vector<double>& v) {
  return check_all<detail::Lanes4>(v);
}
LaneMismatches check_baseline(const std::vector<double>& v) { return check_all<detail::Lanes2>(v); }

TEST(LocalShape, LanesRunTheScalarFormulaBitForBit) {
  const std::vector<double> v = awkward_values(400);
  for (detail::SimdIsa isa :
       {detail::SimdIsa::baseline, detail::SimdIsa::avx2, detail::SimdIsa::avx512}) {
    if (!detail::simd_isa_available(isa)) continue;
    const LaneMismatches bad = detail::kernel_for(isa, check_avx512, check_avx2, check_baseline)(v);
    EXPECT_EQ(bad.frame, 0) << "isa " << static_cast<int>(isa);
    EXPECT_EQ(bad.ray, 0) << "isa " << static_cast<int>(isa);
    EXPECT_EQ(bad.principal, 0) << "isa " << static_cast<int>(isa);
    EXPECT_EQ(bad.classes, 0) << "isa " << static_cast<int>(isa);
    EXPECT_GT(bad.rays, 1000);  // most normals m lie in n's hemisphere
  }
}

}  // namespace
}  // namespace focal
