// Spikes from positions alone (src/mesh/position_spikes.h): the screen and the leave-one-out
// heights on clean analytic meshes (no false spikes on coarse, strip, graded meshes, rims,
// boundaries), the spikes found and put back on spiked ones, and the recommended estimate
// without normals on spiked meshes against analytic truth.
#include "mesh/position_spikes.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "focal/curvature/recommended.h"
#include "focal/evaluation/evaluation.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"
#include "mesh/prepared_access.h"
#include "test_meshes.h"

namespace focal {
namespace {

struct Found {
  detail::SpikeScreen screen;
  detail::PositionSpikes spikes;
  Neighbourhoods ring;
  std::shared_ptr<const detail::VertexFaces> faces;
  RowMatrixX3d max;  ///< the screen's reference normals
};

/// position_spikes as the recommended estimator calls it (Max's normals screen).
Found find(const Mesh& m) {
  const PreparedMesh mesh(m.V, m.F, std::nullopt);
  const auto ring = detail::one_ring(mesh);
  const auto faces = detail::incidence(mesh);
  const RowMatrixX3d max = vertex_normals(m.V, m.F, NormalWeighting::max);
  return {detail::spike_screen(m.V, *ring, max, 1),
          detail::position_spikes(m.V, m.F, *ring, *faces, max, 1), *ring, faces, max};
}

/// The leave-one-out judgement of vertex i as position_spikes makes it.
detail::OffSurface judge(const Mesh& m, const Found& f, int i) {
  const bool closed = detail::ring_is_closed(m.F, f.ring, *f.faces, i);
  const detail::OffSurface a = detail::off_surface(
      m.V, f.ring, f.screen.deviation, i, f.screen.radius[i], f.max.row(i).transpose(), closed);
  const detail::OffSurface b =
      detail::off_surface(m.V, f.ring, f.screen.deviation, i, f.screen.radius[i],
                          detail::ring_polygon_normal(m.V, m.F, *f.faces, i), closed);
  return b.misfit < a.misfit || !std::isfinite(a.misfit) ? b : a;
}

AnalyticSurface shaped(SurfaceKind kind, Triangulation t, int n, std::uint64_t seed,
                       double aspect = 1.0, double grading = 1.0) {
  return make_surface({.kind = kind,
                       .triangulation = t,
                       .target_vertices = n,
                       .seed = seed,
                       .aspect = aspect,
                       .grading = grading});
}

/// The vertices that add_spikes moved (compared with the clean mesh).
std::vector<int> moved(const Mesh& clean, const Mesh& spiked) {
  std::vector<int> out;
  for (int i = 0; i < clean.V.rows(); ++i) {
    if (clean.V.row(i) != spiked.V.row(i)) out.push_back(i);
  }
  return out;
}

/// A closed cube of side 2 with an n x n grid on each face (welded at the edges), each square
/// cut along a diagonal: sharp 90-degree creases and corners.
Mesh cube(int n) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> faces;
  const auto index = [&](const Eigen::Vector3d& p) {
    for (std::size_t k = 0; k < points.size(); ++k) {
      if ((points[k] - p).norm() < 1e-9) return static_cast<int>(k);
    }
    points.push_back(p);
    return static_cast<int>(points.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.0, 1.0}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      std::vector<int> grid;
      for (int a = 0; a <= n; ++a) {
        for (int b = 0; b <= n; ++b) {
          Eigen::Vector3d p;
          p[axis] = side;
          p[u] = -1.0 + 2.0 * a / n;
          p[v] = -1.0 + 2.0 * b / n;
          grid.push_back(index(p));
        }
      }
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          const int p00 = grid[a * (n + 1) + b], p10 = grid[(a + 1) * (n + 1) + b],
                    p01 = grid[a * (n + 1) + b + 1], p11 = grid[(a + 1) * (n + 1) + b + 1];
          if (side > 0) {
            faces.emplace_back(p00, p10, p11);
            faces.emplace_back(p00, p11, p01);
          } else {
            faces.emplace_back(p00, p11, p10);
            faces.emplace_back(p00, p01, p11);
          }
        }
      }
    }
  }
  Mesh m;
  m.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t k = 0; k < points.size(); ++k) m.V.row(static_cast<Eigen::Index>(k)) = points[k];
  m.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t k = 0; k < faces.size(); ++k) m.F.row(static_cast<Eigen::Index>(k)) = faces[k];
  return m;
}

