#include "focal/curvature/triangle_curvature.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/surfaces/surfaces.h"
#include "kernels/triplet.h"
#include "mesh/prepared_access.h"
#include "test_meshes.h"

namespace focal {
namespace {

AnalyticSurface surface(SurfaceKind kind, Triangulation tri, int vertices, double a = 0) {
  return test::analytic_surface(kind, tri, vertices, a, 7);
}

/// Longest edge of the mesh.
double longest_edge(const Mesh& m) {
  double h = 0.0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c)
      h = std::max(h, (m.V.row(m.F(f, c)) - m.V.row(m.F(f, (c + 1) % 3))).norm());
  }
  return h;
}

// On a sphere the three rays of any triangle meet in the centre, at depth -d below the plane
// through the face's centroid, and G = X / d exactly. The estimator lifts that plane by the
// second-order sagitta s = (1/6) sum x^T M x (see triangle_curvature.cpp), so d + s equals r up
// to fourth-order terms: |K r^2 - 1| and |H r - 1| are O((h/r)^4), bounded here by (h_max/r)^4
// with h_max the longest edge (measured: 1.4e-6 against a bound of about 2e-4).
TEST(TriangleCurvature, SpherePerFaceIsFourthOrderAccurate) {
  for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
    for (double r : {1e-2, 1.0, 1e2}) {
      const AnalyticSurface s = surface(SurfaceKind::sphere, tri, 1000, r);
      const double bound = std::pow(longest_edge(s.mesh) / r, 4);
      const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
      for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
        ASSERT_NEAR(t.K[f] * r * r, 1.0, bound) << "face " << f;
        ASSERT_NEAR(t.H[f] * r, 1.0, bound) << "face " << f;
        ASSERT_NEAR(t.lambda1[f] / r, -1.0, bound);  // focal depth: the centre, r below
        ASSERT_EQ(static_cast<PointClass>(t.point_class[f]), PointClass::umbilic);
      }
    }
  }
}

// The per-face operators are rotated (not projected) into each vertex frame, which keeps the
// sphere's kI intact: the vertex average inherits the per-face bound.
TEST(TriangleCurvature, SphereVertexAverage) {
  const AnalyticSurface s = surface(SurfaceKind::sphere, Triangulation::irregular, 1000, 3.0);
  const double bound = std::pow(longest_edge(s.mesh) / 3.0, 4);
  CurvatureOptions o;
  o.method = Method::triangle;
  const CurvatureResult r = estimate_curvature(s.mesh.V, s.mesh.F, s.mesh.N, o);
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    ASSERT_NEAR(r.k1[i] * 3.0, 1.0, bound);
    ASSERT_NEAR(r.k2[i] * 3.0, 1.0, bound);
  }
}

// All normals of a cylinder are perpendicular to its axis, and so is each face's mean normal:
// every (sigma, tau) lies on one line through the origin, the columns of G are parallel and
// A = det G vanishes up to rounding. One focal sheet is at infinity: parabolic (paper 4.3).
TEST(TriangleCurvature, CylinderFacesAreParabolic) {
  for (auto tri : {Triangulation::regular, Triangulation::irregular}) {
    const AnalyticSurface s = surface(SurfaceKind::cylinder, tri, 1500, 2.0);
    const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
    for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
      ASSERT_EQ(static_cast<PointClass>(t.point_class[f]), PointClass::parabolic) << "face " << f;
      ASSERT_TRUE(std::isinf(t.lambda2[f]) || std::abs(t.lambda2[f]) > 1e6);
    }
  }
}

