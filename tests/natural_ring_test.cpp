#include "points/natural_ring.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "focal/points/neighbours.h"

namespace focal::detail {
namespace {

using Eigen::Vector2d;

/// Twice the signed area of (a, b, c): > 0 when counter-clockwise.
double orient(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// The angle at the origin of the fan triangle (origin, p[a], p[b]).
double angle_at_origin(const std::vector<Vector2d>& p, int a, int b) {
  return std::atan2(orient(Vector2d::Zero(), p[a], p[b]), p[a].dot(p[b]));
}

/// Every fan triangle (origin, a, b) is counter-clockwise and Delaunay: no point lies inside its
/// circumcircle (relative tolerance 1e-9 of the squared radius).
void expect_delaunay_fan(const std::vector<Vector2d>& p, const PlanarRing& ring) {
  const std::size_t m = ring.ring.size();
  for (std::size_t k = 0; k < m; ++k) {
    if (!ring.adjacent_to_next[k]) continue;
    const Vector2d a = p[ring.ring[k]], b = p[ring.ring[(k + 1) % m]];
    ASSERT_GT(orient(Vector2d::Zero(), a, b), 0.0) << k;
    // Circumcentre of (0, a, b): c . a = |a|^2 / 2 and c . b = |b|^2 / 2.
    Eigen::Matrix2d A;
    A << a.transpose(), b.transpose();
    const Vector2d c = A.inverse() * Vector2d(0.5 * a.squaredNorm(), 0.5 * b.squaredNorm());
    for (std::size_t q = 0; q < p.size(); ++q) {
      EXPECT_GE((p[q] - c).squaredNorm(), c.squaredNorm() * (1.0 - 1e-9)) << k << " " << q;
    }
  }
}

// On a hexagonal lattice the natural neighbours are the 6 nearest, whatever the order of the
// points and whatever else is in the list: a closed ring of equal angles (pi / 3), the balanced
// stencil of a regular mesh's 1-ring.
TEST(NaturalRing, HexagonalLatticeGivesTheSixNearest) {
  std::vector<Vector2d> p;
  for (int i = -3; i <= 3; ++i) {
    for (int j = -3; j <= 3; ++j) {
      const Vector2d q(i + 0.5 * j, j * std::sqrt(3.0) / 2.0);
      if (q.norm() > 0.0 && q.norm() < 2.5) p.push_back(q);
    }
  }
  std::mt19937 rng(3);
  std::shuffle(p.begin(), p.end(), rng);
  const PlanarRing ring = natural_neighbours_of_origin(p);
  ASSERT_EQ(ring.ring.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_NEAR(p[ring.ring[k]].norm(), 1.0, 1e-12);
    EXPECT_TRUE(ring.adjacent_to_next[k]);
    EXPECT_NEAR(angle_at_origin(p, ring.ring[k], ring.ring[(k + 1) % 6]), std::numbers::pi / 3,
                1e-12);
  }
}

// Four cells meet at each corner of a square lattice's cells: the diagonal neighbours touch the
// origin's cell in a point only and are no natural neighbours; the ring is the 4 axis ones.
TEST(NaturalRing, SquareLatticeGivesTheFourAxisNeighbours) {
  std::vector<Vector2d> p;
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      if (i != 0 || j != 0) p.emplace_back(i, j);
    }
  }
  const PlanarRing ring = natural_neighbours_of_origin(p);
  ASSERT_EQ(ring.ring.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(p[ring.ring[k]].norm(), 1.0, 1e-12);
    EXPECT_TRUE(ring.adjacent_to_next[k]);
  }
}

// Random points around the origin (as a point's projected nearest neighbours): every fan
// triangle is Delaunay, and a closed fan goes once around the origin (angles sum to 2 pi).
TEST(NaturalRing, RandomNeighbourhoodsGiveAClosedDelaunayFan) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vector2d> p;
    while (p.size() < 16) {
      const Vector2d q(u(rng), u(rng));
      if (q.norm() < 1.0) p.push_back(q);
    }
    // The origin well inside: points in each quadrant near the rim.
    for (const Vector2d& q :
         {Vector2d(0.9, 0.1), Vector2d(-0.1, 0.9), Vector2d(-0.9, -0.1), Vector2d(0.1, -0.9)}) {
      p.push_back(q);
    }
    const PlanarRing ring = natural_neighbours_of_origin(p);
    expect_delaunay_fan(p, ring);
    ASSERT_GE(ring.ring.size(), 3u) << trial;
    double total = 0.0;
    for (std::size_t k = 0; k < ring.ring.size(); ++k) {
      ASSERT_TRUE(ring.adjacent_to_next[k]) << trial;
      total += angle_at_origin(p, ring.ring[k], ring.ring[(k + 1) % ring.ring.size()]);
    }
    EXPECT_NEAR(total, 2.0 * std::numbers::pi, 1e-9) << trial;
  }
}

