// Dirty geometry (issue 6): NaN and infinite coordinates, extreme scales, needle and zero-area
// triangles, duplicate and repeated-index faces, non-manifold edges and vertices, holes, several
// components, inconsistent orientation and bad normals. Each case checks what check_mesh()
// counts and that the estimator computes every vertex the problem does not touch exactly as on
// a clean mesh, and gives the touched ones class `undefined` with NaN fields.
//
// Most value checks use spheres with exact normals: every normal ray passes through the centre,
// so the closed-form fit gives k1 = k2 = 1/r up to rounding (curvature_test.cpp checks 1e-9 on
// clean spheres) wherever a vertex keeps two independent rays, whatever else is wrong nearby.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/check.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/orientation.h"
#include "focal/mesh/prepared.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
/// |k r - 1| on spheres with exact normals: rounding only (see the file comment).
constexpr double kExact = 1e-9;

Mesh sphere(double radius = 1.0, int vertices = 600, Triangulation tri = Triangulation::irregular) {
  SurfaceOptions o;
  o.kind = SurfaceKind::sphere;
  o.triangulation = tri;
  o.target_vertices = vertices;
  o.a = radius;
  o.seed = 7;
  return make_surface(o).mesh;
}

/// Appends mesh b to a (indices of b shifted), b's positions moved by `offset`.
Mesh join(const Mesh& a, const Mesh& b, const Eigen::RowVector3d& offset) {
  Mesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V.rowwise() + offset;
  m.N.resize(a.N.rows() + b.N.rows(), 3);
  m.N << a.N, b.N;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, b.F.array() + static_cast<int>(a.V.rows());
  return m;
}

std::vector<bool> touching(const Mesh& m, int vertex) {
  const Neighbourhoods ring = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  std::vector<bool> near(static_cast<std::size_t>(m.V.rows()), false);
  near[static_cast<std::size_t>(vertex)] = true;
  for (const int* j = ring.begin(vertex); j != ring.end(vertex); ++j) {
    near[static_cast<std::size_t>(*j)] = true;
  }
  return near;
}

void expect_undefined(const CurvatureResult& r, Eigen::Index i) {
  EXPECT_EQ(r.class_of(static_cast<int>(i)), PointClass::undefined) << "vertex " << i;
  EXPECT_TRUE(std::isnan(r.k1[i]) && std::isnan(r.k2[i]) && std::isnan(r.H[i]) &&
              std::isnan(r.K[i]) && std::isnan(r.residual[i]) && !r.d1.row(i).allFinite() &&
              !r.d2.row(i).allFinite())
      << "vertex " << i;
}

/// Every vertex with skip[i] false is umbilic with k1 = k2 = k within kExact * |k|.
void expect_sphere_values(const CurvatureResult& r, double k, const std::vector<bool>& skip) {
  for (Eigen::Index i = 0; i < r.k1.size(); ++i) {
    if (!skip.empty() && skip[static_cast<std::size_t>(i)]) continue;
    ASSERT_NEAR(r.k1[i] / k, 1.0, kExact) << "vertex " << i;
    ASSERT_NEAR(r.k2[i] / k, 1.0, kExact) << "vertex " << i;
    ASSERT_EQ(r.class_of(static_cast<int>(i)), PointClass::umbilic) << "vertex " << i;
  }
}

CurvatureOptions gaussian() {
  CurvatureOptions o;
  o.weighting = RayWeighting::gaussian;  // its width comes from the mean edge length
  return o;
}

// ---- Non-finite coordinates --------------------------------------------------------------------

TEST(Robustness, NonFiniteCoordinateLeavesItsVertexUndefinedAndTheRestExact) {
  for (const double bad : {kNaN, kInf, -kInf}) {
    Mesh m = sphere();
    const int v = 17;
    m.V(v, 1) = bad;
    EXPECT_TRUE(std::isfinite(mean_edge_length(m.V, m.F)));
    EXPECT_EQ(check_mesh(m.V, m.F, m.normals()).non_finite_vertex_count, 1);
    for (const auto& options : {CurvatureOptions{}, gaussian()}) {
      const CurvatureResult r = estimate_curvature(m.V, m.F, m.N, options);
      expect_undefined(r, v);
      // The neighbours lose one ray (it is not finite) and still fit the sphere exactly.
      std::vector<bool> skip(static_cast<std::size_t>(m.V.rows()), false);
      skip[v] = true;
      expect_sphere_values(r, 1.0, skip);
    }
  }
}

TEST(Robustness, NanCoordinateDoesNotPoisonTheTolerancesOfAFlatMesh) {
  // A NaN mean edge length would turn the zero tolerance into NaN: every flat vertex would then
  // be classified umbilic (0 - 0 <= 0) instead of flat.
  Mesh m = test::flat_grid(8);
  m.V(27, 2) = kNaN;
  for (const auto& options : {CurvatureOptions{}, gaussian()}) {
    for (auto method : {Method::vertex, Method::triangle}) {
      CurvatureOptions o = options;
      o.method = method;
      const CurvatureResult r = estimate_curvature(m.V, m.F, m.N, o);
      const std::vector<bool> near = touching(m, 27);
      expect_undefined(r, 27);
      for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
        if (near[static_cast<std::size_t>(i)]) continue;
        EXPECT_EQ(r.class_of(static_cast<int>(i)), PointClass::flat) << "vertex " << i;
        EXPECT_EQ(r.k1[i], 0.0) << "vertex " << i;
      }
    }
  }
}

