#include "focal/mesh/neighbourhood.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

struct TestMesh {
  RowMatrixX3d V;
  RowMatrixX3i F;
};

std::vector<int> list(const Neighbourhoods& n, int v) { return {n.begin(v), n.end(v)}; }

std::vector<int> concat(std::vector<std::vector<int>> rings) {
  std::vector<int> out;
  for (const auto& r : rings) out.insert(out.end(), r.begin(), r.end());
  return out;
}

// nx x ny grid in the plane z = 0, vertex (i, j) at index i + nx j, each unit square split along
// its diagonal (i, j)-(i+1, j+1), counter-clockwise seen from +z.
TestMesh grid(int nx, int ny) {
  TestMesh m;
  m.V.resize(nx * ny, 3);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) m.V.row(i + nx * j) << i, j, 0;
  }
  m.F.resize(2 * (nx - 1) * (ny - 1), 3);
  int f = 0;
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = i + nx * j, b = a + 1, c = b + nx, d = a + nx;
      m.F.row(f++) << a, b, c;
      m.F.row(f++) << a, c, d;
    }
  }
  return m;
}

// Edge distance on `grid`: a step changes i, j or both by +1 together or both by -1 together.
int grid_distance(int nx, int v, int w) {
  const int di = w % nx - v % nx, dj = w / nx - v / nx;
  if ((di >= 0) == (dj >= 0) || di == 0 || dj == 0) return std::max(std::abs(di), std::abs(dj));
  return std::abs(di) + std::abs(dj);
}

// The k-ring of v on an nx x ny grid from the distance formula: an oracle independent of BFS.
std::vector<int> grid_k_ring(int nx, int ny, int v, int k) {
  std::vector<std::pair<int, int>> found;  // (distance, index)
  for (int w = 0; w < nx * ny; ++w) {
    const int d = grid_distance(nx, v, w);
    if (w != v && d <= k) found.emplace_back(d, w);
  }
  std::sort(found.begin(), found.end());
  std::vector<int> out;
  for (const auto& [d, w] : found) out.push_back(w);
  return out;
}

TestMesh tetrahedron() {
  TestMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.F.resize(4, 3);
  m.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return m;
}

// --- vertex_adjacency / k_ring -------------------------------------------------------------------

TEST(VertexAdjacency, SingleTriangle) {
  RowMatrixX3i F(1, 3);
  F << 0, 1, 2;
  const Neighbourhoods n = vertex_adjacency(3, F);
  ASSERT_EQ(n.vertex_count(), 3);
  EXPECT_EQ(list(n, 0), (std::vector<int>{1, 2}));
  EXPECT_EQ(list(n, 1), (std::vector<int>{0, 2}));
  EXPECT_EQ(list(n, 2), (std::vector<int>{0, 1}));
  const Neighbourhoods two = k_ring(n, 2);
  for (int v = 0; v < 3; ++v) EXPECT_EQ(list(two, v), list(n, v));
}