/// Creases and corners: the largest screen deviation, the screened vertices, and the
/// leave-one-out heights and misfits at them.
void print_creases(const std::string& name, const Mesh& m) {
  const Found f = find(m);
  const RowMatrixX3d max = vertex_normals(m.V, m.F, NormalWeighting::max);
  std::vector<char> cand(static_cast<std::size_t>(m.V.rows()));
  double worst = 0.0, worst_height = 0.0, misfit = 0.0;
  int screened = 0;
  for (int i = 0; i < m.V.rows(); ++i) {
    cand[static_cast<std::size_t>(i)] = std::abs(f.screen.deviation[i]) > detail::kSpikeScreen;
    if (std::isfinite(f.screen.deviation[i]))
      worst = std::max(worst, std::abs(f.screen.deviation[i]));
  }
  for (int i = 0; i < m.V.rows(); ++i) {
    if (!cand[static_cast<std::size_t>(i)]) continue;
    ++screened;
    const auto off = judge(m, f, i);
    if (std::abs(off.height) > worst_height)
      worst_height = std::abs(off.height), misfit = off.misfit;
  }
  std::printf("%-26s | max dev %.3f screened %d, worst height %.3f (misfit %.3f), found %zu\n",
              name.c_str(), worst, screened, worst_height, misfit, f.spikes.vertices.size());
}

TEST(PositionSpikes, DISABLED_MeasureCreases) {
  for (int n : {500, 3000, 12000})
    print_creases("capped cylinder " + std::to_string(n), make_capped_cylinder(1.0, 2.0, n).mesh);
  for (int n : {2, 3, 4, 8, 16, 32}) print_creases("cube " + std::to_string(n), cube(n));
}

TEST(PositionSpikes, NoneOnCleanMeshesCreasesAndCorners) {
  // Measured (DISABLED_Measure, 8 surfaces x regular/irregular x 850/4000/16000 vertices, strips,
  // graded, seeds 1 and 2): screen deviations at most 0.094 (kSpikeScreen 0.6), leave-one-out
  // heights at most 0.18 at interior and boundary vertices alike (kPositionSpikeOffset 0.75); the
  // capped cylinder's rims screen 0.33; a cube's corners screen 0.76 and stand 0.71 off a quadric
  // whose misfit is 0.46 (1.6 times, kSpikeOverMisfit 4).
  using enum SurfaceKind;
  std::vector<Mesh> meshes;
  for (SurfaceKind k : {torus, helix_tube, monkey_saddle, pear}) {
    meshes.push_back(shaped(k, Triangulation::irregular, 850, 3).mesh);
  }
  meshes.push_back(shaped(saddle, Triangulation::regular, 4000, 1, 20.0).mesh);
  meshes.push_back(shaped(ellipsoid, Triangulation::regular, 4000, 1, 0.2).mesh);
  meshes.push_back(shaped(torus, Triangulation::irregular, 4000, 3, 1.0, 10.0).mesh);
  meshes.push_back(make_capped_cylinder(1.0, 2.0, 3000).mesh);
  for (int n : {2, 3, 8}) meshes.push_back(cube(n));
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    EXPECT_TRUE(find(meshes[k]).spikes.vertices.empty()) << k;
  }
}

