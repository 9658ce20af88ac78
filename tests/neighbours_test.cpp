#include "focal/points/neighbours.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nanoflann.hpp>
#include <random>
#include <utility>
#include <vector>

#include "core/spatial_order.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "points/measured_neighbours.h"
#include "test_threads.h"

namespace focal {
namespace {

RowMatrixX3d random_cloud(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RowMatrixX3d V(n, 3);
  for (int i = 0; i < n; ++i) V.row(i) << u(rng), u(rng), u(rng);
  return V;
}

/// A 12 x 12 x 12 integer lattice: every point has many neighbours at exactly equal distances.
RowMatrixX3d lattice() {
  RowMatrixX3d V(12 * 12 * 12, 3);
  int r = 0;
  for (int x = 0; x < 12; ++x) {
    for (int y = 0; y < 12; ++y) {
      for (int z = 0; z < 12; ++z) V.row(r++) << x, y, z;
    }
  }
  return V;
}

/// The expected list: all other finite points by (squared distance, index), cut at k or radius.
std::vector<int> brute_force(const RowMatrixX3d& V, int i, int k, double radius) {
  std::vector<std::pair<double, int>> all;
  for (int j = 0; j < V.rows(); ++j) {
    if (j == i || !V.row(j).allFinite()) continue;
    const double d = (V.row(j) - V.row(i)).squaredNorm();
    if (radius > 0.0 && d > radius * radius) continue;
    all.emplace_back(d, j);
  }
  std::sort(all.begin(), all.end());
  std::vector<int> out;
  for (const auto& [d, j] : all) {
    if (k > 0 && static_cast<int>(out.size()) == k) break;
    out.push_back(j);
  }
  return out;
}

void expect_lists(const Neighbourhoods& nb, const RowMatrixX3d& V, int k, double radius) {
  ASSERT_EQ(nb.vertex_count(), V.rows());
  for (int i = 0; i < V.rows(); ++i) {
    const std::vector<int> got(nb.begin(i), nb.end(i));
    ASSERT_EQ(got, brute_force(V, i, k, radius)) << "point " << i;
  }
}

TEST(NearestNeighbours, MatchBruteForceWithTiesBrokenByIndex) {
  const RowMatrixX3d random = random_cloud(1500, 7);
  expect_lists(test::on_threads(2, [&] { return nearest_neighbours(random, 10); }), random, 10,
               0.0);
  // On the lattice the 6th, 18th, ... neighbours tie with others at the same distance.
  const RowMatrixX3d grid = lattice();
  for (int k : {1, 6, 7, 20})
    expect_lists(test::on_threads(2, [&] { return nearest_neighbours(grid, k); }), grid, k, 0.0);
}

// The tree's top 8 levels are split one level at a time and the subtrees below built in
// parallel: a cloud large enough for all of it (20000 points, 256 subtrees), with duplicates and
// a flat part where coordinates tie, against brute force at every 37th point.
TEST(NearestNeighbours, MatchBruteForceOnALargeCloudBuiltInParallel) {
  RowMatrixX3d V = random_cloud(20000, 9);
  for (int i = 0; i < 2000; ++i) V.row(10000 + i) = V.row(i);  // duplicates
  for (int i = 12000; i < 14000; ++i) V(i, 2) = 0.25;          // a plane z = 0.25
  for (int threads : {1, 2}) {
    const ExecutionScope scope({.threads = threads});
    const Neighbourhoods nb = nearest_neighbours(V, 16);
    for (int i = 0; i < V.rows(); i += 37) {
      const std::vector<int> got(nb.begin(i), nb.end(i));
      ASSERT_EQ(got, brute_force(V, i, 16, 0.0)) << "point " << i << ", threads " << threads;
    }
  }
}

/// V as nanoflann's dataset adaptor reads it.
struct CloudAdaptor {
  const RowMatrixX3d& V;
  [[nodiscard]] std::size_t kdtree_get_point_count() const {
    return static_cast<std::size_t>(V.rows());
  }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t d) const {
    return V(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(d));
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

// The library builds nanoflann's tree itself, its subtrees in parallel (src/points/); nanoflann's
// own serial build and queries are the plain reference: on a random cloud (no ties) large enough
// for the parallel build, every kNN list and every radius list is the one nanoflann's tree gives
// (its radius test is strict, the library's is <=; no distance equals the radius here).
TEST(NearestNeighbours, EqualNanoflannsOwnTree) {
  const RowMatrixX3d V = random_cloud(20000, 11);
  using Tree =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CloudAdaptor>,
                                          CloudAdaptor, 3, std::uint32_t>;
  const CloudAdaptor cloud{V};
  Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  constexpr int k = 16;
  constexpr double radius = 0.12;
  const Neighbourhoods knn = test::on_threads(2, [&] { return nearest_neighbours(V, k); });
  const Neighbourhoods within =
      test::on_threads(2, [&] { return radius_neighbours(V, radius, 0); });
  std::size_t radius_total = 0;
  for (int i = 0; i < V.rows(); ++i) {
    const double* q = V.row(i).data();
    std::uint32_t index[k + 1];
    double d2[k + 1];
    ASSERT_EQ(tree.knnSearch(q, k + 1, index, d2), static_cast<std::size_t>(k + 1));
    ASSERT_EQ(index[0], static_cast<std::uint32_t>(i));  // itself, at distance 0
    const std::vector<int> expected(index + 1, index + k + 1);
    ASSERT_EQ(std::vector<int>(knn.begin(i), knn.end(i)), expected) << "point " << i;
    std::vector<std::pair<std::uint32_t, double>> matches;
    tree.radiusSearch(q, radius * radius, matches, nanoflann::SearchParams());
    std::vector<std::pair<double, int>> by_distance;
    for (const auto& [j, d] : matches) {
      if (j != static_cast<std::uint32_t>(i)) by_distance.emplace_back(d, static_cast<int>(j));
    }
    std::sort(by_distance.begin(), by_distance.end());
    std::vector<int> listed;
    for (const auto& [d, j] : by_distance) listed.push_back(j);
    ASSERT_EQ(std::vector<int>(within.begin(i), within.end(i)), listed) << "point " << i;
    radius_total += listed.size();
  }
  EXPECT_GT(radius_total, 10u * static_cast<std::size_t>(V.rows()));  // lists of some length
}

TEST(NearestNeighbours, SameForAnyThreadCount) {
  const RowMatrixX3d V = random_cloud(20000, 3);
  const Neighbourhoods one = test::on_threads(1, [&] { return nearest_neighbours(V, 16); });
  const Neighbourhoods two = test::on_threads(2, [&] { return nearest_neighbours(V, 16); });
  const Neighbourhoods five = test::on_threads(5, [&] { return nearest_neighbours(V, 16); });
  EXPECT_EQ(one.offsets, two.offsets);
  EXPECT_EQ(one.indices, two.indices);
  EXPECT_EQ(one.indices, five.indices);
  // The spacing: per point in parallel, summed in row order as a serial loop would.
  double sum = 0.0;
  for (int i = 0; i < V.rows(); ++i) sum += (V.row(*one.begin(i)) - V.row(i)).norm();
  EXPECT_EQ(detail::mean_spacing(V, one, 1), sum / static_cast<double>(V.rows()));
  EXPECT_EQ(detail::mean_spacing(V, one, 2), sum / static_cast<double>(V.rows()));
  EXPECT_EQ(mean_spacing(V, one), sum / static_cast<double>(V.rows()));
  const Neighbourhoods r1 = test::on_threads(1, [&] { return radius_neighbours(V, 0.1, 0); });
  const Neighbourhoods r2 = test::on_threads(2, [&] { return radius_neighbours(V, 0.1, 0); });
  EXPECT_EQ(r1.indices, r2.indices);
}

TEST(NearestNeighbours, NonFinitePointsAreLeftOutAndFewPointsGiveShortLists) {
  RowMatrixX3d V = random_cloud(50, 1);
  V(3, 1) = NAN;
  V(10, 0) = INFINITY;
  const Neighbourhoods nb = test::on_threads(1, [&] { return nearest_neighbours(V, 60); });
  EXPECT_EQ(nb.size(3), 0);
  EXPECT_EQ(nb.size(10), 0);
  for (int i = 0; i < 50; ++i) {
    if (i == 3 || i == 10) continue;
    EXPECT_EQ(nb.size(i), 47);  // every other finite point
    for (const int* j = nb.begin(i); j != nb.end(i); ++j) EXPECT_TRUE(*j != 3 && *j != 10);
  }
  const RowMatrixX3d single = RowMatrixX3d::Zero(1, 3);
  EXPECT_EQ(nearest_neighbours(single, 4).size(0), 0);
  EXPECT_EQ(nearest_neighbours(RowMatrixX3d(0, 3), 4).vertex_count(), 0);
}

TEST(RadiusNeighbours, MatchBruteForceAndLimit) {
  const RowMatrixX3d V = random_cloud(1500, 11);
  expect_lists(test::on_threads(2, [&] { return radius_neighbours(V, 0.15, 0); }), V, 0, 0.15);
  expect_lists(test::on_threads(2, [&] { return radius_neighbours(V, 0.3, 12); }), V, 12, 0.3);
  // The radius is inclusive: lattice neighbours at distance exactly 1.
  const RowMatrixX3d grid = lattice();
  expect_lists(test::on_threads(2, [&] { return radius_neighbours(grid, 1.0, 0); }), grid, 0, 1.0);
}

// Each point's list is exactly the brute-force list within its own radius, scale x the median
// over the point and its k nearest of their k-th distances; the same for any thread count.
TEST(AdaptiveRadiusNeighbours, MatchBruteForceWithTheLocalRadius) {
  const RowMatrixX3d V = random_cloud(1500, 12);
  const int k = 10;
  const double scale = 1.2;
  const Neighbourhoods knn = test::on_threads(1, [&] { return nearest_neighbours(V, k); });
  std::vector<double> reach(static_cast<std::size_t>(V.rows()));
  for (int i = 0; i < V.rows(); ++i) reach[i] = (V.row(*(knn.end(i) - 1)) - V.row(i)).norm();
  const Neighbourhoods nb =
      test::on_threads(1, [&] { return adaptive_radius_neighbours(V, k, scale, 0, {}); });
  for (int i = 0; i < V.rows(); ++i) {
    std::vector<double> around{reach[i]};
    for (const int* j = knn.begin(i); j != knn.end(i); ++j) around.push_back(reach[*j]);
    std::sort(around.begin(), around.end());
    const double radius = scale * around[around.size() / 2];
    const std::vector<int> got(nb.begin(i), nb.end(i));
    ASSERT_EQ(got, brute_force(V, i, 0, radius)) << "point " << i;
  }
  const Neighbourhoods two =
      test::on_threads(2, [&] { return adaptive_radius_neighbours(V, k, scale, 0, {}); });
  EXPECT_EQ(two.offsets, nb.offsets);
  EXPECT_EQ(two.indices, nb.indices);
}

// On a cloud whose density falls 10-fold along x, a fixed radius gives the dense end 10x the
// neighbours of the sparse end; the adaptive radius gives both about the same count.
TEST(AdaptiveRadiusNeighbours, FollowTheDensity) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RowMatrixX3d V(20000, 3);
  for (int i = 0; i < V.rows(); ++i) {
    // Density proportional to 1 - 0.9 x on [0, 1]: inverse transform sampling.
    const double t = u(rng);
    const double x = (1.0 - std::sqrt(1.0 - 1.8 * t + 0.81 * t)) / 0.9;
    V.row(i) << x, u(rng), 0.0;
  }
  const auto mean_count = [&](const Neighbourhoods& nb, double lo, double hi) {
    double sum = 0.0;
    int n = 0;
    for (int i = 0; i < V.rows(); ++i) {
      if (V(i, 0) < lo || V(i, 0) > hi || V(i, 1) < 0.1 || V(i, 1) > 0.9) continue;
      sum += nb.size(i);
      ++n;
    }
    return sum / n;
  };
  const Neighbourhoods fixed = radius_neighbours(V, 0.02, 0);
  const Neighbourhoods adaptive = adaptive_radius_neighbours(V, 16, 1.0, 0);
  const double fixed_ratio = mean_count(fixed, 0.05, 0.15) / mean_count(fixed, 0.85, 0.95);
  const double adaptive_ratio = mean_count(adaptive, 0.05, 0.15) / mean_count(adaptive, 0.85, 0.95);
  EXPECT_GT(fixed_ratio, 3.0);
  EXPECT_NEAR(adaptive_ratio, 1.0, 0.2);
  EXPECT_THROW((void)adaptive_radius_neighbours(V, 16, 0.0, 0), InvalidInput);
  EXPECT_THROW((void)adaptive_radius_neighbours(V, 16, NAN, 0), InvalidInput);
  EXPECT_THROW((void)adaptive_radius_neighbours(V, 0, 1.0, 0), InvalidInput);
  EXPECT_THROW((void)adaptive_radius_neighbours(V, 16, 1.0, -1), InvalidInput);
}

TEST(Neighbours, MeanSpacingOfALattice) {
  const RowMatrixX3d grid = lattice() * 0.5;
  EXPECT_DOUBLE_EQ(mean_spacing(grid, nearest_neighbours(grid, 3)), 0.5);
}

TEST(NearestNeighbours, ExcludedPointsAreLeftOut) {
  const RowMatrixX3d V = random_cloud(400, 3);
  std::vector<char> excluded(400, 0);
  for (int i = 0; i < 400; i += 7) excluded[static_cast<std::size_t>(i)] = 1;
  RowMatrixX3d without = V;  // the exclusion must be what non-finite points get
  for (int i = 0; i < 400; i += 7) without(i, 0) = NAN;
  const Neighbourhoods a = test::on_threads(2, [&] { return nearest_neighbours(V, 10, excluded); });
  const Neighbourhoods b = test::on_threads(2, [&] { return nearest_neighbours(without, 10); });
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.indices, b.indices);
  const Neighbourhoods r =
      test::on_threads(2, [&] { return radius_neighbours(V, 0.3, 0, excluded); });
  const Neighbourhoods s = test::on_threads(2, [&] { return radius_neighbours(without, 0.3, 0); });
  EXPECT_EQ(r.offsets, s.offsets);
  EXPECT_EQ(r.indices, s.indices);
  EXPECT_THROW((void)nearest_neighbours(V, 10, std::vector<char>(3, 0)), InvalidInput);
}

// Points on a plane (a jittered grid) and a few far above it: the isolated ones are flagged,
// no point of the plane is (its ratios lie near 1).
TEST(Neighbours, OutlierPointsAreTheIsolatedOnes) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  RowMatrixX3d V(40 * 40 + 3, 3);
  int r = 0;
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 40; ++y) V.row(r++) << x + jitter(rng), y + jitter(rng), 0.0;
  }
  V.row(r++) << 10.0, 10.0, 6.0;  // 6 spacings above the plane
  V.row(r++) << 30.0, 5.0, -9.0;
  V.row(r++) << 20.0, 30.0, 25.0;
  const std::vector<char> outlier = outlier_points(V, nearest_neighbours(V, 16), 2.0);
  for (int i = 0; i < 1600; ++i) ASSERT_FALSE(outlier[static_cast<std::size_t>(i)]) << i;
  for (int i = 1600; i < 1603; ++i) EXPECT_TRUE(outlier[static_cast<std::size_t>(i)]) << i;
  EXPECT_THROW((void)outlier_points(V, nearest_neighbours(V, 16), 1.0), InvalidInput);
  EXPECT_THROW((void)outlier_points(V.topRows(10), nearest_neighbours(V, 16), 2.0), InvalidInput);
}