// The roots of A l^2 + B l + C are the focal depths -1/k (eq. 6-8). Where rounding or noise
// makes the discriminant negative (near the umbilics of the ellipsoid) both depths are the
// double root -1/H.
TEST(TriangleCurvature, FocalDepthsSolveTheCharacteristicEquation) {
  const AnalyticSurface s = surface(SurfaceKind::ellipsoid, Triangulation::irregular, 1500);
  const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
  int real_roots = 0;
  for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
    if (t.B[f] * t.B[f] - 4 * t.A[f] * t.C[f] < 0) {
      EXPECT_EQ(t.k1[f], t.H[f]);
      EXPECT_EQ(t.k2[f], t.H[f]);
      continue;
    }
    ++real_roots;
    for (double l : {t.lambda1[f], t.lambda2[f]}) {
      const double scale = std::abs(t.A[f]) * l * l + std::abs(t.B[f] * l) + std::abs(t.C[f]);
      EXPECT_LE(std::abs(t.A[f] * l * l + t.B[f] * l + t.C[f]), 1e-9 * scale) << "face " << f;
    }
  }
  EXPECT_GT(real_roots, 0.9 * s.mesh.F.rows());
}

// Appendix B, Lemma 2: the two slits are perpendicular; both lie in the face's tangent plane.
// Exact for a symmetric discrete shape operator; with the exact normals of a smooth surface M is
// symmetric up to O(h), so the cosine between the slits is O(h) (h ~ 0.05 here).
TEST(TriangleCurvature, SlitsArePerpendicular) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::regular, 4000);
  const TriangleCurvatureResult t = triangle_curvature(s.mesh.V, s.mesh.F, s.mesh.N);
  std::vector<double> cosines;
  for (Eigen::Index f = 0; f < s.mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = t.slit1.row(f), b = t.slit2.row(f), n = t.face_normal.row(f);
    EXPECT_NEAR(a.norm(), 1.0, 1e-12);
    EXPECT_NEAR(a.dot(n), 0.0, 1e-12);
    cosines.push_back(std::abs(a.dot(b)));
  }
  std::nth_element(cosines.begin(), cosines.begin() + cosines.size() / 2, cosines.end());
  EXPECT_LT(cosines[cosines.size() / 2], 0.05);
}

TEST(TriangleCurvature, DegenerateFacesAreUndefined) {
  Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0;
  m.F.resize(3, 3);
  m.F << 0, 1, 2,  // collinear: C = 0
      0, 1, 1,     // repeated index
      0, 1, 3;     // fine
  m.N = RowMatrixX3d::Zero(4, 3);
  m.N.col(2).setOnes();
  const TriangleCurvatureResult t = triangle_curvature(m.V, m.F, m.N);
  EXPECT_EQ(static_cast<PointClass>(t.point_class[0]), PointClass::undefined);
  EXPECT_TRUE(std::isnan(t.K[0]));
  EXPECT_EQ(static_cast<PointClass>(t.point_class[1]), PointClass::undefined);
  EXPECT_EQ(static_cast<PointClass>(t.point_class[2]), PointClass::flat);
  EXPECT_EQ(t.K[2], 0.0);
}

/// x and y have the same bits (NaN included).
bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

bool same_row(const RowMatrixX3d& m, Eigen::Index f, const kernels::Vec3<double>& v) {
  return same_bits(m(f, 0), v.x) && same_bits(m(f, 1), v.y) && same_bits(m(f, 2), v.z);
}