TEST(PositionSpikes, AZigZagFanIsJudgedAtBoundedCost) {
  // A polygon of 20000 corners, alternately 0.3 above and below its plane, fan-triangulated
  // around a hub: every corner screens (its 1-ring is the hub and its two neighbours), and
  // every corner's 2-ring holds the hub's 20000 neighbours. Those are not judged (more than
  // kMaxNeighbourhoodSize entries): O(#V) work instead of O(#V^2).
  constexpr int n = 20000;
  Mesh m;
  m.V.resize(n + 1, 3);
  m.V.row(0) << 0.0, 0.0, 0.0;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * 3.141592653589793 * k / n;
    m.V.row(k + 1) << std::cos(a), std::sin(a), k % 2 == 0 ? 0.3 : -0.3;
  }
  m.F.resize(n, 3);
  for (int k = 0; k < n; ++k) m.F.row(k) << 0, 1 + k, 1 + (k + 1) % n;
  const Found f = find(m);
  EXPECT_TRUE(f.spikes.vertices.empty());
}

TEST(PositionSpikes, FindsInteriorSpikesAndPutsThemOnTheSurface) {
  // A sphere of radius 1: the distance of a repaired spike from it is exact truth. Measured at
  // 4000 vertices: every interior spike found, none else.
  for (std::uint64_t seed : {1, 2}) {
    const AnalyticSurface clean = shaped(SurfaceKind::sphere, Triangulation::irregular, 4000, seed);
    AnalyticSurface spiked = clean;
    add_spikes(spiked.mesh, 0.005, 2.0, seed + 4);
    const std::vector<int> truth = moved(clean.mesh, spiked.mesh);
    const Found f = find(spiked.mesh);
    EXPECT_EQ(f.spikes.vertices, truth) << seed;
    const double h = mean_edge_length(clean.mesh.V, clean.mesh.F);
    double worst = 0.0;
    for (const Eigen::Vector3d& p : f.spikes.repaired)
      worst = std::max(worst, std::abs(p.norm() - 1.0) / h);
    // Back on the sphere to a small fraction of an edge (measured 8e-4 and 5e-4 edges at seeds
    // 1 and 2); the spikes were 2 edges off.
    EXPECT_LT(worst, 0.004) << seed;
  }
}

TEST(PositionSpikes, SpikedMeshesWithoutNormalsEstimateAsCleanOnes) {
  // The hard suite's outliers (0.5% spikes of 2 mean edges), no normals. Relative H error before
  // this step (focal eval --suite hard, seed 1): sphere 0.317, torus 0.238, saddle 5.83. Measured
  // now: sphere 1.2e-4 / 7.3e-5 (seeds 1 / 2; clean: exact to 6e-15; bound 1e-3), torus within
  // 1.2% of the clean mesh's (0.00871 against 0.00866, 0.00847 against 0.00837), saddle within
  // 2% (0.01559 / 0.01601 against 0.0155 / 0.0157); bound 1.3 times the clean mesh's.
  for (std::uint64_t seed : {1, 2}) {
    const auto error = [](const AnalyticSurface& a) {
      return evaluate(a, estimate_curvature_recommended(a.mesh.V, a.mesh.F, std::nullopt).curvature)
          .interior.relative_H;
    };
    const auto spiked = [seed](SurfaceKind kind) {
      AnalyticSurface s = shaped(kind, Triangulation::irregular, 4000, seed);
      add_spikes(s.mesh, 0.005, 2.0, seed + 4);
      return s;
    };
    EXPECT_LT(error(spiked(SurfaceKind::sphere)), 1e-3) << seed;
    for (SurfaceKind kind : {SurfaceKind::torus, SurfaceKind::saddle}) {
      const double clean = error(shaped(kind, Triangulation::irregular, 4000, seed));
      EXPECT_LT(error(spiked(kind)), 1.3 * clean) << static_cast<int>(kind) << " seed " << seed;
    }
  }
}