// The same plane (exactly flat: the floor of the spread) with three points one spacing above
// or below it, inside: as close to their neighbours as the plane's points are, the statistical
// test keeps them; the off-surface test flags them and no point of the plane.
TEST(Neighbours, OffSurfacePointsAreOffTheirNeighboursPlane) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  RowMatrixX3d V(40 * 40 + 3, 3);
  int r = 0;
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 40; ++y) V.row(r++) << x + jitter(rng), y + jitter(rng), 0.0;
  }
  V.row(r++) << 10.5, 10.5, 1.0;
  V.row(r++) << 30.5, 5.5, -1.0;
  V.row(r++) << 20.5, 30.5, 1.0;
  const Neighbourhoods nearest = nearest_neighbours(V, 16);
  const std::vector<char> isolated = outlier_points(V, nearest, 2.0);
  const std::vector<char> off = off_surface_points(V, nearest, 10.0);
  for (int i = 0; i < 1600; ++i) ASSERT_FALSE(off[static_cast<std::size_t>(i)]) << i;
  for (int i = 1600; i < 1603; ++i) {
    EXPECT_FALSE(isolated[static_cast<std::size_t>(i)]) << i;
    EXPECT_TRUE(off[static_cast<std::size_t>(i)]) << i;
  }
  EXPECT_THROW((void)off_surface_points(V, nearest, 1.0), InvalidInput);
  EXPECT_THROW((void)off_surface_points(V.topRows(10), nearest, 10.0), InvalidInput);
}

