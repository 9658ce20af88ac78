#include "focal/curvature/normal_rays.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace focal {
namespace {

Eigen::Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::Vector3d v(g(rng), g(rng), g(rng));
  return v.normalized();
}

TEST(TangentFrame, OrthonormalAndRightHandedEverywhere) {
  std::mt19937_64 rng(7);
  std::vector<Eigen::Vector3d> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, 1e-17, -1}};
  for (int i = 0; i < 1000; ++i) normals.push_back(random_unit(rng));
  for (const auto& n : normals) {
    const TangentFrame f = tangent_frame(n);
    EXPECT_NEAR(f.x.norm(), 1.0, 1e-14);
    EXPECT_NEAR(f.y.norm(), 1.0, 1e-14);
    EXPECT_NEAR(f.x.dot(f.y), 0.0, 1e-14);
    EXPECT_NEAR(f.x.dot(n), 0.0, 1e-14);
    EXPECT_LT((f.x.cross(f.y) - n).norm(), 1e-14);
  }
}

// On a sphere of radius r every normal ray passes through the centre, i.e. through (0, 0, -r)
// in the frame of any vertex: sigma = u / r and tau = v / r exactly (paper Fig. 2a, umbilic).
TEST(NormalRay, SphereRaysMeetAtTheCentre) {
  std::mt19937_64 rng(3);
  const double r = 2.5;
  const Eigen::Vector3d centre(0.3, -1.0, 4.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d n = random_unit(rng);
    const Eigen::Vector3d m = (n + 0.3 * random_unit(rng)).normalized();
    if (m.dot(n) <= 0.1) continue;
    const TangentFrame f = tangent_frame(n);
    const auto ray = normal_ray(f, centre + r * n, centre + r * m, m);
    ASSERT_TRUE(ray.has_value());
    EXPECT_NEAR(ray->sigma, ray->u / r, 1e-13);
    EXPECT_NEAR(ray->tau, ray->v / r, 1e-13);
  }
}

// Paper eq. 3 on a Monge patch z(x, y) with normal (-z_x, -z_y, 1) / |.|:
// [sigma, tau] = [-z_x, -z_y] and [u, v] = [x + z z_x, y + z z_y].
TEST(NormalRay, MongePatchMatchesPaperEquation3) {
  const TangentFrame f = tangent_frame(Eigen::Vector3d::UnitZ());
  ASSERT_LT((f.x - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  const double x = 0.2, y = -0.1;
  const double z = 0.7 * x * x - 0.4 * x * y + 0.1 * y * y;
  const double zx = 1.4 * x - 0.4 * y, zy = -0.4 * x + 0.2 * y;
  const Eigen::Vector3d m = Eigen::Vector3d(-zx, -zy, 1.0).normalized();
  const auto ray = normal_ray(f, Eigen::Vector3d::Zero(), {x, y, z}, m);
  ASSERT_TRUE(ray.has_value());
  EXPECT_NEAR(ray->sigma, -zx, 1e-15);
  EXPECT_NEAR(ray->tau, -zy, 1e-15);
  EXPECT_NEAR(ray->u, x + z * zx, 1e-15);
  EXPECT_NEAR(ray->v, y + z * zy, 1e-15);
}

TEST(NormalRay, VertexOwnRayIsZero) {
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 3).normalized();
  const auto ray = normal_ray(tangent_frame(n), {1, 1, 1}, {1, 1, 1}, n);
  ASSERT_TRUE(ray.has_value());
  EXPECT_NEAR(ray->sigma, 0.0, 1e-15);  // x.n and y.n vanish up to rounding
  EXPECT_NEAR(ray->tau, 0.0, 1e-15);
  EXPECT_EQ(ray->u, 0.0);
  EXPECT_EQ(ray->v, 0.0);
}

TEST(NormalRay, NormalsOutsideTheHemisphereAreExcluded) {
  const TangentFrame f = tangent_frame(Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d o = Eigen::Vector3d::Zero(), q(1, 0, 0);
  EXPECT_FALSE(normal_ray(f, o, q, Eigen::Vector3d(1, 0, 0)).has_value());  // M.z = 0
  EXPECT_FALSE(normal_ray(f, o, q, Eigen::Vector3d(0, 0.6, -0.8)).has_value());
  const double nan = std::nan("");
  EXPECT_FALSE(normal_ray(f, o, q, Eigen::Vector3d(nan, 0, 1)).has_value());
  EXPECT_FALSE(normal_ray(f, o, q, Eigen::Vector3d(0, 0, nan)).has_value());
  EXPECT_FALSE(normal_ray(f, o, Eigen::Vector3d(1, nan, 0), Eigen::Vector3d(0, 0, 1)).has_value());
}

}  // namespace
}  // namespace focal
