#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/mesh/orientation.h"
#include "focal/normals/vertex_normals.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

struct TestMesh {
  RowMatrixX3d V;
  RowMatrixX3i F;
};

constexpr NormalWeighting kAllWeightings[] = {NormalWeighting::area, NormalWeighting::angle,
                                              NormalWeighting::max};

// Faces of a convex polyhedron whose edges all have length `edge`: every triple of mutually
// adjacent vertices, turned counter-clockwise seen from outside (the origin is inside).
RowMatrixX3i convex_faces(const RowMatrixX3d& V, double edge) {
  const auto adjacent = [&](int a, int b) {
    return std::abs((V.row(a) - V.row(b)).norm() - edge) < 1e-9;
  };
  std::vector<std::array<int, 3>> faces;
  const int n = static_cast<int>(V.rows());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      for (int c = b + 1; c < n; ++c) {
        if (!adjacent(a, b) || !adjacent(b, c) || !adjacent(a, c)) continue;
        const Eigen::Vector3d normal = (V.row(b) - V.row(a)).cross(V.row(c) - V.row(a));
        if (normal.dot(V.row(a)) > 0) {
          faces.push_back({a, b, c});
        } else {
          faces.push_back({a, c, b});
        }
      }
    }
  }
  RowMatrixX3i F(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) F(static_cast<Eigen::Index>(f), k) = faces[f][k];
  }
  return F;
}

// Regular octahedron with vertices +-e_i (volume 4/3).
TestMesh octahedron() {
  TestMesh m;
  m.V.resize(6, 3);
  m.V << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  m.F = convex_faces(m.V, std::sqrt(2.0));
  return m;
}

// Regular icosahedron with vertices (0, +-1, +-phi) and cyclic permutations (edge length 2).
TestMesh icosahedron() {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  TestMesh m;
  m.V.resize(12, 3);
  int i = 0;
  for (const double s : {-1.0, 1.0}) {
    for (const double t : {-phi, phi}) {
      m.V.row(i++) << 0, s, t;
      m.V.row(i++) << s, t, 0;
      m.V.row(i++) << t, 0, s;
    }
  }
  m.F = convex_faces(m.V, 2.0);
  return m;
}

// Splits every triangle into four at its edge midpoints (shared midpoints are one vertex).
TestMesh subdivide(const TestMesh& in) {
  std::vector<Eigen::Vector3d> points;
  for (Eigen::Index v = 0; v < in.V.rows(); ++v) points.push_back(in.V.row(v).transpose());
  std::map<std::pair<int, int>, int> midpoint;
  const auto mid = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    points.push_back((points[static_cast<std::size_t>(a)] + points[static_cast<std::size_t>(b)]) /
                     2.0);
    const int index = static_cast<int>(points.size()) - 1;
    midpoint.emplace(key, index);
    return index;
  };
  TestMesh out;
  out.F.resize(4 * in.F.rows(), 3);
  for (Eigen::Index f = 0; f < in.F.rows(); ++f) {
    const int a = in.F(f, 0), b = in.F(f, 1), c = in.F(f, 2);
    const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  out.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t v = 0; v < points.size(); ++v) {
    out.V.row(static_cast<Eigen::Index>(v)) = points[v].transpose();
  }
  return out;
}

// An irregularly sampled sphere: a subdivided icosahedron whose vertices are moved by random
// tangential offsets of up to `jitter` times the mean edge length, then projected back onto the
// sphere with the given centre and radius.
TestMesh jittered_sphere(int levels, const Eigen::Vector3d& centre, double radius, double jitter,
                         unsigned seed) {
  TestMesh m = icosahedron();
  for (int l = 0; l < levels; ++l) m = subdivide(m);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v).normalize();
  const double h = mean_edge_length(m.V, m.F);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const Eigen::Vector3d offset(uniform(rng), uniform(rng), uniform(rng));
    const Eigen::Vector3d moved = m.V.row(v).transpose() + jitter * h * offset;
    m.V.row(v) = (centre + radius * moved.normalized()).transpose();
  }
  return m;
}