TEST(Robustness, EstimatedNormalsNextToANanVertexAreUndefinedNotWrong) {
  Mesh m = sphere();
  const int v = 40;
  m.V.row(v).setConstant(kNaN);
  const RowMatrixX3d N = vertex_normals(m.V, m.F, NormalWeighting::max);
  const std::vector<bool> near = touching(m, v);
  const CurvatureResult r = estimate_curvature(m.V, m.F, N);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    if (near[static_cast<std::size_t>(i)]) {
      // Their faces include the NaN vertex: no normal, hence no estimate, rather than a guess.
      if (!N.row(i).allFinite()) expect_undefined(r, i);
    } else {
      ASSERT_TRUE(N.row(i).allFinite()) << "vertex " << i;
    }
  }
  // Max's weights are exact on the sphere, so vertices two rings away are exact as well.
  std::vector<bool> skip = near;
  const Neighbourhoods ring = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    if (!near[static_cast<std::size_t>(i)]) continue;
    for (const int* j = ring.begin(static_cast<int>(i)); j != ring.end(static_cast<int>(i)); ++j)
      skip[static_cast<std::size_t>(*j)] = true;
  }
  expect_sphere_values(r, 1.0, skip);
}

// ---- Scale -----------------------------------------------------------------------------------

/// Curvature scales as 1/s when positions scale by s. Powers of two scale every intermediate
/// value exactly (no overflow or underflow between 2^-40 ~ 1e-12 and 2^40 ~ 1e12), so the
/// results must be bit-identical after rescaling; decimal factors round each coordinate once,
/// which the fit amplifies by about (radius / edge length): 1e-9 relative is far above that.
void expect_scaled(const Mesh& m, double s, double relative, Method method) {
  CurvatureOptions o;
  o.method = method;
  const CurvatureResult ref = estimate_curvature(m.V, m.F, m.N, o);
  const RowMatrixX3d V = m.V * s;
  const CurvatureResult r = estimate_curvature(V, m.F, m.N, o);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    if (relative == 0.0) {
      ASSERT_EQ(r.k1[i] * s, ref.k1[i]) << "vertex " << i << " scale " << s;
      ASSERT_EQ(r.k2[i] * s, ref.k2[i]) << "vertex " << i << " scale " << s;
      ASSERT_TRUE(r.d1.row(i) == ref.d1.row(i)) << "vertex " << i << " scale " << s;
    } else {
      const double k = std::max(std::abs(ref.k1[i]), std::abs(ref.k2[i]));
      ASSERT_NEAR(r.k1[i] * s, ref.k1[i], relative * k) << "vertex " << i << " scale " << s;
      ASSERT_NEAR(r.k2[i] * s, ref.k2[i], relative * k) << "vertex " << i << " scale " << s;
    }
    ASSERT_EQ(r.point_class[i], ref.point_class[i]) << "vertex " << i << " scale " << s;
  }
}

TEST(Robustness, CurvatureScalesAsOneOverTheScaleFrom1em12To1e12) {
  SurfaceOptions torus;
  torus.kind = SurfaceKind::torus;
  torus.triangulation = Triangulation::irregular;
  torus.target_vertices = 1500;
  for (const Mesh& m : {sphere(1.0, 800), make_surface(torus).mesh}) {
    for (auto method : {Method::vertex, Method::triangle}) {
      for (const double s : {std::ldexp(1.0, -40), std::ldexp(1.0, 40)}) {
        expect_scaled(m, s, 0.0, method);
      }
      for (const double s : {1e-12, 1e-6, 1e6, 1e12}) expect_scaled(m, s, 1e-9, method);
    }
  }
}

TEST(Robustness, EstimatedNormalsAndFindingsAreScaleFree) {
  const Mesh m = sphere(1.0, 800);
  const RowMatrixX3d N = vertex_normals(m.V, m.F, NormalWeighting::max);
  for (const double s : {std::ldexp(1.0, -40), std::ldexp(1.0, 40)}) {
    const RowMatrixX3d V = m.V * s;
    EXPECT_TRUE(vertex_normals(V, m.F, NormalWeighting::max) == N) << "scale " << s;
    const MeshFindings f = check_mesh(V, m.F, N);
    EXPECT_FALSE(f.has_problems()) << f.summary();
    EXPECT_EQ(f.component_count, 1);
  }
}

// ---- Degenerate triangles ------------------------------------------------------------------