// A sphere sampled in latitude rings (radius 10, spacing ~1; CGAL's sphere926.pwn is one, and
// lost 2 points without the check of the neighbours): each pole's 16 nearest are one ring, whose
// spread about its plane is ~0 while the pole sits its sagitta above it. The pole is kept because
// its neighbours, each without it, sit as far off their own neighbours' planes; one point moved a
// spacing off the sphere is still flagged.
TEST(Neighbours, OffSurfacePointsKeepThePolesOfRings) {
  std::vector<Eigen::RowVector3d> points{{0.0, 0.0, 10.0}, {0.0, 0.0, -10.0}};
  const int rings = 31;
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    // The rings next to the poles hold 16 points: the poles' 16 nearest.
    const int count = r == 1 || r == rings - 1
                          ? 16
                          : static_cast<int>(std::lround(2.0 * rings * std::sin(theta)));
    for (int k = 0; k < count; ++k) {
      const double phi = 2.0 * M_PI * (k + 0.5 * (r % 2)) / count;
      points.emplace_back(10.0 * std::sin(theta) * std::cos(phi),
                          10.0 * std::sin(theta) * std::sin(phi), 10.0 * std::cos(theta));
    }
  }
  RowMatrixX3d V(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) V.row(static_cast<Eigen::Index>(i)) = points[i];
  const Eigen::Index moved = V.rows() / 2;
  V.row(moved) *= 1.1;  // one spacing (1.0) off the sphere
  const std::vector<char> off = off_surface_points(V, nearest_neighbours(V, 16), 10.0);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    EXPECT_EQ(off[static_cast<std::size_t>(i)], i == moved ? 1 : 0) << i;
  }
}

