#include "focal/curvature/two_slit_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace focal {
namespace {

struct Shape {
  double k1, k2, phi;  // W = k1 d1 d1^T + k2 d2 d2^T with d1 = (cos phi, sin phi)
  [[nodiscard]] Eigen::Matrix2d matrix() const {
    const Eigen::Vector2d d1(std::cos(phi), std::sin(phi)), d2(-d1.y(), d1.x());
    return k1 * d1 * d1.transpose() + k2 * d2 * d2.transpose();
  }
};

/// Rays of a valence-n fan around the vertex, g = W x + noise.
std::vector<NormalRay> rays_of(const Shape& s, int n, double noise, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  std::vector<NormalRay> rays;
  const Eigen::Matrix2d w = s.matrix();
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * (i + 0.3 * jitter(rng)) / n;
    const Eigen::Vector2d x = (1.0 + 0.3 * jitter(rng)) * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Eigen::Vector2d g = w * x + noise * Eigen::Vector2d(jitter(rng), jitter(rng));
    rays.push_back({g.x(), g.y(), x.x(), x.y()});
  }
  return rays;
}

Shape random_shape(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> k(-3.0, 3.0), angle(0.0, std::numbers::pi);
  double k1 = k(rng), k2 = k(rng);
  if (k1 < k2) std::swap(k1, k2);
  return {k1, k2, angle(rng)};
}

/// |sin| of the angle between two lines (directions modulo sign).
double line_angle_sine(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::abs(a.x() * b.y() - a.y() * b.x());
}

TEST(TwoSlitFit, ClosedFormRecoversNoiselessShapeExactly) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 500; ++trial) {
    const Shape s = random_shape(rng);
    const auto rays = rays_of(s, 6, 0.0, rng);
    const SlitFit fit = fit_two_slits_closed_form(rays);
    ASSERT_TRUE(fit.valid);
    EXPECT_NEAR(fit.k1, s.k1, 1e-12);
    EXPECT_NEAR(fit.k2, s.k2, 1e-12);
    EXPECT_NEAR(fit.energy, 0.0, 1e-24);
    if (s.k1 - s.k2 > 1e-3) {  // directions are defined only away from umbilics
      EXPECT_LT(line_angle_sine(fit.d1, {std::cos(s.phi), std::sin(s.phi)}), 1e-9);
    }
    EXPECT_NEAR(fit.d1.norm(), 1.0, 1e-15);
    EXPECT_NEAR(fit.d1.dot(fit.d2), 0.0, 1e-15);
    EXPECT_NEAR(fit.d1.x() * fit.d2.y() - fit.d1.y() * fit.d2.x(), 1.0, 1e-15);  // d2 = rot90(d1)
  }
}

// DESIGN.md: E(t, k1, k2) of eq. 11/14 equals sum |W x - g|^2 with d1 = (-sin t, cos t).
TEST(TwoSlitFit, ClosedFormEnergyIsThePapersObjective) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const auto rays = rays_of(random_shape(rng), 7, 0.5, rng);
    const SlitFit fit = fit_two_slits_closed_form(rays);
    ASSERT_TRUE(fit.valid);
    const double t = std::atan2(-fit.d1.x(), fit.d1.y());
    EXPECT_NEAR(two_slit_energy(rays, {}, t, fit.k1, fit.k2), fit.energy,
                1e-12 * (1.0 + fit.energy));
  }
}

// The closed form is the global minimum: no angle on a dense grid, with the best k1, k2 for that
// angle (E is quadratic in them at fixed t), does better.
TEST(TwoSlitFit, ClosedFormBeatsADenseSearchOverTheAngle) {
  std::mt19937_64 rng(17);
  for (int trial = 0; trial < 50; ++trial) {
    const auto rays = rays_of(random_shape(rng), 6, 1.0, rng);
    const SlitFit fit = fit_two_slits_closed_form(rays);
    ASSERT_TRUE(fit.valid);
    for (int i = 0; i < 3600; ++i) {
      const double t = std::numbers::pi * i / 3600;
      const double s = std::sin(t), c = std::cos(t);
      double aa = 0, ab = 0, cc = 0, ce = 0;
      for (const auto& r : rays) {
        const double a = r.u * s - r.v * c, b = r.sigma * s - r.tau * c;
        const double cu = r.u * c + r.v * s, e = r.sigma * c + r.tau * s;
        aa += a * a, ab += a * b, cc += cu * cu, ce += cu * e;
      }
      EXPECT_LE(fit.energy, two_slit_energy(rays, {}, t, ab / aa, ce / cc) * (1 + 1e-12));
    }
  }
}