/// Splits the edge {b, c} at d = normalize(b + t (c - b)) (on the unit sphere, with its exact
/// normal): each face (b, c, o) becomes (b, d, o) and (d, c, o). Small t makes needles (b, d, o).
Mesh split_edge(const Mesh& m, int b, int c, double t) {
  Mesh out = m;
  const Eigen::RowVector3d d = (m.V.row(b) + t * (m.V.row(c) - m.V.row(b))).normalized();
  const int di = static_cast<int>(m.V.rows());
  out.V.conservativeResize(di + 1, 3);
  out.V.row(di) = d;
  out.N.conservativeResize(di + 1, 3);
  out.N.row(di) = d;
  std::vector<Eigen::RowVector3i> faces;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    bool split = false;
    for (int k = 0; k < 3 && !split; ++k) {
      const int x = m.F(f, k), y = m.F(f, (k + 1) % 3), o = m.F(f, (k + 2) % 3);
      if ((x == b && y == c) || (x == c && y == b)) {
        faces.emplace_back(x, di, o);
        faces.emplace_back(di, y, o);
        split = true;
      }
    }
    if (!split) faces.emplace_back(m.F.row(f));
  }
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) out.F.row(static_cast<Eigen::Index>(f)) = faces[f];
  return out;
}

TEST(Robustness, NeedleTrianglesKeepTheSphereExact) {
  const Mesh base = sphere(1.0, 600, Triangulation::regular);
  const int b = base.F(100, 0), c = base.F(100, 1);
  for (const double t : {1e-4, 1e-8}) {
    const Mesh m = split_edge(base, b, c, t);
    ASSERT_EQ(m.F.rows(), base.F.rows() + 2);
    const MeshFindings f = check_mesh(m.V, m.F, m.normals());
    EXPECT_FALSE(f.has_problems()) << "t " << t << ": " << f.summary();
    expect_sphere_values(estimate_curvature(m.V, m.F, m.N), 1.0, {});
    // Max's weights stay exact on needles up to the rounding of the input: the corners are
    // rounded to eps, so an edge of relative length t has a direction error of about eps / t,
    // and Max's weight 1 / |e|^2 lets that needle dominate its corners' normals.
    const RowMatrixX3d N = vertex_normals(m.V, m.F, NormalWeighting::max);
    EXPECT_LT((N - m.N).cwiseAbs().maxCoeff(), 100 * std::numeric_limits<double>::epsilon() / t)
        << "t " << t;
  }
}

TEST(Robustness, ZeroAreaFacesAreCountedAndChangeNothing) {
  const Mesh clean = test::flat_grid(5);
  Mesh m = clean;
  m.F.conservativeResize(m.F.rows() + 2, 3);
  m.F.row(m.F.rows() - 2) << 2, 1, 0;  // three grid points on one line, oriented like the grid
  m.F.row(m.F.rows() - 1) << 6, 7, 6;  // a repeated index
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.degenerate_face_count, 1);
  EXPECT_EQ(f.repeated_index_face_count, 1);
  EXPECT_EQ(f.summary(), "1 face with a repeated vertex, 1 zero-area face, 1 non-manifold edge");
  // Degenerate faces add no normal; the collinear one adds the edge {0, 2} to the rings.
  EXPECT_TRUE(vertex_normals(m.V, m.F, NormalWeighting::max) ==
              vertex_normals(clean.V, clean.F, NormalWeighting::max));
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    EXPECT_EQ(r.class_of(static_cast<int>(i)), PointClass::flat) << "vertex " << i;
  }
}

// ---- Connectivity ----------------------------------------------------------------------------

TEST(Robustness, DuplicateAndRepeatedIndexFacesLeaveTheVertexMethodUnchanged) {
  const Mesh clean = sphere();
  Mesh m = clean;
  const Eigen::Index n = m.F.rows();
  m.F.conservativeResize(n + 3, 3);
  m.F.row(n) = clean.F.row(5);                                       // the same face again
  m.F.row(n + 1) << clean.F(9, 2), clean.F(9, 0), clean.F(9, 1);     // rotated: same vertex set
  m.F.row(n + 2) << clean.F(20, 0), clean.F(20, 0), clean.F(20, 1);  // repeated index
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.duplicate_face_count, 2);
  EXPECT_EQ(f.repeated_index_face_count, 1);
  // The rings are sets of neighbours, so the vertex method sees exactly the clean mesh.
  const CurvatureResult a = estimate_curvature(m.V, m.F, m.N);
  const CurvatureResult b = estimate_curvature(clean.V, clean.F, clean.N);
  EXPECT_TRUE(a.k1.cwiseEqual(b.k1).all());
  EXPECT_TRUE(a.k2.cwiseEqual(b.k2).all());
  EXPECT_TRUE(a.d1.cwiseEqual(b.d1).all());
  EXPECT_TRUE(a.point_class.cwiseEqual(b.point_class).all());
  CurvatureOptions triangle;
  triangle.method = Method::triangle;
  const CurvatureResult t = estimate_curvature(m.V, m.F, m.N, triangle);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    ASSERT_NE(t.class_of(static_cast<int>(i)), PointClass::undefined) << "vertex " << i;
  }
}