TEST(PositionSpikes, AwayFromSpikesTheEstimateIsTheCleanMeshs) {
  // The repair acts where the spikes are: beyond recommended_reach rings of every spike the
  // spiked mesh's estimate has the clean mesh's bits.
  const AnalyticSurface clean = shaped(SurfaceKind::torus, Triangulation::irregular, 16000, 2);
  AnalyticSurface spiked = clean;
  add_spikes(spiked.mesh, 0.0005, 2.0, 9);
  const std::vector<int> truth = moved(clean.mesh, spiked.mesh);
  ASSERT_FALSE(truth.empty());
  const RecommendedResult a =
      estimate_curvature_recommended(clean.mesh.V, clean.mesh.F, std::nullopt);
  const RecommendedResult b =
      estimate_curvature_recommended(spiked.mesh.V, spiked.mesh.F, std::nullopt);
  ASSERT_EQ(a.plan.rings, b.plan.rings);
  const Neighbourhoods ring = vertex_adjacency(static_cast<int>(clean.mesh.V.rows()), clean.mesh.F);
  std::vector<bool> near(static_cast<std::size_t>(clean.mesh.V.rows()), false);
  for (const int v : truth) near[static_cast<std::size_t>(v)] = true;
  const Eigen::VectorXi distance = rings_to_boundary(ring, near, recommended_reach(a.plan));
  int far = 0;
  for (int i = 0; i < clean.mesh.V.rows(); ++i) {
    if (distance[i] <= recommended_reach(a.plan)) continue;
    ++far;
    ASSERT_EQ(a.curvature.k1[i], b.curvature.k1[i]) << i;
    ASSERT_EQ(a.curvature.k2[i], b.curvature.k2[i]) << i;
  }
  EXPECT_GT(far, 4000);
}