TEST(TwoSlitFit, ClosedFormNeverWorseThanLevenbergMarquardt) {
  std::mt19937_64 rng(23);
  for (int trial = 0; trial < 1000; ++trial) {
    const auto rays = rays_of(random_shape(rng), 5 + trial % 6, 2.0, rng);
    const SlitFit cf = fit_two_slits_closed_form(rays);
    const SlitFit lm = fit_two_slits_levenberg_marquardt(rays);
    ASSERT_TRUE(cf.valid);
    ASSERT_TRUE(lm.valid);
    EXPECT_LE(cf.energy, lm.energy * (1 + 1e-12) + 1e-300);
    EXPECT_GE(lm.k1, lm.k2);
  }
}

TEST(TwoSlitFit, LevenbergMarquardtReproducesClosedFormOnNoiselessRays) {
  std::mt19937_64 rng(29);
  for (int trial = 0; trial < 500; ++trial) {
    const Shape s = random_shape(rng);
    const auto rays = rays_of(s, 6, 0.0, rng);
    const SlitFit cf = fit_two_slits_closed_form(rays);
    const SlitFit lm = fit_two_slits_levenberg_marquardt(rays);
    ASSERT_TRUE(lm.valid);
    EXPECT_NEAR(lm.k1, cf.k1, 1e-9 * (1 + std::abs(cf.k1)));
    EXPECT_NEAR(lm.k2, cf.k2, 1e-9 * (1 + std::abs(cf.k2)));
    EXPECT_NEAR(lm.energy, cf.energy, 1e-9);
    if (s.k1 - s.k2 > 1e-3) {
      EXPECT_LT(line_angle_sine(lm.d1, cf.d1), 1e-6);
    }
  }
}

TEST(TwoSlitFit, WeightsActLikeRepeatedRays) {
  std::mt19937_64 rng(31);
  const auto rays = rays_of(random_shape(rng), 6, 0.4, rng);
  std::vector<double> weights = {1, 2, 1, 3, 0, 1};
  std::vector<NormalRay> repeated;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    for (int k = 0; k < static_cast<int>(weights[i]); ++k) repeated.push_back(rays[i]);
  }
  const SlitFit a = fit_two_slits_closed_form(rays, weights);
  const SlitFit b = fit_two_slits_closed_form(repeated);
  EXPECT_NEAR(a.k1, b.k1, 1e-12);
  EXPECT_NEAR(a.k2, b.k2, 1e-12);
  EXPECT_NEAR(a.energy, b.energy, 1e-12);
  const SlitFit c = fit_two_slits_levenberg_marquardt(rays, weights);
  EXPECT_NEAR(c.energy, b.energy, 1e-9);
}

TEST(TwoSlitFit, UnderDeterminedFitsAreInvalidWithNaN) {
  const std::vector<NormalRay> none;
  const std::vector<NormalRay> one = {{0.1, 0.2, 1.0, 0.0}};
  const std::vector<NormalRay> collinear = {
      {0.1, 0.0, 1.0, 0.0}, {-0.1, 0.0, -1.0, 0.0}, {0.2, 0.0, 2.0, 0.0}};
  const std::vector<NormalRay> zero_weight = {{0.1, 0.0, 1.0, 0.0}, {0.0, 0.1, 0.0, 1.0}};
  for (const auto* rays : {&none, &one, &collinear}) {
    for (const SlitFit& fit :
         {fit_two_slits_closed_form(*rays), fit_two_slits_levenberg_marquardt(*rays)}) {
      EXPECT_FALSE(fit.valid);
      EXPECT_TRUE(std::isnan(fit.k1));
      EXPECT_TRUE(std::isnan(fit.k2));
      EXPECT_TRUE(std::isnan(fit.d1.x()));
    }
  }
  const std::vector<double> w = {1.0, 0.0};
  EXPECT_FALSE(fit_two_slits_closed_form(zero_weight, w).valid);
  EXPECT_TRUE(fit_two_slits_closed_form(zero_weight).valid);  // two independent rays suffice
}

}  // namespace
}  // namespace focal