TEST(Robustness, OutOfRangeIndicesAreRejectedNotRead) {
  Mesh m = sphere();
  m.F(3, 1) = static_cast<int>(m.V.rows());
  EXPECT_THROW((void)check_mesh(m.V, m.F, m.normals()), InvalidInput);
  m.F(3, 1) = -1;
  EXPECT_THROW((void)check_mesh(m.V, m.F, m.normals()), InvalidInput);
  EXPECT_THROW((void)estimate_curvature(m.V, m.F, m.N), InvalidInput);
}

TEST(Robustness, NonManifoldEdgeFinIsFittedExactly) {
  // A fin triangle (b, c, apex) on the sphere edge {b, c}: that edge gets three faces. Every
  // ray, the apex's included, passes through the centre, so the sphere vertices stay at k = 1
  // and the apex, at distance |apex| from the centre, gets k = 1 / |apex|.
  Mesh m = sphere();
  const int b = m.F(0, 0), c = m.F(0, 1);
  const Eigen::RowVector3d apex = 0.75 * (m.V.row(b) + m.V.row(c)) + 0.2 * m.V.row(m.F(0, 2));
  const int a = static_cast<int>(m.V.rows());
  m.V.conservativeResize(a + 1, 3);
  m.V.row(a) = apex;
  m.N.conservativeResize(a + 1, 3);
  m.N.row(a) = apex.normalized();
  m.F.conservativeResize(m.F.rows() + 1, 3);
  m.F.row(m.F.rows() - 1) << b, c, a;
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.non_manifold_edge_count, 1);
  EXPECT_EQ(f.non_manifold_vertex_count, 0);
  EXPECT_EQ(f.boundary_edge_count, 2);
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  std::vector<bool> skip(static_cast<std::size_t>(m.V.rows()), false);
  skip[static_cast<std::size_t>(a)] = true;
  expect_sphere_values(r, 1.0, skip);
  EXPECT_NEAR(r.k1[a] * apex.norm(), 1.0, kExact);
  EXPECT_NEAR(r.k2[a] * apex.norm(), 1.0, kExact);
}

TEST(Robustness, SpheresTouchingAtOneVertexAreFittedExactly) {
  // Sphere B touches sphere A at one shared vertex (a non-manifold vertex: two fans). The shared
  // vertex keeps A's normal; B's vertices next to it see that normal pointing away from theirs
  // (outside their hemisphere), leave its ray out and still fit B exactly, and vice versa.
  const Mesh a = sphere();
  const int touch = 11;
  const Eigen::RowVector3d p = a.V.row(touch);
  const Mesh b = sphere();
  // B is A reflected about the tangent plane at p (x -> x - 2 ((x - p) . p) p, |p| = 1): the
  // unit sphere about 2p, whose copy of `touch` lands exactly on p.
  Mesh m = join(a, b, Eigen::RowVector3d::Zero());
  const Eigen::Index n = a.V.rows();
  for (Eigen::Index i = n; i < m.V.rows(); ++i) {
    m.V.row(i) = b.V.row(i - n) - 2.0 * (b.V.row(i - n) - p).dot(p) * p;
    m.N.row(i) = b.N.row(i - n) - 2.0 * b.N.row(i - n).dot(p) * p;
  }
  // Reflection reverses orientation: flip B's faces back to outward.
  for (Eigen::Index f = a.F.rows(); f < m.F.rows(); ++f) std::swap(m.F(f, 1), m.F(f, 2));
  ASSERT_EQ(m.V.row(n + touch), p);
  // Weld B's copy of the touching vertex to A's; the copy stays, unreferenced.
  for (Eigen::Index f = a.F.rows(); f < m.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (m.F(f, k) == n + touch) m.F(f, k) = touch;
    }
  }
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.non_manifold_vertex_count, 1);
  EXPECT_EQ(f.unreferenced_vertex_count, 1);  // B's own copy of the touching vertex
  EXPECT_EQ(f.component_count, 1);
  EXPECT_EQ(f.boundary_edge_count, 0);
  EXPECT_EQ(f.inward_component_count, 0);
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  std::vector<bool> skip(static_cast<std::size_t>(m.V.rows()), false);
  skip[static_cast<std::size_t>(n + touch)] = true;
  expect_sphere_values(r, 1.0, skip);
  expect_undefined(r, n + touch);
}

TEST(Robustness, HoleBoundaryVerticesAreStillExact) {
  Mesh m = sphere();
  // Remove one face: a hole bounded by its three edges.
  RowMatrixX3i kept(m.F.rows() - 1, 3);
  kept << m.F.topRows(7), m.F.bottomRows(m.F.rows() - 8);
  m.F = kept;
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.boundary_edge_count, 3);
  EXPECT_FALSE(f.has_problems()) << f.summary();
  expect_sphere_values(estimate_curvature(m.V, m.F, m.N), 1.0, {});
}