// Unit cube [0,1]^3, vertex x + 2y + 4z, each square split along the diagonal through its first
// listed corner. Corners 0 and 7 touch both triangles of all three squares; corner 1 touches both
// triangles of its x = 1 square but only one of its y = 0 and z = 0 squares.
TestMesh cube() {
  TestMesh m;
  m.V.resize(8, 3);
  for (int v = 0; v < 8; ++v) m.V.row(v) << (v & 1), ((v >> 1) & 1), ((v >> 2) & 1);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  m.F.resize(12, 3);
  for (int q = 0; q < 6; ++q) {
    m.F.row(2 * q) << quads[q][0], quads[q][1], quads[q][2];
    m.F.row(2 * q + 1) << quads[q][0], quads[q][2], quads[q][3];
  }
  return m;
}

RowMatrixX3i flipped(const RowMatrixX3i& F) {
  RowMatrixX3i out = F;
  out.col(1).swap(out.col(2));
  return out;
}

// Stacks two meshes into one (vertex indices of the second shifted).
TestMesh join(const TestMesh& a, const TestMesh& b) {
  TestMesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return m;
}

// --- vertex_normals -------------------------------------------------------------------------

// By symmetry every weighting gives the radial direction at a vertex of a regular polyhedron.
// The sums involve a handful of rounded terms of size ~1, so a few ulps (1e-14) bound the error.
TEST(VertexNormals, RegularPolyhedraGiveRadialNormalsForEveryWeighting) {
  for (const TestMesh& m : {octahedron(), icosahedron()}) {
    ASSERT_EQ(m.F.rows(), m.V.rows() == 6 ? 8 : 20);
    for (const auto weighting : kAllWeightings) {
      const RowMatrixX3d N = vertex_normals(m.V, m.F, weighting);
      for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
        EXPECT_LT((N.row(v) - m.V.row(v).normalized()).norm(), 1e-14)
            << "vertex " << v << " weighting " << static_cast<int>(weighting);
      }
    }
  }
}

// Max's weights are exact for a vertex whose neighbours lie on a common sphere, however irregular
// the sampling; area weights are only first-order accurate in h / R on irregular samplings. The
// sphere has h / R ~ 0.13 (icosahedron subdivided 3 times) and vertices jittered by up to 30% of an
// edge, so area weights err by O(h / R) at the worst vertex (0.10 measured; checked > 1e-2), while
// Max's error is rounding only: ~6 terms of relative error ~1e-16 each (3e-15 measured), bounded
// here by 1e-12.
TEST(VertexNormals, MaxWeightsAreExactOnAnIrregularlySampledSphere) {
  const Eigen::Vector3d centre(0.3, -0.2, 0.5);
  const double radius = 2.0;
  const TestMesh m = jittered_sphere(3, centre, radius, 0.3, 7);
  ASSERT_EQ(m.V.rows(), 642);
  // Precondition: the jitter kept every triangle outward-facing (no fold-over).
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    ASSERT_GT((b - a).cross(c - a).dot(a - centre), 0.0) << "face " << f;
  }
  const RowMatrixX3d max_n = vertex_normals(m.V, m.F, NormalWeighting::max);
  const RowMatrixX3d area_n = vertex_normals(m.V, m.F, NormalWeighting::area);
  double max_error = 0.0, area_error = 0.0;
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const Eigen::RowVector3d exact = (m.V.row(v) - centre.transpose()) / radius;
    max_error = std::max(max_error, (max_n.row(v) - exact).norm());
    area_error = std::max(area_error, (area_n.row(v) - exact).norm());
  }
  EXPECT_LT(max_error, 1e-12);
  EXPECT_GT(area_error, 1e-2);
}

// At a cube corner the three squares meet at right angles. Angle weights give each square pi/2
// and Max weights give each square 1 (sin 90 / 1 unsplit, or 2 x sin 45 / sqrt 2 split), however
// the squares are triangulated, so both are exactly the diagonal. Area weights count a square
// once or twice depending on its diagonal: at corner 1 they give (2, -1, -1) / sqrt 6.
TEST(VertexNormals, CubeCorner) {
  const TestMesh m = cube();
  for (const auto weighting : {NormalWeighting::angle, NormalWeighting::max}) {
    const RowMatrixX3d N = vertex_normals(m.V, m.F, weighting);
    for (int v = 0; v < 8; ++v) {
      const Eigen::RowVector3d outward =
          (m.V.row(v) - Eigen::RowVector3d::Constant(0.5)).normalized();
      EXPECT_LT((N.row(v) - outward).norm(), 1e-14) << "corner " << v;
    }
  }
  const RowMatrixX3d area_n = vertex_normals(m.V, m.F, NormalWeighting::area);
  EXPECT_LT((area_n.row(1) - Eigen::RowVector3d(2, -1, -1) / std::sqrt(6.0)).norm(), 1e-14);
  EXPECT_LT((area_n.row(0) - Eigen::RowVector3d(-1, -1, -1) / std::sqrt(3.0)).norm(), 1e-14);
}