// The origin on the hull of its neighbours (all on one side, as at the rim of an open surface):
// the cell is open, the ring has one gap, between its last and first neighbours, and its
// triangles stay Delaunay. Points at the origin are left out.
TEST(NaturalRing, OriginOnTheHullGivesAnOpenFan) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.05, 1.0), v(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<Vector2d> p{Vector2d::Zero()};
    for (int k = 0; k < 15; ++k) p.emplace_back(u(rng), v(rng));
    const PlanarRing ring = natural_neighbours_of_origin(p);
    ASSERT_GE(ring.ring.size(), 2u) << trial;
    EXPECT_EQ(std::count(ring.ring.begin(), ring.ring.end(), 0), 0) << "the origin's duplicate";
    EXPECT_FALSE(ring.adjacent_to_next.back()) << trial;
    EXPECT_EQ(std::count(ring.adjacent_to_next.begin(), ring.adjacent_to_next.end(), 0), 1);
    expect_delaunay_fan(p, ring);
  }
  EXPECT_TRUE(natural_neighbours_of_origin({}).ring.empty());
  EXPECT_TRUE(natural_neighbours_of_origin({Vector2d::Zero()}).ring.empty());
}

// planar_fans: the triangles at the centres, each once, the same as the fans of natural
// neighbours about each centre.
TEST(NaturalRing, PlanarFansListEachTriangleOnce) {
  std::vector<Vector2d> p;
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) p.emplace_back(i + 0.5 * j + 0.01 * i * i, j * 0.87);
  }
  const int centre = 12;  // (0, 0)
  const auto one = planar_fans(p, {centre});
  const auto two = planar_fans(p, {centre, 13});
  EXPECT_EQ(one.size(), 6u);
  EXPECT_LT(two.size(), 2 * one.size());  // two neighbours share two triangles
  for (const auto& t : two) {
    EXPECT_EQ(t[0], *std::min_element(t.begin(), t.end()));
    EXPECT_GT(orient(p[t[0]], p[t[1]], p[t[2]]), 0.0);
  }
  EXPECT_TRUE(std::is_sorted(two.begin(), two.end()));
  EXPECT_EQ(std::adjacent_find(two.begin(), two.end()), two.end());
}

// The scratch forms give planar_fans' triangles, reusing one scratch for every centre: planar_fan
// about each centre, and fan_of_ring from the ring about a centre at the origin.
TEST(NaturalRing, ScratchFormsMatchPlanarFans) {
  std::vector<Vector2d> p{{0.0, 0.0}};
  for (int k = 0; k < 16; ++k)
    p.emplace_back(std::cos(2.4 * k) * (1.0 + 0.1 * k), std::sin(2.4 * k));
  RingScratch scratch;
  std::vector<std::array<int, 3>> fan;
  for (int c = 0; c < static_cast<int>(p.size()); ++c) {
    planar_fan(p, c, scratch, fan);
    EXPECT_EQ(fan, planar_fans(p, {c})) << c;
  }
  PlanarRing ring;
  natural_neighbours_of_origin(p, scratch, ring);
  fan_of_ring(ring, 0, fan);
  EXPECT_EQ(fan, planar_fans(p, {0}));
  EXPECT_FALSE(fan.empty());
}