TEST(Robustness, SeveralComponentsAreEstimatedIndependently) {
  const Mesh m = join(sphere(1.0), sphere(2.0), Eigen::RowVector3d(10, 0, 0));
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.component_count, 2);
  EXPECT_FALSE(f.has_problems()) << f.summary();
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  const Eigen::Index n = sphere(1.0).V.rows();
  std::vector<bool> second(static_cast<std::size_t>(m.V.rows()), false);
  std::fill(second.begin() + n, second.end(), true);
  std::vector<bool> first(second.size());
  for (std::size_t i = 0; i < first.size(); ++i) first[i] = !second[i];
  expect_sphere_values(r, 1.0, second);  // checks the first sphere
  expect_sphere_values(r, 0.5, first);   // checks the second
}

TEST(Robustness, InwardAndInconsistentOrientationIsFoundPerComponent) {
  Mesh m = join(sphere(1.0), sphere(2.0), Eigen::RowVector3d(10, 0, 0));
  const Eigen::Index n = sphere(1.0).F.rows();
  // The second sphere turned inside out, one face of the first flipped on its own.
  for (Eigen::Index f = n; f < m.F.rows(); ++f) std::swap(m.F(f, 1), m.F(f, 2));
  std::swap(m.F(4, 1), m.F(4, 2));
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.inward_component_count, 1);
  EXPECT_EQ(f.inconsistent_component_count, 1);
  // The file's normals are outward: against the second sphere's faces, and the flipped face
  // turns none of its corners around (each has five or six other faces).
  EXPECT_EQ(f.normals_against_faces_count, m.V.rows() - sphere(1.0).V.rows());
  EXPECT_EQ(f.inward_normal_component_count, 0);
  // The vertex method does not use face orientation: with the given normals nothing changes.
  std::vector<bool> second(static_cast<std::size_t>(m.V.rows()), false);
  std::fill(second.begin() + sphere(1.0).V.rows(), second.end(), true);
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  expect_sphere_values(r, 1.0, second);
  // Estimated normals after repairing the orientation point outward again: k = +1/r.
  const ConsistentFaces consistent = orient_consistently(static_cast<int>(m.V.rows()), m.F);
  EXPECT_EQ(consistent.conflicting_edge_count, 0);
  const RowMatrixX3i outward = orient_outward(consistent.F, orientation_report(m.V, consistent.F));
  const RowMatrixX3d N = vertex_normals(m.V, outward, NormalWeighting::max);
  EXPECT_LT((N - m.N).cwiseAbs().maxCoeff(), 1e-12);
}

// ---- Normals ---------------------------------------------------------------------------------

TEST(Robustness, BadNormalRowsAreCountedByKind) {
  Mesh m = sphere();
  m.N.row(1).setZero();
  m.N(2, 0) = kNaN;
  m.N(3, 2) = kInf;
  m.N.row(4) *= 2.0;
  m.N.row(5) *= 1.0 + 1e-7;  // within the estimator's 1e-6: unit
  m.N.row(6) *= -1.0;        // inward
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.zero_normal_count, 1);
  EXPECT_EQ(f.non_finite_normal_count, 2);
  EXPECT_EQ(f.non_unit_normal_count, 1);
  EXPECT_EQ(f.normals_against_faces_count, 1);
  EXPECT_EQ(f.normals_compared_count, m.V.rows() - 2);  // all but the non-finite rows
  EXPECT_EQ(f.inward_normal_component_count, 0);
  EXPECT_EQ(f.summary(),
            "2 non-finite normals, 1 zero normal, 1 non-unit normal, 1 normal against its faces");
  const CurvatureResult r = estimate_curvature(m.V, m.F, m.N);
  // Vertex 6's normal points inward: every neighbour's normal leaves its hemisphere (no rays),
  // and the neighbours leave its ray out in turn. Vertex 4's is normalised, not an error.
  std::vector<bool> skip(static_cast<std::size_t>(m.V.rows()), false);
  for (int i : {1, 2, 3, 6}) {
    expect_undefined(r, i);
    skip[static_cast<std::size_t>(i)] = true;
  }
  expect_sphere_values(r, 1.0, skip);
}

TEST(Robustness, InwardNormalsAreDetectedPerComponentAndGiveNegativeCurvature) {
  Mesh m = join(sphere(1.0), sphere(2.0), Eigen::RowVector3d(10, 0, 0));
  const Eigen::Index n = sphere(1.0).V.rows();
  m.N.bottomRows(m.V.rows() - n) *= -1.0;
  const MeshFindings f = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(f.inward_normal_component_count, 1);
  EXPECT_EQ(f.normals_against_faces_count, m.V.rows() - n);
  EXPECT_EQ(f.inward_component_count, 0);
  // Curvature signs follow the normals (curvature.h): the second sphere gets k = -1/2.
  std::vector<bool> first(static_cast<std::size_t>(m.V.rows()), false);
  std::fill(first.begin(), first.begin() + n, true);
  expect_sphere_values(estimate_curvature(m.V, m.F, m.N), -0.5, first);
  // Faces and normals both inward: the faces are the inward-oriented component now, and the
  // normals agree with them.
  for (Eigen::Index f2 = sphere(1.0).F.rows(); f2 < m.F.rows(); ++f2)
    std::swap(m.F(f2, 1), m.F(f2, 2));
  const MeshFindings g = check_mesh(m.V, m.F, m.normals());
  EXPECT_EQ(g.inward_component_count, 1);
  EXPECT_EQ(g.inward_normal_component_count, 1);
  EXPECT_EQ(g.normals_against_faces_count, 0);
}