/// Measurement table (docs/notes/estimator-log.md, "Spikes without normals"):
/// build/release/tests/position_spikes_test --gtest_also_run_disabled_tests
///   --gtest_filter='*DISABLED_Measure*'
TEST(PositionSpikes, DISABLED_Measure) {
  using enum SurfaceKind;
  struct Shape {
    std::string name;
    SurfaceKind kind;
    Triangulation t;
    int n;
    double aspect, grading;
  };
  std::vector<Shape> shapes;
  for (SurfaceKind k : all_surfaces()) {
    for (auto t : {Triangulation::regular, Triangulation::irregular}) {
      for (int n : {850, 4000, 16000}) {
        shapes.push_back({std::string(surface_name(k)) +
                              (t == Triangulation::regular ? " reg " : " irr ") + std::to_string(n),
                          k, t, n, 1.0, 1.0});
      }
    }
  }
  shapes.push_back({"cylinder strips 1:8", cylinder, Triangulation::regular, 4000, 1.0 / 8, 1.0});
  shapes.push_back({"sphere lat-long 8:1", sphere, Triangulation::regular, 4000, 8.0, 1.0});
  shapes.push_back({"ellipsoid 1:5", ellipsoid, Triangulation::regular, 4000, 0.2, 1.0});
  shapes.push_back({"torus strips 8:1", torus, Triangulation::regular, 4000, 8.0, 1.0});
  shapes.push_back({"saddle strips 20:1", saddle, Triangulation::regular, 4000, 20.0, 1.0});
  shapes.push_back({"helix strips 1:5", helix_tube, Triangulation::regular, 4000, 0.2, 1.0});
  for (SurfaceKind k : {ellipsoid, torus, saddle, pear})
    shapes.push_back(
        {std::string(surface_name(k)) + " graded", k, Triangulation::irregular, 4000, 1.0, 10.0});
  for (const Shape& sh : shapes) {
    for (std::uint64_t seed : {1, 2}) {
      const AnalyticSurface clean = shaped(sh.kind, sh.t, sh.n, seed, sh.aspect, sh.grading);
      const Found c = find(clean.mesh);
      const RowMatrixX3d max = vertex_normals(clean.mesh.V, clean.mesh.F, NormalWeighting::max);
      double worst = 0.0, worst_height = 0.0;
      int screened = 0;
      for (int i = 0; i < clean.mesh.V.rows(); ++i) {
        const double d = std::abs(c.screen.deviation[i]);
        if (std::isfinite(d)) worst = std::max(worst, d);
        screened += d > detail::kSpikeScreen;
      }
      // Every vertex's leave-one-out height on the clean mesh (interior ones only are judged).
      const VectorXu8 inside =
          interior_mask(static_cast<int>(clean.mesh.V.rows()), clean.mesh.F, 0);
      for (int i = 0; i < clean.mesh.V.rows(); ++i) {
        if (!inside[i]) continue;
        const double h = std::abs(judge(clean.mesh, c, i).height);
        if (std::isfinite(h)) worst_height = std::max(worst_height, h);
      }
      AnalyticSurface spiked = clean;
      add_spikes(spiked.mesh, 0.005, 2.0, seed + 4);
      const std::vector<int> truth = moved(clean.mesh, spiked.mesh);
      const Found s = find(spiked.mesh);
      double least = 1e9;
      for (const int v : truth) least = std::min(least, std::abs(s.screen.deviation[v]));
      int hit = 0;
      double off = 0.0, ratio = 1e9;
      {
        const RowMatrixX3d smax =
            vertex_normals(spiked.mesh.V, spiked.mesh.F, NormalWeighting::max);
        for (const int v : s.spikes.vertices) {
          const auto o = judge(spiked.mesh, s, v);
          ratio = std::min(ratio, std::abs(o.height) / o.misfit);
        }
      }
      for (std::size_t k = 0; k < s.spikes.vertices.size(); ++k) {
        const int v = s.spikes.vertices[k];
        const bool real = std::find(truth.begin(), truth.end(), v) != truth.end();
        hit += real;
        if (real) {
          off = std::max(off, (s.spikes.repaired[k] - clean.mesh.V.row(v).transpose()).norm() /
                                  mean_edge_length(clean.mesh.V, clean.mesh.F));
        }
      }
      {
        const RowMatrixX3d smax =
            vertex_normals(spiked.mesh.V, spiked.mesh.F, NormalWeighting::max);
        std::vector<char> cand(static_cast<std::size_t>(spiked.mesh.V.rows()));
        for (int i = 0; i < spiked.mesh.V.rows(); ++i)
          cand[static_cast<std::size_t>(i)] =
              std::abs(s.screen.deviation[i]) > detail::kSpikeScreen;
        const VectorXu8 in =
            interior_mask(static_cast<int>(spiked.mesh.V.rows()), spiked.mesh.F, 0);
        for (const int v : truth) {
          if (std::find(s.spikes.vertices.begin(), s.spikes.vertices.end(), v) !=
              s.spikes.vertices.end())
            continue;
          int nb = 0;
          for (const int* j = s.ring.begin(v); j != s.ring.end(v); ++j)
            nb += cand[static_cast<std::size_t>(*j)];
          std::printf("   missed %d: interior %d dev %.2f loo %.2f candidate neighbours %d\n", v,
                      in[v], s.screen.deviation[v], judge(spiked.mesh, s, v).height, nb);
        }
      }
      const auto error = [](const AnalyticSurface& a) {
        return evaluate(a,
                        estimate_curvature_recommended(a.mesh.V, a.mesh.F, std::nullopt).curvature)
            .interior.relative_H;
      };
      std::printf(
          "%-26s seed %d | clean: max dev %.3f screened %d max loo %.3f found %zu | spiked: %zu "
          "spikes, min dev %.2f, found %d true %zu all, repaired within %.3f edges, min h/misfit "
          "%.1f | rel H "
          "clean %.4g spiked %.4g\n",
          sh.name.c_str(), static_cast<int>(seed), worst, screened, worst_height,
          c.spikes.vertices.size(), truth.size(), least, hit, s.spikes.vertices.size(), off, ratio,
          error(clean), error(spiked));
    }
  }
}

