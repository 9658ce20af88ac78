// PreparedMesh: every function given one returns the same bits as on the arrays, what it builds
// is shared by later calls and by with_normals(), and bad arrays are rejected once, up front.

#include "focal/mesh/prepared.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "focal/core/error.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/curvature/recommended.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/mesh/check.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/orientation.h"
#include "focal/normals/jets.h"
#include "focal/normals/vertex_normals.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

/// Equal bits, NaN where the other has NaN.
template <class A, class B>
bool same(const A& a, const B& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      const double x = static_cast<double>(a(i, j)), y = static_cast<double>(b(i, j));
      if (!(x == y || (std::isnan(x) && std::isnan(y)))) return false;
    }
  }
  return true;
}

void expect_same(const CurvatureResult& a, const CurvatureResult& b) {
  EXPECT_TRUE(same(a.k1, b.k1));
  EXPECT_TRUE(same(a.k2, b.k2));
  EXPECT_TRUE(same(a.d1, b.d1));
  EXPECT_TRUE(same(a.d2, b.d2));
  EXPECT_TRUE(same(a.residual, b.residual));
  EXPECT_TRUE(a.point_class == b.point_class);
  EXPECT_TRUE(a.rays_used == b.rays_used);
  EXPECT_TRUE(a.rays_excluded == b.rays_excluded);
}

Mesh noisy_torus() {
  Mesh m = test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, 3000, 0.0, 7).mesh;
  add_normal_noise(m, 0.05, 3);
  return m;
}

TEST(PreparedMesh, EveryFunctionGivesTheBitsOfItsArrays) {
  const Mesh m = noisy_torus();
  // One PreparedMesh through every function, so that each reuses what the earlier ones built.
  const ExecutionScope scope({.threads = 2});
  const PreparedMesh p(m.V, m.F, m.N);
  const MeshFindings f = check_mesh(p);
  const MeshFindings g = check_mesh(m.V, m.F, m.N);
  EXPECT_EQ(f.summary(), g.summary());
  EXPECT_EQ(f.component_count, g.component_count);
  EXPECT_EQ(f.normals_compared_count, g.normals_compared_count);
  EXPECT_TRUE(same(vertex_normals(p, NormalWeighting::max),
                   vertex_normals(m.V, m.F, NormalWeighting::max)));
  EXPECT_EQ(orientation_report(p).inward_count(), orientation_report(m.V, m.F).inward_count());
  expect_same(estimate_curvature(p), estimate_curvature(m.V, m.F, m.N));
  CurvatureOptions two;
  two.rings = 2;
  two.weighting = RayWeighting::gaussian;
  expect_same(estimate_curvature(p, two), estimate_curvature(m.V, m.F, m.N, two));
  CurvatureOptions triangle;
  triangle.method = Method::triangle;
  expect_same(estimate_curvature(p, triangle), estimate_curvature(m.V, m.F, m.N, triangle));
  const TriangleCurvatureResult t = triangle_curvature(p), u = triangle_curvature(m.V, m.F, m.N);
  EXPECT_TRUE(same(t.K, u.K));
  EXPECT_TRUE(same(t.slit1, u.slit1));
  const RecommendedResult r = estimate_curvature_recommended(p);
  const RecommendedResult s = estimate_curvature_recommended(m.V, m.F, m.N);
  expect_same(r.curvature, s.curvature);
  EXPECT_TRUE(same(r.N, s.N));
  EXPECT_EQ(r.file_normals_used, s.file_normals_used);
  EXPECT_EQ(recommended_plan(p).noise, recommended_plan(m.V, m.F).noise);
  EXPECT_TRUE(same(jet_normals(p).N, jet_normals(m.V, m.F).N));
  expect_same(jet_curvature(p), jet_curvature(m.V, m.F));
  const FocalMeshes a = focal_meshes(p, r.curvature), b = focal_meshes(m.V, m.F, m.N, r.curvature);
  EXPECT_TRUE(same(a.gamma1.mesh.V, b.gamma1.mesh.V));
  EXPECT_TRUE(same(a.gamma2.mesh.V, b.gamma2.mesh.V));
  EXPECT_DOUBLE_EQ(p.mean_edge_length(), mean_edge_length(m.V, m.F));
  const Neighbourhoods& one = p.one_ring();
  const Neighbourhoods adjacency = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  EXPECT_EQ(one.offsets, adjacency.offsets);
  EXPECT_EQ(one.indices, adjacency.indices);
  EXPECT_EQ(&p.one_ring(), &one);  // kept
  // ... and the estimators use the kept 1-ring.
  expect_same(estimate_curvature(p), estimate_curvature(m.V, m.F, m.N));
}