TEST(Robustness, SingleTriangleAndEmptyMeshHaveNoProblems) {
  Mesh m;
  m.V.resize(3, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  const MeshFindings f = check_mesh(m.V, m.F, std::nullopt);
  EXPECT_FALSE(f.has_problems()) << f.summary();
  EXPECT_EQ(f.boundary_edge_count, 3);
  EXPECT_EQ(f.component_count, 1);
  const MeshFindings e = check_mesh(RowMatrixX3d(0, 3), RowMatrixX3i(0, 3), std::nullopt);
  EXPECT_FALSE(e.has_problems());
  EXPECT_EQ(e.summary(), "");
  // Three unreferenced vertices and nothing else.
  const MeshFindings p = check_mesh(m.V, RowMatrixX3i(0, 3), std::nullopt);
  EXPECT_EQ(p.summary(), "3 unreferenced vertices");
  EXPECT_THROW((void)check_mesh(m.V, m.F, RowMatrixX3d::Zero(2, 3)), InvalidInput);
  // No normals is std::nullopt, not a matrix of 0 rows.
  EXPECT_THROW((void)check_mesh(m.V, m.F, RowMatrixX3d(0, 3)), InvalidInput);
}

// ---- The parallel topology pass (check stage) against a serial reference ----------------------

// Three grids of 150 x 150 vertices: the second turned over and joined to the first at one
// corner by a face that also makes a diagonal of the second non-manifold, one face of the third
// flipped, a duplicate face, two faces with repeated indices and an unreferenced vertex; faces
// shuffled so that components interleave. About 133K faces: enough for the parallel incidence
// to split them into chunks.
Mesh messy_big_mesh() {
  constexpr int n = 150;
  Mesh m = join(join(test::flat_grid(n), test::flat_grid(n), Eigen::RowVector3d(300, 0, 0)),
                test::flat_grid(n), Eigen::RowVector3d(0, 300, 0));
  const Eigen::Index per_grid = m.F.rows() / 3;
  for (Eigen::Index f = per_grid; f < 2 * per_grid; ++f) std::swap(m.F(f, 1), m.F(f, 2));
  std::swap(m.F(2 * per_grid, 1), m.F(2 * per_grid, 2));  // one face of the third grid
  RowMatrixX3i extra(4, 3);
  extra << m.F.row(7), 5, 5, 9, 0, n * n + n + 1, n * n + 2 * n + 2, 3, 3, 3;
  m.F.conservativeResize(m.F.rows() + extra.rows(), 3);
  m.F.bottomRows(extra.rows()) = extra;
  m.V.conservativeResize(m.V.rows() + 1, 3);  // unreferenced
  m.V.bottomRows(1) << 1e3, 1e3, 1e3;
  m.N.conservativeResize(m.V.rows(), 3);
  m.N.bottomRows(1) << 0, 0, 1;
  std::vector<Eigen::Index> order(static_cast<std::size_t>(m.F.rows()));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Eigen::Index>(i);
  std::mt19937 random(5);
  std::shuffle(order.begin(), order.end(), random);
  const RowMatrixX3i faces = m.F;
  for (std::size_t i = 0; i < order.size(); ++i)
    m.F.row(static_cast<Eigen::Index>(i)) = faces.row(order[i]);
  return m;
}

// Components of faces by a plain serial union-find, numbered by first face.
std::vector<int> reference_face_components(const Mesh& m) {
  std::vector<int> parent(static_cast<std::size_t>(m.V.rows()));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      x = parent[static_cast<std::size_t>(x)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    }
    return x;
  };
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int c = 1; c < 3; ++c) parent[static_cast<std::size_t>(root(m.F(f, c)))] = root(m.F(f, 0));
  }
  std::map<int, int> label;
  std::vector<int> out;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    out.push_back(label.try_emplace(root(m.F(f, 0)), static_cast<int>(label.size())).first->second);
  }
  return out;
}

// Edge and face counts by plain maps: incident faces per undirected edge (each face once per
// edge), and faces repeating the vertex set of an earlier one.
struct ReferenceCounts {
  int edges = 0, boundary = 0, non_manifold = 0, duplicates = 0;
};

ReferenceCounts reference_counts(const Mesh& m) {
  std::map<std::pair<int, int>, int> faces_of_edge;
  std::set<std::array<int, 3>> triples;
  ReferenceCounts r;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    std::array<int, 3> t{m.F(f, 0), m.F(f, 1), m.F(f, 2)};
    std::sort(t.begin(), t.end());
    r.duplicates += triples.insert(t).second ? 0 : 1;
    std::set<std::pair<int, int>> edges;
    for (int c = 0; c < 3; ++c) {
      const int a = m.F(f, c), b = m.F(f, (c + 1) % 3);
      if (a != b) edges.insert({std::min(a, b), std::max(a, b)});
    }
    for (const auto& e : edges) ++faces_of_edge[e];
  }
  r.edges = static_cast<int>(faces_of_edge.size());
  for (const auto& [edge, count] : faces_of_edge) {
    r.boundary += count == 1 ? 1 : 0;
    r.non_manifold += count >= 3 ? 1 : 0;
  }
  return r;
}