TEST(VertexNormals, IsolatedAndDegenerateOnlyVerticesGetNaNRows) {
  // Triangle 0-1-2 in the plane z = 0, vertex 3 on edge 0-1 (in a zero-area face only), vertex 4
  // in a face with a repeated index only, vertex 5 in no face.
  RowMatrixX3d V(6, 3);
  V << 0, 0, 0, 2, 0, 0, 0, 1, 0, 1, 0, 0, 5, 5, 5, 7, 7, 7;
  RowMatrixX3i F(4, 3);
  F << 0, 1, 2,  //
      0, 3, 1,   // collinear: zero area
      2, 2, 4,   // repeated index
      4, 0, 4;   // repeated index
  for (const auto weighting : kAllWeightings) {
    const RowMatrixX3d N = vertex_normals(V, F, weighting);
    // The degenerate faces must not tilt the normals of the valid triangle: exact (0, 0, 1).
    for (int v = 0; v < 3; ++v) {
      EXPECT_EQ(N.row(v), Eigen::RowVector3d(0, 0, 1)) << "vertex " << v;
    }
    for (int v = 3; v < 6; ++v) {
      EXPECT_TRUE(N.row(v).array().isNaN().all()) << "vertex " << v;
    }
  }
}

TEST(VertexNormals, CancellingFacesGiveNaNNotZero) {
  RowMatrixX3d V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  RowMatrixX3i F(2, 3);
  F << 0, 1, 2, 0, 2, 1;  // the same triangle twice, opposite orientations
  for (const auto weighting : kAllWeightings) {
    const RowMatrixX3d N = vertex_normals(V, F, weighting);
    EXPECT_TRUE(N.array().isNaN().all());
  }
}

// The degeneracy threshold is relative to the triangle's size: a well-shaped triangle of size
// 1e-10 (area 5e-21) is valid and gets its exact normal.
TEST(VertexNormals, TinyWellShapedTriangleIsNotDegenerate) {
  RowMatrixX3d V(3, 3);
  V << 0, 0, 0, 0, 1e-10, 0, 0, 0, 1e-10;
  RowMatrixX3i F(1, 3);
  F << 0, 1, 2;
  for (const auto weighting : kAllWeightings) {
    const RowMatrixX3d N = vertex_normals(V, F, weighting);
    for (int v = 0; v < 3; ++v) EXPECT_EQ(N.row(v), Eigen::RowVector3d(1, 0, 0));
  }
}

TEST(VertexNormals, OutOfRangeIndexThrows) {
  const TestMesh m = octahedron();
  RowMatrixX3i F = m.F;
  F(3, 1) = 6;
  EXPECT_THROW((void)vertex_normals(m.V, F), InvalidInput);
  F(3, 1) = -1;
  EXPECT_THROW((void)vertex_normals(m.V, F, NormalWeighting::max), InvalidInput);
}

TEST(VertexNormals, EmptyMeshGivesEmptyResult) {
  EXPECT_EQ(vertex_normals(RowMatrixX3d(0, 3), RowMatrixX3i(0, 3)).rows(), 0);
}

// Every vertex sums its faces in ascending order whatever thread computes it, so results are
// bitwise equal across thread counts (the mesh has more vertices than the parallel cutoff).
TEST(VertexNormals, BitwiseIdenticalForAnyThreadCount) {
  const TestMesh m = jittered_sphere(4, Eigen::Vector3d::Zero(), 1.0, 0.3, 11);
  ASSERT_GT(m.V.rows(), 2048);
  for (const auto weighting : kAllWeightings) {
    const auto run = [&] { return vertex_normals(m.V, m.F, weighting); };
    const RowMatrixX3d one = test::on_threads(1, run);
    const RowMatrixX3d three = test::on_threads(3, run);
    EXPECT_TRUE((one.array() == three.array()).all());
  }
}