TEST(VertexAdjacency, TetrahedronAndUnreferencedVertex) {
  const TestMesh m = tetrahedron();
  const Neighbourhoods n = vertex_adjacency(5, m.F);  // vertex 4 is in no face
  ASSERT_EQ(n.vertex_count(), 5);
  EXPECT_EQ(list(n, 0), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(list(n, 1), (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(list(n, 2), (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(list(n, 3), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(n.size(4), 0);
  const Neighbourhoods three = k_ring(n, 3);
  EXPECT_EQ(three.offsets, n.offsets);
  EXPECT_EQ(three.indices, n.indices);
}

// Strip of three squares: bottom row 0 1 2 3, top row 4 5 6 7.
TEST(VertexAdjacency, StripRingsInOrder) {
  RowMatrixX3i F(6, 3);
  F << 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6;
  const Neighbourhoods n = vertex_adjacency(8, F);
  EXPECT_EQ(list(n, 0), (std::vector<int>{1, 4, 5}));
  EXPECT_EQ(list(n, 1), (std::vector<int>{0, 2, 5, 6}));
  EXPECT_EQ(list(n, 5), (std::vector<int>{0, 1, 4, 6}));
  EXPECT_EQ(list(n, 7), (std::vector<int>{2, 3, 6}));
  EXPECT_EQ(list(k_ring(n, 2), 0), (std::vector<int>{1, 4, 5, 2, 6}));
  EXPECT_EQ(list(k_ring(n, 3), 0), (std::vector<int>{1, 4, 5, 2, 6, 3, 7}));
  EXPECT_EQ(list(k_ring(n, 2), 4), (std::vector<int>{0, 5, 1, 6}));
}

// 5 x 5 grid, vertex (i, j) = i + 5 j. Lists worked out by hand: ring by ring, ascending.
TEST(VertexAdjacency, GridRingsByHand) {
  const TestMesh m = grid(5, 5);
  const Neighbourhoods one = vertex_adjacency(25, m.F);
  const focal::Neighbourhoods two = focal::k_ring(one, 2);
  const Neighbourhoods three = k_ring(one, 3);
  // Centre (2, 2).
  const std::vector<int> c1{6, 7, 11, 13, 17, 18};
  const std::vector<int> c2{0, 1, 2, 5, 8, 10, 14, 16, 19, 22, 23, 24};
  const std::vector<int> c3{3, 9, 15, 21};
  EXPECT_EQ(list(one, 12), c1);
  EXPECT_EQ(list(two, 12), concat({c1, c2}));
  EXPECT_EQ(list(three, 12), concat({c1, c2, c3}));
  // Corner (0, 0), on the split diagonal.
  EXPECT_EQ(list(one, 0), (std::vector<int>{1, 5, 6}));
  EXPECT_EQ(list(two, 0), (std::vector<int>{1, 5, 6, 2, 7, 10, 11, 12}));
  EXPECT_EQ(list(three, 0),
            (std::vector<int>{1, 5, 6, 2, 7, 10, 11, 12, 3, 8, 13, 15, 16, 17, 18}));
  // Corner (4, 0), off the diagonals.
  EXPECT_EQ(list(one, 4), (std::vector<int>{3, 9}));
  EXPECT_EQ(list(two, 4), (std::vector<int>{3, 9, 2, 8, 14}));
  EXPECT_EQ(list(three, 4), (std::vector<int>{3, 9, 2, 8, 14, 1, 7, 13, 19}));
}

// Every vertex of grids small and large (the large one runs the parallel path: more vertices than
// parallel_for's serial cutoff) against the distance-formula oracle.
TEST(VertexAdjacency, GridRingsMatchDistanceOracle) {
  for (const auto& [nx, ny, k_max] :
       {std::tuple{5, 5, 4}, std::tuple{7, 4, 3}, std::tuple{40, 30, 3}}) {
    const TestMesh m = grid(nx, ny);
    const Neighbourhoods one = vertex_adjacency(nx * ny, m.F);
    for (int k = 1; k <= k_max; ++k) {
      const Neighbourhoods ring = k_ring(one, k);
      ASSERT_EQ(ring.vertex_count(), nx * ny);
      for (int v = 0; v < nx * ny; ++v) {
        ASSERT_EQ(list(ring, v), grid_k_ring(nx, ny, v, k))
            << nx << "x" << ny << " k " << k << " vertex " << v;
      }
    }
  }
}

TEST(VertexAdjacency, BitwiseIdenticalForAnyThreadCount) {
  const TestMesh m = grid(60, 50);
  Neighbourhoods one_a, one_b, ring_a, ring_b;
  test::on_threads(1, [&] {
    one_a = vertex_adjacency(3000, m.F);
    ring_a = k_ring(one_a, 3);
  });
  test::on_threads(3, [&] {
    one_b = vertex_adjacency(3000, m.F);
    ring_b = k_ring(one_b, 3);
  });
  EXPECT_EQ(one_a.offsets, one_b.offsets);
  EXPECT_EQ(one_a.indices, one_b.indices);
  EXPECT_EQ(ring_a.offsets, ring_b.offsets);
  EXPECT_EQ(ring_a.indices, ring_b.indices);
}

TEST(VertexAdjacency, NonManifoldEdgeAndRepeatedIndicesAreAccepted) {
  RowMatrixX3i F(5, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4,  // three faces on edge 0-1
      5, 5, 6,                     // repeated index: an edge 5-6, no self-loop
      2, 2, 2;                     // a single vertex: no edge at all
  const Neighbourhoods n = vertex_adjacency(7, F);
  EXPECT_EQ(list(n, 0), (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(list(n, 1), (std::vector<int>{0, 2, 3, 4}));
  EXPECT_EQ(list(n, 2), (std::vector<int>{0, 1}));
  EXPECT_EQ(list(n, 3), (std::vector<int>{0, 1}));
  EXPECT_EQ(list(n, 5), (std::vector<int>{6}));
  EXPECT_EQ(list(n, 6), (std::vector<int>{5}));
  EXPECT_EQ(list(k_ring(n, 2), 2), (std::vector<int>{0, 1, 3, 4}));
}

TEST(VertexAdjacency, EmptyInputs) {
  const Neighbourhoods none = vertex_adjacency(0, RowMatrixX3i(0, 3));
  EXPECT_EQ(none.vertex_count(), 0);
  EXPECT_EQ(k_ring(none, 2).vertex_count(), 0);
  const Neighbourhoods isolated = vertex_adjacency(3, RowMatrixX3i(0, 3));
  EXPECT_EQ(isolated.vertex_count(), 3);
  EXPECT_EQ(k_ring(isolated, 2).indices.size(), 0);
}

TEST(VertexAdjacency, ErrorsAreReported) {
  RowMatrixX3i F(2, 3);
  F << 0, 1, 2, 2, 1, 3;
  EXPECT_THROW((void)vertex_adjacency(3, F), InvalidInput);  // index 3 of 3 vertices
  EXPECT_THROW((void)vertex_adjacency(-1, RowMatrixX3i(0, 3)), InvalidInput);
  F(1, 2) = -1;
  EXPECT_THROW((void)vertex_adjacency(4, F), InvalidInput);
}

TEST(KRing, ErrorsAreReported) {
  const TestMesh m = tetrahedron();
  const Neighbourhoods n = vertex_adjacency(4, m.F);
  EXPECT_THROW((void)k_ring(n, 0), InvalidInput);
  EXPECT_THROW((void)k_ring(n, -3), InvalidInput);
  EXPECT_THROW((void)k_ring(Neighbourhoods{}, 2), InvalidInput);  // no offsets at all
  Neighbourhoods bad = n;
  bad.indices[2] = 4;  // outside [0, 4)
  EXPECT_THROW((void)k_ring(bad, 2), InvalidInput);
  bad = n;
  bad.offsets[4] += 1;  // does not end at indices.size()
  EXPECT_THROW((void)k_ring(bad, 2), InvalidInput);
  bad = n;
  std::swap(bad.offsets[1], bad.offsets[2]);  // decreasing
  EXPECT_THROW((void)k_ring(bad, 2), InvalidInput);
}

// --- boundary_vertices / rings_to_boundary ------------------------------------------------------

TEST(BoundaryVertices, GridBorderOnly) {
  const TestMesh m = grid(5, 5);
  const std::vector<bool> b = boundary_vertices(25, m.F);
  ASSERT_EQ(b.size(), 25u);
  for (int v = 0; v < 25; ++v) {
    const int i = v % 5, j = v / 5;
    EXPECT_EQ(b[static_cast<std::size_t>(v)], i == 0 || j == 0 || i == 4 || j == 4) << v;
  }
}

TEST(BoundaryVertices, ClosedAndNonManifold) {
  EXPECT_EQ(boundary_vertices(5, tetrahedron().F), std::vector<bool>(5, false));
  // Three faces on edge 0-1: that edge is non-manifold, not boundary, but every referenced vertex
  // is also on a boundary edge (0-2, 1-3, ...); vertex 5 is in no face.
  RowMatrixX3i F(3, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  EXPECT_EQ(boundary_vertices(6, F), (std::vector<bool>{true, true, true, true, true, false}));
  EXPECT_THROW((void)boundary_vertices(4, F), InvalidInput);
  EXPECT_THROW((void)boundary_vertices(-2, RowMatrixX3i(0, 3)), InvalidInput);
}

// On the 7 x 7 grid the distance to the border is min(i, j, 6 - i, 6 - j): each step moves i and
// j by at most one, and the straight path towards the nearest side achieves it.
TEST(RingsToBoundary, GridValuesAndCap) {
  const TestMesh m = grid(7, 7);
  const Neighbourhoods one = vertex_adjacency(49, m.F);
  const std::vector<bool> b = boundary_vertices(49, m.F);
  for (const int max_rings : {0, 1, 2, 3, 10}) {
    const Eigen::VectorXi r = rings_to_boundary(one, b, max_rings);
    ASSERT_EQ(r.size(), 49);
    for (int v = 0; v < 49; ++v) {
      const int i = v % 7, j = v / 7;
      const int d = std::min({i, j, 6 - i, 6 - j});
      EXPECT_EQ(r[v], std::min(d, max_rings + 1)) << "vertex " << v << " max_rings " << max_rings;
    }
  }
}

TEST(RingsToBoundary, ClosedComponentGetsTheCap) {
  const TestMesh m = tetrahedron();
  const Neighbourhoods one = vertex_adjacency(4, m.F);
  EXPECT_EQ(rings_to_boundary(one, boundary_vertices(4, m.F), 5), Eigen::VectorXi::Constant(4, 6));
}

TEST(RingsToBoundary, ErrorsAreReported) {
  const TestMesh m = grid(3, 3);
  const Neighbourhoods one = vertex_adjacency(9, m.F);
  const std::vector<bool> b = boundary_vertices(9, m.F);
  EXPECT_THROW((void)rings_to_boundary(one, std::vector<bool>(8, false), 2), InvalidInput);
  EXPECT_THROW((void)rings_to_boundary(one, b, -1), InvalidInput);
  EXPECT_THROW((void)rings_to_boundary(Neighbourhoods{}, {}, 2), InvalidInput);
}

// --- mesh_statistics ----------------------------------------------------------------------------

TEST(MeshStatistics, ClosedTetrahedron) {
  const TestMesh m = tetrahedron();
  const MeshStatistics s = mesh_statistics(m.V, m.F);
  EXPECT_EQ(s.vertex_count, 4);
  EXPECT_EQ(s.face_count, 4);
  EXPECT_EQ(s.edge_count, 6);
  EXPECT_EQ(s.boundary_edge_count, 0);
  EXPECT_EQ(s.non_manifold_edge_count, 0);
  EXPECT_EQ(s.non_manifold_vertex_count, 0);
  EXPECT_EQ(s.unreferenced_vertex_count, 0);
  EXPECT_EQ(s.degenerate_face_count, 0);
  EXPECT_EQ(s.duplicate_face_count, 0);
  EXPECT_EQ(s.component_count, 1);
  EXPECT_EQ(s.min_corner, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(s.max_corner, Eigen::Vector3d(1, 1, 1));
  // Three edges of length 1 and three of sqrt 2, each in two faces.
  EXPECT_NEAR(s.mean_edge_length, (3.0 + 3.0 * std::sqrt(2.0)) / 6.0, 1e-15);
}

TEST(MeshStatistics, GridCounts) {
  const TestMesh m = grid(5, 4);
  const MeshStatistics s = mesh_statistics(m.V, m.F);
  EXPECT_EQ(s.vertex_count, 20);
  EXPECT_EQ(s.face_count, 24);
  EXPECT_EQ(s.edge_count, 4 * 4 + 5 * 3 + 4 * 3);  // horizontal, vertical, diagonal
  EXPECT_EQ(s.boundary_edge_count, 2 * 4 + 2 * 3);
  EXPECT_EQ(s.non_manifold_edge_count, 0);
  EXPECT_EQ(s.non_manifold_vertex_count, 0);
  EXPECT_EQ(s.component_count, 1);
  EXPECT_EQ(s.max_corner, Eigen::Vector3d(4, 3, 0));
}

// Two open cones (three faces each) whose apexes are the same vertex 0: one component, and
// vertex 0's faces form two fans that share no edge.
TEST(MeshStatistics, BowtieVertexIsNonManifold) {
  RowMatrixX3d V(7, 3);
  V << 0, 0, 0, 1, 0, 1, -1, 1, 1, -1, -1, 1, 1, 0, -1, -1, 1, -1, -1, -1, -1;
  RowMatrixX3i F(6, 3);
  F << 0, 1, 2, 0, 2, 3, 0, 3, 1,  // upper cone
      0, 5, 4, 0, 6, 5, 0, 4, 6;   // lower cone
  const MeshStatistics s = mesh_statistics(V, F);
  EXPECT_EQ(s.edge_count, 12);
  EXPECT_EQ(s.boundary_edge_count, 6);  // the rims
  EXPECT_EQ(s.non_manifold_edge_count, 0);
  EXPECT_EQ(s.non_manifold_vertex_count, 1);
  EXPECT_EQ(s.component_count, 1);
  EXPECT_EQ(s.degenerate_face_count, 0);
  EXPECT_EQ(s.duplicate_face_count, 0);
}

TEST(MeshStatistics, NonManifoldEdgeIsNotANonManifoldVertex) {
  RowMatrixX3d V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  RowMatrixX3i F(3, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  const MeshStatistics s = mesh_statistics(V, F);
  EXPECT_EQ(s.edge_count, 7);
  EXPECT_EQ(s.boundary_edge_count, 6);
  EXPECT_EQ(s.non_manifold_edge_count, 1);
  EXPECT_EQ(s.non_manifold_vertex_count, 0);  // the three faces at 0 are linked by edge 0-1
}

TEST(MeshStatistics, DuplicateDegenerateUnreferencedAndComponents) {
  const TestMesh t = tetrahedron();
  RowMatrixX3d V(11, 3);
  V << t.V,                                         // 0-3: tetrahedron
      t.V.rowwise() + Eigen::RowVector3d(5, 0, 0),  // 4-7: a second one
      9, 9, 9,                                      // 8: unreferenced
      0, 0, 2, 0, 0, 4;                             // 9, 10: collinear with vertex 0
  RowMatrixX3i F(14, 3);
  F << t.F, (t.F.array() + 4).matrix(),  //
      2, 1, 0,                           // same vertex set as face 0, other order: duplicate
      1, 0, 2,                           // and again: second duplicate
      0, 9, 10,                          // zero area: degenerate, a third component
      6, 6, 7,                           // repeated index: degenerate
      5, 6, 7,                           // a third duplicate of the second tetrahedron's face
      7, 6, 5;                           // same set, reversed: a fourth duplicate
  const MeshStatistics s = mesh_statistics(V, F);
  EXPECT_EQ(s.vertex_count, 11);
  EXPECT_EQ(s.face_count, 14);
  EXPECT_EQ(s.duplicate_face_count, 4);
  EXPECT_EQ(s.degenerate_face_count, 2);
  EXPECT_EQ(s.unreferenced_vertex_count, 1);
  EXPECT_EQ(s.component_count, 2);  // the zero-area face shares vertex 0 with the first
  EXPECT_EQ(s.min_corner, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(s.max_corner, Eigen::Vector3d(9, 9, 9));
}

// The zero-area test is relative to the triangle's size: tiny well-shaped faces are fine, thin
// ones of any size are degenerate once |cross| <= 1e-14 longest^2.
TEST(MeshStatistics, DegenerateAreaThresholdIsRelative) {
  RowMatrixX3d V(9, 3);
  V << 0, 0, 0, 1e-9, 0, 0, 0, 1e-9, 0,  // tiny right triangle: valid
      0, 0, 0, 1e6, 0, 0, 5e5, 1e-5, 0,  // |cross| / L^2 = 1e-11: valid
      0, 0, 0, 1e6, 0, 0, 5e5, 1e-9, 0;  // |cross| / L^2 = 1e-15: degenerate
  RowMatrixX3i F(3, 3);
  F << 0, 1, 2, 3, 4, 5, 6, 7, 8;
  EXPECT_EQ(mesh_statistics(V, F).degenerate_face_count, 1);
}

TEST(MeshStatistics, EmptyMeshAndErrors) {
  const MeshStatistics s = mesh_statistics(RowMatrixX3d(0, 3), RowMatrixX3i(0, 3));
  EXPECT_EQ(s.vertex_count, 0);
  EXPECT_EQ(s.edge_count, 0);
  EXPECT_EQ(s.component_count, 0);
  EXPECT_EQ(s.mean_edge_length, 0.0);
  const TestMesh m = tetrahedron();
  RowMatrixX3i F = m.F;
  F(1, 1) = 4;
  EXPECT_THROW((void)mesh_statistics(m.V, F), InvalidInput);
}

}  // namespace
}  // namespace focal

// Issue 13 item 3: one polygon of n corners, fan-triangulated as the readers do: the hub
// neighbours every corner, so every 2-ring holds all n - 1 other vertices. Above the cap the
// k-ring is empty and crowded_vertices() names every vertex; 1-rings are never capped.
TEST(KRing, NeighbourhoodsAboveTheCapAreEmptyAndNamed) {
  const int n = 3 * focal::kMaxNeighbourhoodSize;
  focal::RowMatrixX3i F(n - 2, 3);
  for (int k = 0; k < n - 2; ++k) F.row(k) << 0, k + 1, k + 2;
  const focal::Neighbourhoods one = focal::vertex_adjacency(n, F);
  EXPECT_EQ(one.size(0), n - 1);  // the hub's 1-ring, kept whole
  const focal::Neighbourhoods two = focal::k_ring(one, 2);
  for (int v = 0; v < n; ++v) EXPECT_EQ(two.size(v), 0) << "vertex " << v;
  const std::vector<int> crowded = focal::crowded_vertices(one, 2);
  ASSERT_EQ(crowded.size(), static_cast<std::size_t>(n));
  EXPECT_EQ(crowded.front(), 0);
  EXPECT_EQ(crowded.back(), n - 1);
  EXPECT_TRUE(focal::crowded_vertices(one, 1).empty());

  // Just below the cap nothing changes: the 2-ring of a corner is every other vertex.
  const int m = focal::kMaxNeighbourhoodSize + 1;
  focal::RowMatrixX3i G(m - 2, 3);
  for (int k = 0; k < m - 2; ++k) G.row(k) << 0, k + 1, k + 2;
  const focal::Neighbourhoods small = focal::k_ring(focal::vertex_adjacency(m, G), 2);
  for (int v = 0; v < m; ++v) EXPECT_EQ(small.size(v), m - 1) << "vertex " << v;
  EXPECT_TRUE(focal::crowded_vertices(focal::vertex_adjacency(m, G), 2).empty());
}