// Vertices whose normals point against (and are compared with) the faces' area-weighted normals,
// from the whole matrix of those normals.
std::pair<int, int> reference_against_and_compared(const Mesh& m) {
  const RowMatrixX3d area = vertex_normals(m.V, m.F, NormalWeighting::area);
  int against = 0, compared = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const double dot = m.N.row(i).dot(area.row(i));
    if (!std::isfinite(dot)) continue;
    ++compared;
    against += dot < 0.0 ? 1 : 0;
  }
  return {against, compared};
}

TEST(Robustness, TopologyCountsMatchASerialReferenceForAnyThreadCount) {
  const Mesh m = messy_big_mesh();
  const ReferenceCounts reference = reference_counts(m);
  const std::vector<int> components = reference_face_components(m);
  // The second grid's faces are flipped, so its normals point against them.
  const auto [against, compared] = reference_against_and_compared(m);
  ASSERT_GT(against, 10000);

  for (const int threads : {1, 2, 3}) {
    const ExecutionScope scope({.threads = threads});
    const MeshStatistics s = mesh_statistics(m.V, m.F);
    EXPECT_EQ(s.edge_count, reference.edges);
    EXPECT_EQ(s.boundary_edge_count, reference.boundary);
    EXPECT_EQ(s.non_manifold_edge_count, reference.non_manifold);
    EXPECT_EQ(s.duplicate_face_count, reference.duplicates);
    EXPECT_EQ(s.duplicate_face_count, 1);
    EXPECT_EQ(s.unreferenced_vertex_count, 1);
    EXPECT_EQ(s.non_manifold_vertex_count, 1);  // vertex 0: its grid fan and the joining face
    EXPECT_EQ(s.component_count, 2);            // the joining face makes one of the first two
    const OrientationReport r = orientation_report(m.V, m.F);
    ASSERT_EQ(r.face_component.size(), static_cast<Eigen::Index>(components.size()));
    for (std::size_t f = 0; f < components.size(); ++f) {
      ASSERT_EQ(r.face_component[static_cast<Eigen::Index>(f)], components[f]) << "face " << f;
    }
    const MeshFindings findings = check_mesh(m.V, m.F, m.normals());
    EXPECT_EQ(findings.component_count, 2);
    EXPECT_EQ(findings.duplicate_face_count, 1);
    EXPECT_EQ(findings.repeated_index_face_count, 2);
    EXPECT_EQ(findings.unreferenced_vertex_count, 1);
    EXPECT_EQ(findings.inconsistent_component_count, 1);  // the third grid's flipped face
    EXPECT_EQ(findings.non_manifold_vertex_count, 1);
    EXPECT_EQ(findings.normals_against_faces_count, against);
    EXPECT_EQ(findings.normals_compared_count, compared);
  }
}

TEST(Robustness, InwardNormalComponentsAreCountedAlikeForAnyThreadCount) {
  // Closed components larger than a block of check_mesh's parallel tally (16384 vertices), one
  // after another, so that some blocks hold runs of two components.
  SurfaceOptions o;
  o.kind = SurfaceKind::torus;
  o.triangulation = Triangulation::regular;
  o.target_vertices = 30000;
  const Mesh torus = make_surface(o).mesh;
  Mesh m =
      join(join(torus, torus, Eigen::RowVector3d(10, 0, 0)), torus, Eigen::RowVector3d(0, 10, 0));
  const Eigen::Index n = torus.V.rows();
  m.N.middleRows(n, n) *= -1.0;  // the second torus: most normals inward
  m.N.topRows(n / 3) *= -1.0;    // a third of the first: a minority, still outward
  for (const int threads : {1, 2, 3}) {
    const ExecutionScope scope({.threads = threads});
    const MeshFindings f = check_mesh(m.V, m.F, m.normals());
    EXPECT_EQ(f.component_count, 3);
    EXPECT_EQ(f.inward_normal_component_count, 1) << threads << " threads";
    EXPECT_EQ(f.normals_against_faces_count, n + n / 3) << threads << " threads";
    EXPECT_EQ(f.normals_compared_count, 3 * n) << threads << " threads";
  }
}