/// A unit sphere of n random points moved by noise of 0.1 spacing, 3% of them moved to random
/// places in its bounding box and 2% moved 1-3 spacings along the normal (seeded).
RowMatrixX3d noisy_sphere_with_outliers(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double spacing = std::sqrt(4.0 * M_PI / n);
  RowMatrixX3d V(n, 3);
  for (int i = 0; i < n; ++i) {
    const Eigen::RowVector3d p =
        Eigen::RowVector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    V.row(i) = p + 0.1 * spacing * Eigen::RowVector3d(u(rng), u(rng), u(rng));
    const double kind = 0.5 * (u(rng) + 1.0);
    if (kind < 0.03) V.row(i) << u(rng), u(rng), u(rng);
    if (kind >= 0.03 && kind < 0.05)
      V.row(i) = p * (1.0 + (2.0 * u(rng) + (u(rng) > 0 ? 1 : -1) * 2.0) * spacing);
  }
  return V;
}

/// outlier_points by its definition over brute-force lists, every point in row order.
std::vector<char> reference_outliers(const RowMatrixX3d& V,
                                     const std::vector<std::vector<int>>& lists, double ratio) {
  const auto n = static_cast<std::size_t>(V.rows());
  std::vector<double> reach(n, NAN);
  for (std::size_t i = 0; i < n; ++i) {
    if (lists[i].empty()) continue;
    double sum = 0.0;
    for (int j : lists[i]) sum += (V.row(j) - V.row(static_cast<Eigen::Index>(i))).norm();
    reach[i] = sum / static_cast<double>(lists[i].size());
  }
  std::vector<char> out(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> around;
    for (int j : lists[i]) {
      if (std::isfinite(reach[static_cast<std::size_t>(j)])) {
        around.push_back(reach[static_cast<std::size_t>(j)]);
      }
    }
    if (around.empty()) continue;
    std::nth_element(around.begin(),
                     around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2), around.end());
    out[i] = reach[i] > ratio * around[around.size() / 2];
  }
  return out;
}