// The per-face lane kernel is kernels/triplet.h's characteristic equation, the formula the
// device's per-triangle and image-space kernels run in float: run on plain doubles, one face at
// a time, it gives every field's bits, for clean and noisy normals and for the faces the lanes
// handle by select (a zero normal, a collinear face, a repeated corner).
TEST(TriangleCurvature, TheLaneKernelIsTheSharedFormulaOnScalarsBitForBit) {
  std::vector<Mesh> meshes;
  meshes.push_back(surface(SurfaceKind::saddle, Triangulation::irregular, 1500).mesh);
  meshes.push_back(surface(SurfaceKind::torus, Triangulation::regular, 1500).mesh);
  Mesh noisy = surface(SurfaceKind::ellipsoid, Triangulation::irregular, 1500).mesh;
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (Eigen::Index i = 0; i < noisy.N.rows(); ++i) {
    noisy.N.row(i) += Eigen::RowVector3d(noise(random), noise(random), noise(random));
  }
  noisy.N.row(7).setZero();
  const Eigen::RowVector3i corners = noisy.F.row(11);
  noisy.F.row(11) << corners(0), corners(0), corners(1);  // a repeated corner
  meshes.push_back(noisy);
  for (const Mesh& m : meshes) {
    const TriangleCurvatureResult t = triangle_curvature(m.V, m.F, m.N);
    std::vector<char> ok;
    const RowMatrixX3d unit = detail::unit_rows(m.N, ok);
    const double zero = CurvatureOptions{}.tolerances.zero / mean_edge_length(m.V, m.F);
    int undefined = 0;
    for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
      kernels::Vec3<double> p[3], n[3];
      bool valid = true;
      for (int c = 0; c < 3; ++c) {
        const int v = m.F(f, c);
        p[c] = {m.V(v, 0), m.V(v, 1), m.V(v, 2)};
        n[c] = {unit(v, 0), unit(v, 1), unit(v, 2)};
        valid = valid && ok[static_cast<std::size_t>(v)];
      }
      const triplet::Equation<double> e = triplet::characteristic_equation(p, n, valid);
      if (!e.valid) {
        ++undefined;
        ASSERT_EQ(static_cast<PointClass>(t.point_class[f]), PointClass::undefined) << f;
        ASSERT_TRUE(std::isnan(t.K[f]) && std::isnan(t.d1(f, 0)) && std::isnan(t.slit2(f, 2)));
        continue;
      }
      ASSERT_TRUE(same_bits(t.A[f], e.A) && same_bits(t.B[f], e.B) && same_bits(t.C[f], e.C)) << f;
      ASSERT_TRUE(same_bits(t.K[f], e.K) && same_bits(t.H[f], e.H)) << f;
      ASSERT_TRUE(same_bits(t.k1[f], e.k1) && same_bits(t.k2[f], e.k2)) << f;
      ASSERT_TRUE(same_bits(t.lambda1[f], e.lambda1) && same_bits(t.lambda2[f], e.lambda2)) << f;
      ASSERT_TRUE(
          same_bits(t.shape_operator(f, 0), e.M.a) && same_bits(t.shape_operator(f, 1), e.M.b) &&
          same_bits(t.shape_operator(f, 2), e.M.c) && same_bits(t.shape_operator(f, 3), e.M.d))
          << f;
      const triplet::Directions<double> d = triplet::directions_of(e);
      ASSERT_TRUE(same_row(t.d1, f, d.d1) && same_row(t.d2, f, d.d2)) << f;
      ASSERT_TRUE(same_row(t.slit1, f, d.slit1) && same_row(t.slit2, f, d.slit2)) << f;
      ASSERT_TRUE(same_row(t.face_normal, f, e.frame.n)) << f;
      ASSERT_EQ(t.point_class[f],
                kernels::classify(e.k1, e.k2, zero, CurvatureOptions{}.tolerances.umbilic))
          << f;
    }
    EXPECT_LT(undefined, m.F.rows() / 10);
    if (&m == &meshes.back()) {  // at least the faces at vertex 7 and face 11
      int expected = 0;
      for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
        expected += f == 11 || (m.F.row(f).array() == 7).any();
      }
      EXPECT_GE(undefined, expected);
      EXPECT_GE(expected, 4);
    }
  }
}

TEST(TriangleCurvature, InvalidArgumentsThrow) {
  const Mesh m = test::flat_grid(3);
  EXPECT_THROW((void)triangle_curvature(m.V, m.F, m.N.topRows(2)), InvalidInput);
  RowMatrixX3i bad = m.F;
  bad(0, 0) = -1;
  EXPECT_THROW((void)triangle_curvature(m.V, bad, m.N), InvalidInput);
}