TEST(PositionSpikes, AVertexMovedSidewaysGoesBackToItsRing) {
  // The hard suite's helix tube: 2% outlier normals, then 0.5% spikes along the file's normals,
  // so a spike at a vertex with an outlier normal moves mostly sideways and folds its faces (at
  // seed 1, vertex 3854: 2 edges at 66 degrees from the surface's normal; its Max normal is 125
  // degrees off). Without normals, relative H error measured 0.01643 / 0.01647 at seeds 1 / 2
  // against 0.0164 / 0.0162 clean (0.036 at seed 1 with Max's normal as the only frame and
  // without the pull back to the ring's centroid; 0.103 / 0.117 before spikes were found from
  // positions).
  for (std::uint64_t seed : {1, 2}) {
    const AnalyticSurface clean =
        shaped(SurfaceKind::helix_tube, Triangulation::irregular, 4000, seed);
    AnalyticSurface s = clean;
    add_outlier_normals(s.mesh, 0.02, seed + 3);
    add_spikes(s.mesh, 0.005, 2.0, seed + 4);
    const auto error = [](const AnalyticSurface& a) {
      return evaluate(a, estimate_curvature_recommended(a.mesh.V, a.mesh.F, std::nullopt).curvature)
          .interior.relative_H;
    };
    EXPECT_LT(error(s), 1.1 * error(clean)) << seed;
    const RecommendedResult r = estimate_curvature_recommended(s.mesh.V, s.mesh.F, std::nullopt);
    EXPECT_EQ(r.crease.cast<int>().sum(), 0) << seed;  // no folded faces left
  }
}

TEST(PositionSpikes, DISABLED_MeasureBoundaries) {
  using enum SurfaceKind;
  for (SurfaceKind k : {saddle, monkey_saddle, cylinder, helix_tube}) {
    for (auto t : {Triangulation::regular, Triangulation::irregular}) {
      for (int n : {850, 4000, 16000}) {
        for (std::uint64_t seed : {1, 2}) {
          const AnalyticSurface clean = shaped(k, t, n, seed);
          const std::vector<bool> boundary =
              boundary_vertices(static_cast<int>(clean.mesh.V.rows()), clean.mesh.F);
          const Found c = find(clean.mesh);
          double dev = 0, height = 0;
          int few = 0, judged = 0;
          for (int i = 0; i < clean.mesh.V.rows(); ++i) {
            if (!boundary[static_cast<std::size_t>(i)]) continue;
            if (std::isfinite(c.screen.deviation[i]))
              dev = std::max(dev, std::abs(c.screen.deviation[i]));
            const auto o = judge(clean.mesh, c, i);
            if (!std::isfinite(o.height)) {
              ++few;
              continue;
            }
            ++judged;
            height = std::max(height, std::abs(o.height));
          }
          AnalyticSurface spiked = clean;
          add_spikes(spiked.mesh, 0.02, 2.0, seed + 4);
          const Found f = find(spiked.mesh);
          double sdev = 1e9, sheight = 1e9;
          int count = 0;
          for (const int v : moved(clean.mesh, spiked.mesh)) {
            if (!boundary[static_cast<std::size_t>(v)]) continue;
            ++count;
            sdev = std::min(sdev, std::abs(f.screen.deviation[v]));
            const auto o = judge(spiked.mesh, f, v);
            sheight = std::min(sheight, std::isfinite(o.height) ? std::abs(o.height) : -1.0);
          }
          std::printf(
              "%-14s %s %5d seed %d | clean boundary: max dev %.3f, judged %d (few %d), max height "
              "%.3f | %d boundary spikes: min dev %.2f min height %.2f\n",
              std::string(surface_name(k)).c_str(), t == Triangulation::regular ? "reg" : "irr", n,
              static_cast<int>(seed), dev, judged, few, height, count, sdev, sheight);
        }
      }
    }
  }
}


}  // namespace
}  // namespace focal