/// The distance of point p to the least-squares plane of its list without `without`, and that
/// list's RMS distance to the plane (floored at 1e-9 x its mean distance to p), as
/// neighbours.h states them; NaN for fewer than 3.
std::pair<double, double> reference_plane(const RowMatrixX3d& V,
                                          const std::vector<std::vector<int>>& lists, int p,
                                          int without) {
  const Eigen::RowVector3d origin = V.row(p);
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  double reach = 0.0;
  int count = 0;
  for (int j : lists[static_cast<std::size_t>(p)]) {
    if (j == without) continue;
    const Eigen::RowVector3d q = V.row(j) - origin;
    sum += q;
    moment += q.transpose() * q;
    reach += q.norm();
    ++count;
  }
  if (count < 3) return {NAN, NAN};
  const Eigen::RowVector3d centroid = sum / count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(moment / count - centroid.transpose() * centroid);
  const Eigen::RowVector3d normal = eig.eigenvectors().col(0).transpose();
  if (!normal.allFinite()) return {NAN, NAN};
  return {std::abs(centroid.dot(normal)),
          std::max(std::sqrt(std::max(eig.eigenvalues()[0], 0.0)), 1e-9 * reach / count)};
}

/// off_surface_points by its definition over brute-force lists, every point in row order.
std::vector<char> reference_off_surface(const RowMatrixX3d& V,
                                        const std::vector<std::vector<int>>& lists, double ratio) {
  std::vector<char> out(static_cast<std::size_t>(V.rows()), 0);
  for (int p = 0; p < V.rows(); ++p) {
    const auto [distance, spread] = reference_plane(V, lists, p, -1);
    if (!(distance > ratio * spread)) continue;
    std::vector<double> around;
    for (int j : lists[static_cast<std::size_t>(p)]) {
      const double d = reference_plane(V, lists, j, p).first;
      if (std::isfinite(d)) around.push_back(d);
    }
    double typical = NAN;
    if (!around.empty()) {
      std::nth_element(around.begin(),
                       around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2),
                       around.end());
      typical = around[around.size() / 2];
    }
    out[static_cast<std::size_t>(p)] = !(distance <= 0.5 * ratio * typical);
  }
  return out;
}