TEST(PreparedMesh, SameResultForAnyThreadCount) {
  const Mesh m = noisy_torus();
  // Each PreparedMesh builds what it keeps on the thread count of the calls that need it.
  const PreparedMesh one(m), three(m);
  const auto on = [](int threads, const PreparedMesh& p) {
    const ExecutionScope scope({.threads = threads});
    return std::make_tuple(estimate_curvature(p), estimate_curvature_recommended(p).curvature,
                           check_mesh(p).normals_against_faces_count);
  };
  const auto [a1, b1, c1] = on(1, one);
  const auto [a3, b3, c3] = on(3, three);
  expect_same(a1, a3);
  expect_same(b1, b3);
  EXPECT_EQ(c1, c3);
}

TEST(PreparedMesh, WithNormalsSharesTheGeometry) {
  const Mesh m = noisy_torus();
  const PreparedMesh p(m.V, m.F);
  EXPECT_FALSE(p.has_normals());
  EXPECT_FALSE(p.normals().has_value());
  EXPECT_THROW((void)p.N(), InvalidInput);
  EXPECT_THROW((void)estimate_curvature(p), InvalidInput);
  EXPECT_THROW((void)focal_meshes(p, estimate_curvature(m.V, m.F, m.N)), InvalidInput);
  const Neighbourhoods& one = p.one_ring();
  const RowMatrixX3d max = vertex_normals(p, NormalWeighting::max);
  const PreparedMesh q = p.with_normals(max);
  EXPECT_TRUE(q.has_normals());
  EXPECT_EQ(&q.one_ring(), &one);
  EXPECT_EQ(q.N().data(), max.data());  // viewed, not copied
  expect_same(estimate_curvature(q), estimate_curvature(m.V, m.F, max));
  // Without normals the recommended estimator estimates its own.
  expect_same(estimate_curvature_recommended(p).curvature,
              estimate_curvature_recommended(m.V, m.F, std::nullopt).curvature);
  EXPECT_FALSE(q.with_normals(std::nullopt).has_normals());
}

TEST(PreparedMesh, RejectsBadArraysOnce) {
  const Mesh m = noisy_torus();
  EXPECT_THROW(PreparedMesh(m.V, m.F, m.N.topRows(10)), InvalidInput);
  // No normals is std::nullopt, not a matrix of 0 rows.
  EXPECT_THROW(PreparedMesh(m.V, m.F, RowMatrixX3d(0, 3)), InvalidInput);
  RowMatrixX3i F = m.F;
  F(5, 1) = static_cast<int>(m.V.rows());
  try {
    const PreparedMesh p(m.V, F);
    ADD_FAILURE() << "no exception";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("face 5 refers to vertex"), std::string::npos) << e.what();
  }
  const PreparedMesh p(m.V, m.F);
  EXPECT_THROW((void)p.with_normals(m.N.topRows(3)), InvalidInput);
  EXPECT_FALSE(Mesh{}.normals().has_value());
  EXPECT_TRUE(m.normals().has_value());
}

TEST(PreparedMesh, KeepsTheFindingsOfItsNormals) {
  Mesh m = noisy_torus();
  m.N.row(4).setZero();
  const PreparedMesh p(m);
  EXPECT_EQ(check_mesh(p).zero_normal_count, 1);
  EXPECT_EQ(check_mesh(p.with_normals(std::nullopt)).zero_normal_count, 0);
  EXPECT_EQ(check_mesh(p).zero_normal_count, 1);
}

// check_mesh builds the 1-ring in its topology pass and hands it on: the lists are those of
// vertex_adjacency, also with repeated indices, a bowtie vertex, an unreferenced vertex and an
// edge of three faces.
TEST(PreparedMesh, TheRingOfTheCheckIsTheOneRing) {
  RowMatrixX3d V(9, 3);
  for (int i = 0; i < 9; ++i) V.row(i) << i % 3, i / 3, (i * i) % 5;
  RowMatrixX3i F(9, 3);
  F << 0, 1, 2, 0, 2, 3, 0, 4, 5, 0, 5, 6, 1, 1, 2, 3, 2, 3, 0, 0, 0, 1, 2, 7, 1, 2, 4;
  Mesh odd;
  odd.V = V;
  odd.F = F;
  for (const Mesh& m : {odd, noisy_torus()}) {
    const Neighbourhoods expected =
        test::on_threads(1, [&] { return vertex_adjacency(static_cast<int>(m.V.rows()), m.F); });
    for (const int threads : {1, 2}) {
      const ExecutionScope scope({.threads = threads});
      const PreparedMesh p(m.V, m.F, std::nullopt, {});
      (void)check_mesh(p);
      const Neighbourhoods& ring = p.one_ring();
      EXPECT_EQ(ring.offsets, expected.offsets);
      EXPECT_EQ(ring.indices, expected.indices);
    }
  }
}

}  // namespace
}  // namespace focal