// Gadgets for the topology pass's two paths (a regular vertex: one closed, consistent fan of 3
// to 16 faces; any other vertex: its sorted edge sides), 300 copies with their faces shuffled:
// two octahedra sharing a vertex (two closed fans there: non-manifold), a tetrahedron with one
// face flipped, a cone of 20 sides closed by a fan (two vertices of valence 20), a 3 x 3 grid
// (boundary), and a triangle twice, once reversed (duplicate; two faces at each corner).
Mesh fan_gadgets(int copies) {
  const std::vector<std::array<int, 3>> octahedron = {{0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 2},
                                                      {1, 3, 2}, {1, 4, 3}, {1, 5, 4}, {1, 2, 5}};
  std::vector<std::array<int, 3>> gadget;
  for (const auto& f : octahedron) gadget.push_back(f);  // vertices 0-5, apex 0
  for (const auto& f : octahedron) {                     // 0 and 6-10: 0 is its other apex
    const auto to = [](int c) { return c == 1 ? 0 : (c == 0 ? 6 : c + 5); };
    gadget.push_back({to(f[0]), to(f[1]), to(f[2])});
  }
  for (const auto& f : std::vector<std::array<int, 3>>{{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 2, 3}})
    gadget.push_back({f[0] + 11, f[1] + 11, f[2] + 11});  // the last face flipped
  for (int i = 0; i < 20; ++i) {                          // apex 15, rim 16-35, bottom 36
    gadget.push_back({15, 16 + i, 16 + (i + 1) % 20});
    gadget.push_back({36, 16 + (i + 1) % 20, 16 + i});
  }
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {  // grid 37-45
      const int a = 37 + 3 * i + j;
      gadget.push_back({a, a + 1, a + 4});
      gadget.push_back({a, a + 4, a + 3});
    }
  }
  gadget.push_back({46, 47, 48});
  gadget.push_back({46, 48, 47});
  constexpr int kVertices = 49;
  Mesh m;
  m.V.resize(copies * kVertices, 3);
  m.F.resize(copies * static_cast<Eigen::Index>(gadget.size()), 3);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    m.V.row(i) << unit(random) + static_cast<double>(i / kVertices) * 3.0, unit(random),
        unit(random);
  }
  std::vector<Eigen::Index> order(static_cast<std::size_t>(m.F.rows()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::shuffle(order.begin(), order.end(), random);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const auto& g = gadget[static_cast<std::size_t>(f) % gadget.size()];
    const int base = static_cast<int>(f / static_cast<Eigen::Index>(gadget.size())) * kVertices;
    m.F.row(order[static_cast<std::size_t>(f)]) << base + g[0], base + g[1], base + g[2];
  }
  m.N = vertex_normals(m.V, m.F, NormalWeighting::area);  // NaN on the doubled triangle
  for (Eigen::Index i = 0; i < m.V.rows(); i += 7) m.N.row(i) *= -1.0;
  return m;
}

TEST(Robustness, FindingsAndRingOfEveryKindOfFanAreAlikeForAnyThreadCount) {
  constexpr int kCopies = 300;
  const Mesh m = fan_gadgets(kCopies);
  const ReferenceCounts reference = reference_counts(m);
  const auto [against, compared] = reference_against_and_compared(m);
  const Neighbourhoods ring =
      test::on_threads(1, [&] { return vertex_adjacency(static_cast<int>(m.V.rows()), m.F); });
  const auto fields = [](const MeshFindings& f) {
    return std::vector<int>{f.non_finite_vertex_count,
                            f.repeated_index_face_count,
                            f.degenerate_face_count,
                            f.duplicate_face_count,
                            f.unreferenced_vertex_count,
                            f.non_manifold_edge_count,
                            f.non_manifold_vertex_count,
                            f.inconsistent_component_count,
                            f.inward_component_count,
                            f.non_finite_normal_count,
                            f.zero_normal_count,
                            f.non_unit_normal_count,
                            f.normals_against_faces_count,
                            f.normals_compared_count,
                            f.inward_normal_component_count,
                            f.boundary_edge_count,
                            f.component_count};
  };
  std::vector<int> first;
  for (const int threads : {1, 2, 3, 8}) {
    const ExecutionScope scope({.threads = threads});
    const MeshStatistics s = mesh_statistics(m.V, m.F);
    EXPECT_EQ(s.edge_count, reference.edges) << threads << " threads";
    EXPECT_EQ(s.boundary_edge_count, reference.boundary) << threads << " threads";
    EXPECT_EQ(s.non_manifold_edge_count, reference.non_manifold) << threads << " threads";
    EXPECT_EQ(s.duplicate_face_count, kCopies) << threads << " threads";
    EXPECT_EQ(s.non_manifold_vertex_count, kCopies) << threads << " threads";  // the shared apex
    EXPECT_EQ(s.component_count, 5 * kCopies) << threads << " threads";
    const PreparedMesh p(m.V, m.F, m.N);
    const MeshFindings f = check_mesh(p);
    EXPECT_EQ(f.boundary_edge_count, reference.boundary);
    EXPECT_EQ(f.duplicate_face_count, kCopies);
    EXPECT_EQ(f.non_manifold_vertex_count, kCopies);
    EXPECT_EQ(f.inconsistent_component_count, kCopies);  // the tetrahedra
    EXPECT_EQ(f.normals_against_faces_count, against);
    EXPECT_EQ(f.normals_compared_count, compared);
    if (first.empty()) first = fields(f);
    EXPECT_EQ(fields(f), first) << threads << " threads";
    const Neighbourhoods& checked = p.one_ring();
    EXPECT_EQ(checked.offsets, ring.offsets) << threads << " threads";
    EXPECT_EQ(checked.indices, ring.indices) << threads << " threads";
  }
}

}  // namespace
}  // namespace focal