// Both outlier tests take the points in the tree's leaf order (Neighbourhoods::order), in
// parallel: their flags are those of the definitions over brute-force lists in row order, for
// several seeds and thread counts, and with the order dropped (row order) the same.
TEST(Neighbours, OutlierTestsMatchTheirDefinitionsInAnyOrder) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const RowMatrixX3d V = noisy_sphere_with_outliers(3000, seed);
    std::vector<std::vector<int>> lists(static_cast<std::size_t>(V.rows()));
    for (int i = 0; i < V.rows(); ++i)
      lists[static_cast<std::size_t>(i)] = brute_force(V, i, 16, 0.0);
    const std::vector<char> isolated = reference_outliers(V, lists, 3.0);
    const std::vector<char> off = reference_off_surface(V, lists, 10.0);
    EXPECT_GT(std::count(isolated.begin(), isolated.end(), 1), 5) << seed;
    EXPECT_GT(std::count(off.begin(), off.end(), 1), 5) << seed;
    for (int threads : {1, 2, 5}) {
      const ExecutionScope scope({.threads = threads});
      const Neighbourhoods nb = nearest_neighbours(V, 16);
      EXPECT_EQ(outlier_points(V, nb, 3.0), isolated) << seed << " " << threads;
      EXPECT_EQ(off_surface_points(V, nb, 10.0), off) << seed << " " << threads;
      // The cloud estimators' path: the measures taken by the kNN query itself, from the tree's
      // copies of the points; the same lists, the same flags.
      const detail::MeasuredNeighbours measured =
          detail::measured_nearest_neighbours(V, 16, {}, threads);
      EXPECT_EQ(measured.neighbours.offsets, nb.offsets);
      EXPECT_EQ(measured.neighbours.indices, nb.indices);
      EXPECT_EQ(detail::outlier_points(V, nb, measured.measures.reach, 3.0, threads), isolated)
          << seed << " " << threads;
      EXPECT_EQ(detail::off_surface_points(V, nb, measured.measures, 10.0, threads), off)
          << seed << " " << threads;
      // Without the isolated outliers (the lists the off-surface test takes when some are).
      const detail::MeasuredNeighbours rest =
          detail::measured_nearest_neighbours(V, 16, isolated, threads);
      EXPECT_EQ(detail::off_surface_points(V, rest.neighbours, rest.measures, 10.0, threads),
                off_surface_points(V, nearest_neighbours(V, 16, isolated), 10.0))
          << seed << " " << threads;
    }
  }
}

