#include "focal/normals/cloud_normals.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "focal/core/error.h"
#include "focal/points/neighbours.h"
#include "focal/surfaces/cloud_samples.h"
#include "normals/cloud_jets.h"
#include "test_clouds.h"

namespace focal {
namespace {

/// Points whose estimated normal points against the exact outward one.
int flipped(const RowMatrixX3d& N, const RowMatrixX3d& exact) {
  int count = 0;
  for (Eigen::Index i = 0; i < N.rows(); ++i) count += N.row(i).dot(exact.row(i)) < 0.0 ? 1 : 0;
  return count;
}

/// The largest angle (radians) between estimated and exact normals, sides ignored.
double worst_angle(const RowMatrixX3d& N, const RowMatrixX3d& exact) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    worst = std::max(worst, std::acos(std::min(1.0, std::abs(N.row(i).dot(exact.row(i))))));
  }
  return worst;
}

TEST(PcaNormals, ExactOnATiltedPlane) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  RowMatrixX3d V(500, 3);
  for (int i = 0; i < 500; ++i) V.row(i) = (u(rng) * a + u(rng) * b).transpose();
  const RowMatrixX3d N = pca_normals(V, nearest_neighbours(V, 10));
  for (int i = 0; i < 500; ++i) EXPECT_NEAR(std::abs(N.row(i).dot(n.transpose())), 1.0, 1e-12);
}

// Hoppe et al.'s MST orientation on unoriented samples of the closed analytic surfaces, two
// densities and two seeds: no normal may point inward.
TEST(OrientNormals, NoFlippedNormalOnClosedSurfaces) {
  for (SurfaceKind kind :
       {SurfaceKind::sphere, SurfaceKind::torus, SurfaceKind::ellipsoid, SurfaceKind::pear}) {
    for (int n : {1000, 5000}) {
      for (std::uint64_t seed : {1, 2}) {
        const AnalyticSurface s = test::cloud_of(kind, n, seed);
        const Neighbourhoods nb = nearest_neighbours(s.mesh.V, 16);
        RowMatrixX3d pca = pca_normals(s.mesh.V, nb);
        EXPECT_EQ(orient_normals_mst(s.mesh.V, nb, pca), 1);
        EXPECT_EQ(flipped(pca, s.mesh.N), 0) << surface_name(kind) << " n=" << n;
        const RowMatrixX3d jet = cloud_normals(s.mesh.V, nb);
        EXPECT_EQ(flipped(jet, s.mesh.N), 0) << surface_name(kind) << " n=" << n;
      }
    }
  }
}

// No flipped component on any analytic surface, clean, with position noise 0.1 and with 2%
// outliers, seeds 1 and 2 (3000 points, k = 16, no outlier test). Before the extreme-point vote
// the MST seeded at the highest point (an outlier, or a cylinder rim point with a horizontal
// normal) turned 5 of these 48 clouds inside out (cylinder seed 1 noisy and with outliers,
// ellipsoid, cylinder and saddle seed 2 with outliers); after it at most 1 point is flipped
// (cylinder seed 2 with outliers). Asserted: under 1% of the points with truth.
TEST(OrientNormals, NoFlippedComponentWithNoiseOrOutliers) {
  for (SurfaceKind kind : {SurfaceKind::sphere, SurfaceKind::ellipsoid, SurfaceKind::torus,
                           SurfaceKind::cylinder, SurfaceKind::saddle, SurfaceKind::monkey_saddle,
                           SurfaceKind::helix_tube, SurfaceKind::pear}) {
    for (std::uint64_t seed : {1, 2}) {
      for (int c = 0; c < 3; ++c) {
        const AnalyticSurface s =
            sample_cloud({.surface = {.kind = kind, .target_vertices = 3000, .seed = seed},
                          .position_noise = c == 1 ? 0.1 : 0.0,
                          .outliers = c == 2 ? 0.02 : 0.0,
                          .normals = true});  // the truth; not used
        const RowMatrixX3d N = cloud_normals(s.mesh.V, nearest_neighbours(s.mesh.V, 16));
        int bad = 0, scored = 0;
        for (Eigen::Index i = 0; i < N.rows(); ++i) {
          if (!std::isfinite(s.k1[i])) continue;  // an outlier
          ++scored;
          bad += N.row(i).dot(s.mesh.N.row(i)) < 0.0 ? 1 : 0;
        }
        EXPECT_LT(bad, scored / 100) << surface_name(kind) << " seed " << seed << " case " << c;
      }
    }
  }
}