/// A hexagonal lattice of unit spacing in the plane z = 0, within `radius` of the origin.
RowMatrixX3d planar_hexagonal_lattice(double radius) {
  std::vector<Eigen::Vector3d> rows;
  for (int i = -20; i <= 20; ++i) {
    for (int j = -20; j <= 20; ++j) {
      const Eigen::Vector3d q(i + 0.5 * j, j * std::sqrt(3.0) / 2.0, 0.0);
      if (q.norm() <= radius) rows.push_back(q);
    }
  }
  RowMatrixX3d V(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t r = 0; r < rows.size(); ++r) V.row(static_cast<Eigen::Index>(r)) = rows[r];
  return V;
}

// natural_fans on a planar hexagonal lattice (a cloud of known Delaunay triangulation): each
// point far enough inside that its 16 nearest surround it gets its 6 equilateral triangles,
// starting at itself, counter-clockwise about its normal (+z: positive in (x, y); -z: negative).
// Points without ok get no fan, and a neighbour without ok or with a normal in the other
// hemisphere is in no one's fan.
TEST(NaturalRing, NaturalFansOfAPlanarLatticeAreItsSixTriangles) {
  const RowMatrixX3d V = planar_hexagonal_lattice(6.0);
  const Eigen::Index n = V.rows();
  const Neighbourhoods knn = nearest_neighbours(V, 16);
  for (const double side : {1.0, -1.0}) {
    RowMatrixX3d N = RowMatrixX3d::Zero(n, 3);
    N.col(2).setConstant(side);
    const std::vector<char> ok(static_cast<std::size_t>(n), 1);
    const NaturalFans fans = natural_fans(V, N, ok, knn, 2);
    ASSERT_EQ(fans.own.vertex_count(), n);
    int interior = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (V.row(i).norm() > 3.5) continue;
      ++interior;
      ASSERT_EQ(fans.own.size(i), 6) << i;
      for (int f = fans.own.begin(i); f < fans.own.end(i); ++f) {
        const auto t = fans.F.row(fans.own.faces[static_cast<std::size_t>(f)]);
        EXPECT_EQ(t[0], i);
        for (const int c : {1, 2}) EXPECT_NEAR((V.row(t[c]) - V.row(i)).norm(), 1.0, 1e-12);
        EXPECT_NEAR((V.row(t[1]) - V.row(t[2])).norm(), 1.0, 1e-12);
        const Vector2d a = (V.row(t[1]) - V.row(i)).head<2>().transpose();
        const Vector2d b = (V.row(t[2]) - V.row(i)).head<2>().transpose();
        EXPECT_GT(side * orient(Vector2d::Zero(), a, b), 0.0) << i;
      }
    }
    EXPECT_GT(interior, 30);
  }
  // The origin's point: drop one neighbour (ok 0) and turn another's normal over.
  RowMatrixX3d N = RowMatrixX3d::Zero(n, 3);
  N.col(2).setOnes();
  std::vector<char> ok(static_cast<std::size_t>(n), 1);
  Eigen::Index centre = 0;
  V.rowwise().norm().minCoeff(&centre);
  const int dropped = knn.begin(static_cast<int>(centre))[0];
  const int flipped = knn.begin(static_cast<int>(centre))[1];
  ok[static_cast<std::size_t>(dropped)] = 0;
  N(flipped, 2) = -1.0;
  const NaturalFans fans = natural_fans(V, N, ok, knn, 1);
  EXPECT_EQ(fans.own.size(dropped), 0);
  EXPECT_EQ(fans.own.size(flipped), 0);  // all its neighbours are in the other hemisphere
  for (int r = 0; r < fans.F.rows(); ++r) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NE(fans.F(r, c), dropped) << r;
      EXPECT_NE(fans.F(r, c), flipped) << r;
    }
  }
  // The centre's fan closes over the gap, through the next ring: its angles sum to 2 pi.
  double total = 0.0;
  for (int f = fans.own.begin(centre); f < fans.own.end(centre); ++f) {
    const auto t = fans.F.row(fans.own.faces[static_cast<std::size_t>(f)]);
    const Vector2d a = (V.row(t[1]) - V.row(centre)).head<2>().transpose();
    const Vector2d b = (V.row(t[2]) - V.row(centre)).head<2>().transpose();
    total += std::atan2(orient(Vector2d::Zero(), a, b), a.dot(b));
  }
  EXPECT_NEAR(total, 2.0 * std::numbers::pi, 1e-9);
}
}  // namespace
}  // namespace focal::detail