// --- orientation_report / orient_outward ------------------------------------------------------

TEST(Orientation, ClosedOutwardMesh) {
  const TestMesh m = octahedron();
  const OrientationReport r = orientation_report(m.V, m.F);
  ASSERT_EQ(r.components.size(), 1u);
  const auto& c = r.components[0];
  EXPECT_EQ(c.face_count, 8);
  EXPECT_EQ(c.vertex_count, 6);
  EXPECT_TRUE(c.closed);
  EXPECT_TRUE(c.consistent);
  EXPECT_NEAR(c.signed_volume, 4.0 / 3.0, 1e-15);  // 8 exact tetrahedra of volume 1/6
  EXPECT_FALSE(c.inward);
  EXPECT_EQ(r.inward_count(), 0);
  EXPECT_TRUE((r.face_component.array() == 0).all());
  EXPECT_EQ(orient_outward(m.F, r), m.F);
}

TEST(Orientation, FlippedClosedMeshIsInwardAndOrientOutwardFixesIt) {
  const TestMesh m = icosahedron();
  const RowMatrixX3i F = flipped(m.F);
  const OrientationReport r = orientation_report(m.V, F);
  ASSERT_EQ(r.components.size(), 1u);
  EXPECT_TRUE(r.components[0].closed);
  EXPECT_TRUE(r.components[0].consistent);
  EXPECT_LT(r.components[0].signed_volume, 0.0);
  EXPECT_TRUE(r.components[0].inward);
  EXPECT_EQ(r.inward_count(), 1);

  const RowMatrixX3i fixed = orient_outward(F, r);
  const OrientationReport after = orientation_report(m.V, fixed);
  EXPECT_FALSE(after.components[0].inward);
  EXPECT_NEAR(after.components[0].signed_volume, -r.components[0].signed_volume, 1e-13);
  // Normals from the fixed faces point away from the centre.
  const RowMatrixX3d N = vertex_normals(m.V, fixed);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) EXPECT_GT(N.row(v).dot(m.V.row(v)), 0.0);
}

// Far from the origin the raw determinants are ~1e18 and cancel; about the centroid they do not.
// Exact volume 4/3; 1e-12 allows rounding of the translated coordinates (1e6 + 1 ~ 1e-10 ulps).
TEST(Orientation, SignedVolumeIsAccurateFarFromTheOrigin) {
  TestMesh m = octahedron();
  m.V.rowwise() += Eigen::RowVector3d(1e6, -2e6, 3e6);
  const OrientationReport r = orientation_report(m.V, m.F);
  EXPECT_NEAR(r.components[0].signed_volume, 4.0 / 3.0, 1e-12);
}

TEST(Orientation, TwoComponentsWithOneFlippedAreReportedSeparately) {
  TestMesh ico = icosahedron();
  ico.V.rowwise() += Eigen::RowVector3d(10, 0, 0);
  ico.F = flipped(ico.F);
  const TestMesh m = join(octahedron(), ico);
  const OrientationReport r = orientation_report(m.V, m.F);
  ASSERT_EQ(r.components.size(), 2u);
  EXPECT_EQ(r.components[0].face_count, 8);
  EXPECT_EQ(r.components[0].vertex_count, 6);
  EXPECT_FALSE(r.components[0].inward);
  EXPECT_EQ(r.components[1].face_count, 20);
  EXPECT_EQ(r.components[1].vertex_count, 12);
  EXPECT_TRUE(r.components[1].inward);
  EXPECT_EQ(r.inward_count(), 1);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) EXPECT_EQ(r.face_component[f], f < 8 ? 0 : 1);

  const RowMatrixX3i fixed = orient_outward(m.F, r);
  EXPECT_EQ(fixed.topRows(8), m.F.topRows(8));
  EXPECT_EQ(fixed.bottomRows(20), flipped(m.F.bottomRows(20)));
  EXPECT_EQ(orientation_report(m.V, fixed).inward_count(), 0);
}

TEST(Orientation, OpenPatchIsNeverInward) {
  const TestMesh m = octahedron();
  const RowMatrixX3i open = m.F.topRows(7);
  for (const RowMatrixX3i& F : {open, flipped(open)}) {
    const OrientationReport r = orientation_report(m.V, F);
    ASSERT_EQ(r.components.size(), 1u);
    EXPECT_FALSE(r.components[0].closed);
    EXPECT_TRUE(r.components[0].consistent);
    EXPECT_FALSE(r.components[0].inward);
    EXPECT_EQ(orient_outward(F, r), F);
  }
}