// The order the kd-tree takes its points in (21 bits per axis), and the coarser one of a cloud's
// spatial copy (10, detail::morton_permutation): a permutation (non-finite rows last, also after
// a point whose code has every bit set, duplicates by row), whose neighbours in the order are
// near in space: on a shuffled random cloud the mean distance between consecutive points is a
// small fraction of that in row order.
TEST(MortonOrder, APermutationThatKeepsNeighboursTogether) {
  RowMatrixX3d V = random_cloud(20000, 4);
  V.row(3) = V.colwise().maxCoeff();  // the box's far corner: every bit of its code set
  V.row(7).setConstant(NAN);
  V(11, 2) = INFINITY;
  V.row(100) = V.row(50);
  V.row(30) = V.row(50);
  for (const int bits : {21, 16, 10}) {
    const std::vector<int> order = detail::morton_order(V, 2, bits);
    ASSERT_EQ(order.size(), static_cast<std::size_t>(V.rows()));
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < V.rows(); ++i) ASSERT_EQ(sorted[static_cast<std::size_t>(i)], i);
    EXPECT_EQ(order[order.size() - 2], 7) << bits;
    EXPECT_EQ(order.back(), 11) << bits;
    const auto at = [&](int row) {
      return std::find(order.begin(), order.end(), row) - order.begin();
    };
    EXPECT_LT(at(30), at(50));
    EXPECT_LT(at(50), at(100));
    const auto path = [&](const auto& row_at) {  // summed steps between finite consecutive rows
      double sum = 0.0;
      for (std::size_t j = 1; j < order.size(); ++j) {
        const double step = (V.row(row_at(j)) - V.row(row_at(j - 1))).norm();
        if (std::isfinite(step)) sum += step;
      }
      return sum;
    };
    const double along_order = path([&](std::size_t j) { return order[j]; });
    const double along_rows = path([](std::size_t j) { return static_cast<int>(j); });
    // In row order consecutive points are about 1.3 apart (uniform in a cube of side 2); along
    // the Z-order curve, steps of about the spacing (2 / 20000^(1/3) = 0.07) with jumps: the
    // ratio was 0.073 for seeds 4, 5 and 6 (a numpy copy of the order), so 0.15 leaves a factor
    // 2 (10 bits: cells of 0.002, far below the spacing, so the same curve).
    EXPECT_LT(along_order, 0.15 * along_rows) << bits;
    EXPECT_EQ(detail::morton_order(V, 1, bits), order) << bits;
  }
  EXPECT_EQ(detail::morton_order(V, 2), detail::morton_order(V, 2, 21));
  EXPECT_TRUE(detail::morton_order(RowMatrixX3d(0, 3), 2).empty());
  const detail::RowPermutation p = detail::morton_permutation(V, 2);
  EXPECT_EQ(p.order, detail::morton_order(V, 2, detail::kPermutationBits));
  for (int i = 0; i < V.rows(); ++i) {
    ASSERT_EQ(p.order[static_cast<std::size_t>(p.position[static_cast<std::size_t>(i)])], i);
  }
  // From 65,536 rows on, each pass of the sort counts and places runs of rows in parallel, one
  // per thread: the order of one run for any number of them, ties (duplicates far apart in the
  // rows, so in different runs) by row.
  RowMatrixX3d big = random_cloud(150000, 5);
  big.topRows(1000) = big.middleRows(120000, 1000);
  for (const int bits : {21, 10}) {
    const std::vector<int> one_run = detail::morton_order(big, 1, bits);
    for (const int threads : {2, 3, 7}) {
      EXPECT_EQ(detail::morton_order(big, threads, bits), one_run) << bits << " " << threads;
    }
    const auto at = [&](int row) {
      return std::find(one_run.begin(), one_run.end(), row) - one_run.begin();
    };
    EXPECT_EQ(at(120000), at(0) + 1) << bits;
  }
}

TEST(Neighbours, RejectInvalidArguments) {
  const RowMatrixX3d V = random_cloud(10, 1);
  EXPECT_THROW((void)nearest_neighbours(V, 0), InvalidInput);
  EXPECT_THROW((void)test::on_threads(-1, [&] { return nearest_neighbours(V, 4); }), InvalidInput);
  EXPECT_THROW((void)radius_neighbours(V, 0.0), InvalidInput);
  EXPECT_THROW((void)radius_neighbours(V, NAN), InvalidInput);
  EXPECT_THROW((void)radius_neighbours(V, INFINITY), InvalidInput);
  EXPECT_THROW((void)radius_neighbours(V, 1.0, -1), InvalidInput);
}

}  // namespace
}  // namespace focal