TEST(OrientNormals, RandomlyFlippedExactNormalsAreRestoredPerComponent) {
  AnalyticSurface a = test::cloud_of(SurfaceKind::sphere, 800);
  // Two spheres 10 apart: two components, each oriented from its own highest point.
  RowMatrixX3d V(2 * a.mesh.V.rows(), 3), exact(V.rows(), 3);
  V << a.mesh.V, a.mesh.V.rowwise() + Eigen::RowVector3d(10.0, 0.0, 0.0);
  exact << a.mesh.N, a.mesh.N;
  RowMatrixX3d N = exact;
  std::mt19937_64 rng(3);
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    if (rng() % 2) N.row(i) *= -1.0;
  }
  EXPECT_EQ(orient_normals_mst(V, nearest_neighbours(V, 12), N), 2);
  EXPECT_EQ(N, exact);
}

/// Lists as CSR.
Neighbourhoods lists_of(const std::vector<std::vector<int>>& lists) {
  Neighbourhoods out;
  out.offsets.resize(static_cast<Eigen::Index>(lists.size()) + 1);
  out.offsets[0] = 0;
  std::vector<int> all;
  for (std::size_t i = 0; i < lists.size(); ++i) {
    all.insert(all.end(), lists[i].begin(), lists[i].end());
    out.offsets[static_cast<Eigen::Index>(i) + 1] = static_cast<int>(all.size());
  }
  out.indices =
      Eigen::Map<const Eigen::VectorXi>(all.data(), static_cast<Eigen::Index>(all.size()));
  return out;
}

// The tree runs over the lists made symmetric (j in i's list or i in j's): the same bits from
// the kNN lists, from their symmetric closure (sorted, each edge once per direction) and from
// that closure shuffled with repeated entries, where PCA's signs leave the tree real choices
// (a noisy torus, 8 neighbours: lists far from mutual), and one point far below that no list
// holds: reached only by its own list's edges, one way, it is no component of its own.
TEST(OrientNormals, TheTreeIsThatOfTheSymmetricGraph) {
  const AnalyticSurface a = test::cloud_of(SurfaceKind::torus, 3000);
  RowMatrixX3d V(a.mesh.V.rows() + 1, 3);
  const double extent = (a.mesh.V.colwise().maxCoeff() - a.mesh.V.colwise().minCoeff()).maxCoeff();
  V << a.mesh.V, Eigen::RowVector3d(0.0, 0.0, a.mesh.V.col(2).minCoeff() - extent);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 0.02);
  for (Eigen::Index i = 0; i < V.size(); ++i) V.data()[i] += g(rng);
  const Neighbourhoods knn = nearest_neighbours(V, 8);
  const int n = knn.vertex_count();
  std::vector<std::vector<int>> closure(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    for (const int* j = knn.begin(i); j != knn.end(i); ++j) {
      closure[static_cast<std::size_t>(i)].push_back(*j);
      closure[static_cast<std::size_t>(*j)].push_back(i);
    }
  }
  int one_way = 0;
  for (auto& l : closure) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    one_way += static_cast<int>(l.size()) - 8;
  }
  EXPECT_GT(one_way, n / 10);  // the closure adds edges: the one-way ones are exercised
  std::vector<std::vector<int>> shuffled = closure;
  for (auto& l : shuffled) {
    l.push_back(l.front());
    std::shuffle(l.begin(), l.end(), rng);
  }
  const RowMatrixX3d pca = pca_normals(V, knn);
  RowMatrixX3d N1 = pca, N2 = pca, N3 = pca;
  const int c1 = orient_normals_mst(V, knn, N1);
  EXPECT_EQ(c1, 1);
  EXPECT_EQ(orient_normals_mst(V, lists_of(closure), N2), c1);
  EXPECT_EQ(orient_normals_mst(V, lists_of(shuffled), N3), c1);
  EXPECT_EQ(N1, N2);
  EXPECT_EQ(N1, N3);
  EXPECT_NE(N1, pca);
}