// Asking for fewer fields leaves the others empty and changes none of the asked values, also
// for undefined faces (NaN where all fields are asked), and any thread count gives the same.
TEST(TriangleCurvature, FieldSelectionFillsOnlyTheAskedFieldsWithTheSameValues) {
  const AnalyticSurface s = surface(SurfaceKind::ellipsoid, Triangulation::irregular, 3000);
  Mesh m = s.mesh;
  m.N.row(0).setZero();  // its faces come out undefined
  const TriangleCurvatureResult all = triangle_curvature(m.V, m.F, m.N);
  TriangleFields few;
  few.coefficients = few.focal_depths = few.slits = few.face_normal = false;
  CurvatureOptions o;
  for (const int threads : {1, 3}) {
    const ExecutionScope scope({.threads = threads});
    const TriangleCurvatureResult t = triangle_curvature(m.V, m.F, m.N, o, few);
    for (const Eigen::VectorXd* v : {&t.A, &t.B, &t.C, &t.lambda1, &t.lambda2}) {
      EXPECT_EQ(v->size(), 0);
    }
    EXPECT_EQ(t.slit1.rows(), 0);
    EXPECT_EQ(t.face_normal.rows(), 0);
    const auto same = [](const auto& a, const auto& b) {
      return a.rows() == b.rows() && a.cols() == b.cols() &&
             ((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all();
    };
    EXPECT_TRUE(same(t.K, all.K) && same(t.H, all.H) && same(t.k1, all.k1) && same(t.k2, all.k2));
    EXPECT_TRUE(same(t.d1, all.d1) && same(t.d2, all.d2));
    EXPECT_TRUE(same(t.shape_operator, all.shape_operator));
    EXPECT_TRUE((t.point_class.array() == all.point_class.array()).all());
  }
  const auto undefined = static_cast<std::uint8_t>(PointClass::undefined);
  EXPECT_GT((all.point_class.array() == undefined).count(), 0);  // the faces at vertex 0
}

// The vertex average solves the faces of one block of vertices at a time (a face at most once
// per block, its row the same bits in any block): on a mesh of three blocks whose vertices are
// shuffled (so most faces are solved in two or three blocks) every row has the same bits as the
// row of the same vertex in the original order, a vertex without a normal included.
TEST(TriangleCurvature, VertexAverageDoesNotDependOnTheVertexOrder) {
  const AnalyticSurface s = surface(SurfaceKind::torus, Triangulation::regular, 140000);
  Mesh m = s.mesh;
  m.N.row(5).setZero();
  const auto n = static_cast<int>(m.V.rows());
  ASSERT_GT(n, 2 * 65536);
  std::vector<int> to(static_cast<std::size_t>(n));
  std::iota(to.begin(), to.end(), 0);
  std::shuffle(to.begin(), to.end(), std::mt19937(3));
  Mesh p = m;
  for (int i = 0; i < n; ++i) {
    p.V.row(to[static_cast<std::size_t>(i)]) = m.V.row(i);
    p.N.row(to[static_cast<std::size_t>(i)]) = m.N.row(i);
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) p.F(f, c) = to[static_cast<std::size_t>(m.F(f, c))];
  }
  CurvatureOptions o;
  o.method = Method::triangle;
  const CurvatureResult a = estimate_curvature(m.V, m.F, m.N, o);
  const CurvatureResult b = estimate_curvature(p.V, p.F, p.N, o);
  const auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  int differing = 0;
  for (int i = 0; i < n; ++i) {
    const int j = to[static_cast<std::size_t>(i)];
    bool equal = a.point_class[i] == b.point_class[j] && a.rays_used[i] == b.rays_used[j];
    for (const auto& [x, y] :
         {std::pair{&a.k1, &b.k1}, {&a.k2, &b.k2}, {&a.residual, &b.residual}}) {
      equal = equal && same((*x)[i], (*y)[j]);
    }
    for (int c = 0; c < 3; ++c) equal = equal && same(a.d1(i, c), b.d1(j, c));
    differing += equal ? 0 : 1;
  }
  EXPECT_EQ(differing, 0);
  EXPECT_EQ(a.class_of(5), PointClass::undefined);
}

}  // namespace
}  // namespace focal
