// The recommended estimator's spike repair (src/curvature/spike_repair.h): the offsets on
// analytic surfaces with exact normals, which vertices count as spikes (not outlier normals,
// not creases), the repaired positions against the surface, and the estimate on spiked meshes.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "curvature/spike_repair.h"
#include "focal/curvature/recommended.h"
#include "focal/evaluation/evaluation.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/surfaces/surfaces.h"
#include "test_meshes.h"

namespace focal {
namespace {

using test::analytic_surface;

Neighbourhoods ring_of(const Mesh& m) {
  return vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
}

RowMatrixX3d unit(const RowMatrixX3d& N) { return N.rowwise().normalized(); }

/// Moves `vertices` by `edges` mean edge lengths along their normals, alternately up and down.
void spike(Mesh& m, const std::vector<int>& vertices, double edges) {
  const double h = mean_edge_length(m.V, m.F);
  double side = 1.0;
  for (const int v : vertices) {
    m.V.row(v) += side * edges * h * m.N.row(v).normalized();
    side = -side;
  }
}

TEST(SpikeRepair, OffsetsAreSecondOrderSmallOnSmoothSurfaces) {
  // Exact normals: (p_i - p_j) . (n_i + n_j) cancels the curvature's k |e|^2 / 2 to third order,
  // so the offset falls faster than the edge length; the distance from the neighbours' planes
  // alone is first order (k |e| / 2 in edge lengths).
  for (SurfaceKind kind : {SurfaceKind::sphere, SurfaceKind::torus, SurfaceKind::saddle}) {
    double previous = NAN;
    for (int n : {1000, 4000, 16000}) {
      const AnalyticSurface s = analytic_surface(kind, Triangulation::irregular, n, 0.0, 1);
      const Eigen::VectorXd t = detail::normal_offsets(s.mesh.V, unit(s.mesh.N), ring_of(s.mesh), 1);
      const double worst = t.cwiseAbs().maxCoeff();
      EXPECT_LT(worst, 0.05) << n;
      if (std::isfinite(previous)) {
        EXPECT_LT(worst, 0.6 * previous + 1e-12) << n;  // h halves: / 2 or more; sphere: 0
      }
      previous = worst;
      const Eigen::VectorXd planes =
          detail::normal_offsets(s.mesh.V, unit(s.mesh.N), ring_of(s.mesh), 1, false);
      EXPECT_LT(planes.cwiseAbs().maxCoeff(), 0.25) << n;
      EXPECT_TRUE(detail::find_spikes(s.mesh.V, unit(s.mesh.N), ring_of(s.mesh), t).empty()) << n;
    }
  }
}

TEST(SpikeRepair, FindsSpikesAndRepairsThemOntoTheSurface) {
  AnalyticSurface s = analytic_surface(SurfaceKind::torus, Triangulation::irregular, 4000, 0.0, 1);
  const RowMatrixX3d truth = s.mesh.V;
  const std::vector<int> spikes = {17, 901, 2222, 3500};
  spike(s.mesh, spikes, 2.0);
  // An outlier normal elsewhere: the vertex stays on its neighbours' planes, not a spike.
  RowMatrixX3d N = unit(s.mesh.N);
  N.row(1500) = Eigen::RowVector3d(0.6, 0.0, 0.8);
  const Neighbourhoods ring = ring_of(s.mesh);
  const Eigen::VectorXd t = detail::normal_offsets(s.mesh.V, N, ring, 1);
  std::vector<int> found = detail::find_spikes(s.mesh.V, N, ring, t);
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, spikes);
  const RowMatrixX3d repaired = detail::repaired_positions(s.mesh.V, N, ring, t, found);
  const double h = mean_edge_length(truth, s.mesh.F);
  for (int i = 0; i < truth.rows(); ++i) {
    const bool moved = std::find(spikes.begin(), spikes.end(), i) != spikes.end();
    // Back on the torus to a small fraction of an edge (measured under 0.005 edges); the rest
    // untouched, bit for bit.
    if (moved) {
      EXPECT_LT((repaired.row(i) - truth.row(i)).norm(), 0.02 * h) << i;
    } else {
      EXPECT_TRUE(repaired.row(i) == s.mesh.V.row(i)) << i;
    }
  }
}

TEST(SpikeRepair, CreasesAndNoiseAreNotSpikes) {
  // The capped cylinder's rims: a line of vertices whose normals belong to two pieces.
  const AnalyticSurface capped = make_capped_cylinder(1.0, 2.0, 3000);
  const Neighbourhoods ring = ring_of(capped.mesh);
  const RowMatrixX3d N = unit(capped.mesh.N);
  EXPECT_TRUE(
      detail::find_spikes(capped.mesh.V, N, ring, detail::normal_offsets(capped.mesh.V, N, ring, 1))
          .empty());
  // 10% vertex noise moves whole neighbourhoods by a tenth of an edge.
  AnalyticSurface noisy = analytic_surface(SurfaceKind::torus, Triangulation::irregular, 4000, 0.0, 3);
  add_position_noise(noisy.mesh, 0.1, 3);
  const Neighbourhoods noisy_ring = ring_of(noisy.mesh);
  const RowMatrixX3d M = unit(noisy.mesh.N);
  EXPECT_TRUE(detail::find_spikes(noisy.mesh.V, M, noisy_ring,
                                  detail::normal_offsets(noisy.mesh.V, M, noisy_ring, 1))
                  .empty());
}

TEST(SpikeRepair, TheRecommendedEstimateWithSpikesIsTheCleanMeshs) {
  // 0.5% spikes of 2 edges with exact file normals (the hard suite's outliers): before the
  // repair the spikes' 2-rings took the crease handling (relative H error on the torus, focal
  // eval at 4000 vertices: 0.017 against 0.0036 clean); repaired, the estimate is within 1.5x
  // of the clean mesh's at every vertex set scored.
  for (SurfaceKind kind : {SurfaceKind::torus, SurfaceKind::saddle}) {
    const AnalyticSurface clean = analytic_surface(kind, Triangulation::irregular, 4000, 0.0, 2);
    AnalyticSurface spiked = clean;
    add_spikes(spiked.mesh, 0.005, 2.0, 5);
    const double before = evaluate(clean, estimate_curvature_recommended(
                                              clean.mesh.V, clean.mesh.F, clean.mesh.normals())
                                              .curvature)
                              .interior.relative_H;
    const RecommendedResult r =
        estimate_curvature_recommended(spiked.mesh.V, spiked.mesh.F, spiked.mesh.normals());
    const double after = evaluate(spiked, r.curvature).interior.relative_H;
    EXPECT_LT(after, 1.5 * before) << static_cast<int>(kind);
    EXPECT_EQ(r.crease.cast<int>().sum(), 0) << static_cast<int>(kind);
  }
}

}  // namespace
}  // namespace focal