TEST(OrientNormals, TowardsAViewpoint) {
  const AnalyticSurface s = test::cloud_of(SurfaceKind::sphere, 500);
  RowMatrixX3d N = s.mesh.N;
  orient_towards_viewpoint(s.mesh.V, Eigen::Vector3d::Zero(), N);  // the centre: all inward
  EXPECT_EQ(flipped(N, s.mesh.N), N.rows());
  const RowMatrixX3d outward = cloud_normals(s.mesh.V, nearest_neighbours(s.mesh.V, 16),
                                             {.viewpoint = Eigen::Vector3d(0.0, 0.0, 0.0)});
  EXPECT_EQ(flipped(outward, s.mesh.N), N.rows());
  EXPECT_THROW(orient_towards_viewpoint(s.mesh.V, Eigen::Vector3d(NAN, 0, 0), N), InvalidInput);
}

// Jets (degree 2) over the kNN are more accurate than PCA, whose normal tilts with any
// asymmetry of the neighbourhood: measured worst angles on the 4000-point ellipsoid, seeds 1-2,
// PCA 0.037-0.045 rad, jets 0.0059-0.0060 rad (a factor 6-7); asserted: jets 3x better.
TEST(CloudNormals, JetsBeatPcaOnAnEllipsoid) {
  for (std::uint64_t seed : {1, 2}) {
    const AnalyticSurface s = test::cloud_of(SurfaceKind::ellipsoid, 4000, seed);
    const Neighbourhoods nb = nearest_neighbours(s.mesh.V, 16);
    const double pca =
        worst_angle(cloud_normals(s.mesh.V, nb, {.method = CloudNormalMethod::pca}), s.mesh.N);
    const double jet = worst_angle(cloud_normals(s.mesh.V, nb), s.mesh.N);
    EXPECT_LT(3.0 * jet, pca);
  }
}

TEST(CloudNormals, RejectInvalidInput) {
  const AnalyticSurface s = test::cloud_of(SurfaceKind::sphere, 100);
  const Neighbourhoods nb = nearest_neighbours(s.mesh.V, 8);
  const RowMatrixX3d other = s.mesh.V.topRows(10);
  EXPECT_THROW((void)pca_normals(other, nb), InvalidInput);
  EXPECT_THROW((void)cloud_normals(s.mesh.V, nb, {.jet_degree = 5}), InvalidInput);
  RowMatrixX3d short_normals = RowMatrixX3d::Zero(3, 3);
  EXPECT_THROW((void)orient_normals_mst(s.mesh.V, nb, short_normals), InvalidInput);
}

// The plan's jets started on the side of given normals (no MST), then oriented as the MST
// orients them: the same residuals and normals as cloud_jets, bit for bit, for given normals
// that agree, that are random (every start sign a coin toss) and for both jet degrees.
TEST(CloudJetsSided, SameBitsAsTheMstJets) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (SurfaceKind kind : {SurfaceKind::torus, SurfaceKind::saddle}) {
    const AnalyticSurface s = test::cloud_of(kind, 3000, 2);
    const Neighbourhoods nb = nearest_neighbours(s.mesh.V, 16);
    RowMatrixX3d random(s.mesh.V.rows(), 3);
    for (Eigen::Index i = 0; i < random.rows(); ++i) random.row(i) << u(rng), u(rng), u(rng);
    for (const RowMatrixX3d& side : {s.mesh.N, random}) {
      for (int degree : {2, 3}) {
        CloudNormalOptions options;
        options.jet_degree = degree;
        const JetNormals mst = detail::cloud_jets(s.mesh.V, nb, options);
        JetNormals sided = detail::cloud_jets_sided(s.mesh.V, nb, options, side);
        EXPECT_EQ(std::memcmp(sided.residual.data(), mst.residual.data(),
                              sizeof(double) * static_cast<std::size_t>(mst.residual.size())),
                  0);
        detail::orient_sided_jets(s.mesh.V, nb, options, side, sided);
        EXPECT_EQ(std::memcmp(sided.N.data(), mst.N.data(),
                              sizeof(double) * static_cast<std::size_t>(mst.N.size())),
                  0)
            << surface_name(kind) << " degree " << degree;
      }
    }
  }
}

}  // namespace
}  // namespace focal