TEST(Orientation, InconsistentMeshIsDetectedAndNotInward) {
  const TestMesh m = octahedron();
  RowMatrixX3i F = flipped(m.F);
  std::swap(F(0, 1), F(0, 2));  // one face back: 7 inward faces and 1 outward
  const OrientationReport r = orientation_report(m.V, F);
  ASSERT_EQ(r.components.size(), 1u);
  EXPECT_TRUE(r.components[0].closed);
  EXPECT_FALSE(r.components[0].consistent);
  EXPECT_LT(r.components[0].signed_volume, 0.0);
  EXPECT_FALSE(r.components[0].inward);
}

// Components are vertex-connected: two tetrahedra sharing only a vertex form one component.
TEST(Orientation, SurfacesTouchingAtAVertexAreOneComponent) {
  RowMatrixX3d V(7, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1;
  RowMatrixX3i F(8, 3);
  F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3,  // tetrahedron in the + octant, outward
      0, 4, 5, 0, 6, 4, 0, 5, 6, 4, 6, 5;   // its mirror image through the origin, outward
  const OrientationReport r = orientation_report(V, F);
  ASSERT_EQ(r.components.size(), 1u);
  EXPECT_EQ(r.components[0].vertex_count, 7);
  EXPECT_TRUE(r.components[0].closed);
  EXPECT_TRUE(r.components[0].consistent);
  EXPECT_NEAR(r.components[0].signed_volume, 2.0 / 6.0, 1e-15);
}

TEST(Orientation, ErrorsAreReported) {
  const TestMesh m = octahedron();
  RowMatrixX3i F = m.F;
  F(2, 0) = 100;
  EXPECT_THROW((void)orientation_report(m.V, F), InvalidInput);
  const OrientationReport r = orientation_report(m.V, m.F);
  EXPECT_THROW((void)orient_outward(m.F.topRows(5), r), InvalidInput);
  OrientationReport bad = r;
  bad.face_component[3] = 1;  // only component 0 exists
  EXPECT_THROW((void)orient_outward(m.F, bad), InvalidInput);
}

// --- orient_consistently ------------------------------------------------------------------------

// A band of n quads between a top row t_i = i and a bottom row b_i = n + i (topology only). The
// last quad joins back to the first rungs straight (an annulus) or crossed (a Moebius strip).
RowMatrixX3i band(int n, bool twisted) {
  RowMatrixX3i F(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int t0 = i, b0 = n + i;
    int t1 = (i + 1) % n, b1 = n + (i + 1) % n;
    if (twisted && i == n - 1) std::swap(t1, b1);
    F.row(2 * i) << t0, b0, b1;
    F.row(2 * i + 1) << t0, b1, t1;
  }
  return F;
}

TEST(OrientConsistently, RestoresAMinorityOfFlippedFaces) {
  const TestMesh m = jittered_sphere(2, Eigen::Vector3d::Zero(), 1.0, 0.3, 3);
  std::mt19937 rng(5);
  RowMatrixX3i scrambled = m.F;
  int flipped = 0;
  for (Eigen::Index f = 1; f < m.F.rows(); ++f) {  // face 0 kept: it seeds the search
    if (rng() % 10 < 3) {
      std::swap(scrambled(f, 1), scrambled(f, 2));
      ++flipped;
    }
  }
  ASSERT_GT(flipped, 0);
  ASSERT_FALSE(orientation_report(m.V, scrambled).components[0].consistent);
  const ConsistentFaces fixed = orient_consistently(static_cast<int>(m.V.rows()), scrambled);
  EXPECT_EQ(fixed.F, m.F);
  EXPECT_EQ(fixed.flipped_face_count, flipped);
  EXPECT_EQ(fixed.conflicting_edge_count, 0);
}

// With most faces reversed, the majority wins: the mesh comes out consistently inward, and
// orient_outward then turns it outward.
TEST(OrientConsistently, KeepsTheMajorityOrientationOfEachPatch) {
  const TestMesh m = octahedron();
  RowMatrixX3i F = flipped(m.F);
  for (const int f : {0, 5, 6}) std::swap(F(f, 1), F(f, 2));  // 3 outward, 5 inward
  const ConsistentFaces fixed = orient_consistently(6, F);
  EXPECT_EQ(fixed.flipped_face_count, 3);
  EXPECT_EQ(fixed.F, flipped(m.F));
  const OrientationReport r = orientation_report(m.V, fixed.F);
  EXPECT_TRUE(r.components[0].inward);
  EXPECT_EQ(orient_outward(fixed.F, r), m.F);
}

TEST(OrientConsistently, MoebiusStripKeepsOneConflictAndAnnulusNone) {
  RowMatrixX3i annulus = band(6, false);
  std::swap(annulus(3, 1), annulus(3, 2));
  const ConsistentFaces a = orient_consistently(12, annulus);
  EXPECT_EQ(a.conflicting_edge_count, 0);
  EXPECT_EQ(a.flipped_face_count, 1);
  EXPECT_EQ(a.F, band(6, false));
  // The strip's faces form a cycle through its 12 interior edges; a spanning tree leaves exactly
  // one edge that no choice of orientations can make consistent.
  const ConsistentFaces moebius = orient_consistently(12, band(6, true));
  EXPECT_EQ(moebius.conflicting_edge_count, 1);
}

TEST(OrientConsistently, LeavesUnorientableFacesAndSeparatePatchesAlone) {
  // Two triangles sharing only vertex 0 are separate patches: each keeps its orientation.
  RowMatrixX3i F(3, 3);
  F << 0, 1, 2, 0, 4, 3, 5, 5, 6;
  const ConsistentFaces c = orient_consistently(7, F);
  EXPECT_EQ(c.F, F);
  EXPECT_EQ(c.flipped_face_count, 0);
  EXPECT_EQ(c.conflicting_edge_count, 0);
  EXPECT_EQ(orient_consistently(0, RowMatrixX3i(0, 3)).F.rows(), 0);
}

TEST(OrientConsistently, ErrorsAreReported) {
  const TestMesh m = octahedron();
  EXPECT_THROW((void)orient_consistently(5, m.F), InvalidInput);
  EXPECT_THROW((void)orient_consistently(-1, RowMatrixX3i(0, 3)), InvalidInput);
}

// --- fraction_against_faces -------------------------------------------------------------------

TEST(FractionAgainstFaces, CountsVerticesWhoseNormalOpposesTheFaces) {
  const TestMesh m = icosahedron();
  RowMatrixX3d N = m.V.rowwise().normalized();
  EXPECT_EQ(fraction_against_faces(m.V, m.F, N), 0.0);
  EXPECT_EQ(fraction_against_faces(m.V, m.F, -N), 1.0);
  N.topRows(3) *= -1.0;
  EXPECT_DOUBLE_EQ(fraction_against_faces(m.V, m.F, N), 3.0 / 12.0);
  // Vertices with non-finite normals drop out of numerator and denominator.
  N.row(11).setConstant(std::nan(""));
  EXPECT_DOUBLE_EQ(fraction_against_faces(m.V, m.F, N), 3.0 / 11.0);
}

TEST(FractionAgainstFaces, UnreferencedVerticesDoNotCountAndNoVertexGivesNaN) {
  TestMesh m = octahedron();
  RowMatrixX3d V(7, 3);
  V << m.V, Eigen::RowVector3d(5, 5, 5);
  RowMatrixX3d N(7, 3);
  N << -m.V, Eigen::RowVector3d(1, 1, 1);
  EXPECT_EQ(fraction_against_faces(V, m.F, N), 1.0);
  EXPECT_TRUE(std::isnan(fraction_against_faces(V, RowMatrixX3i(0, 3), N)));
}

TEST(FractionAgainstFaces, ErrorsAreReported) {
  const TestMesh m = octahedron();
  EXPECT_THROW((void)fraction_against_faces(m.V, m.F, m.V.topRows(5)), InvalidInput);
  EXPECT_THROW((void)fraction_against_faces(m.V, m.F, RowMatrixX3d(0, 3)), InvalidInput);
  RowMatrixX3i F = m.F;
  F(0, 0) = -2;
  EXPECT_THROW((void)fraction_against_faces(m.V, F, m.V), InvalidInput);
}

}  // namespace
}  // namespace focal
