// Point clouds in tiles (focal/tiles/tiles.h): tile by tile, the cloud estimator gives the same
// bits as on the whole cloud, with the file's normals and without, with outliers, on graded
// density and noisy positions, for the default and given k or radius; the halo holds each owned
// point's neighbours by construction, and one step less changes the result.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/points/neighbours.h"
#include "focal/surfaces/cloud_samples.h"
#include "focal/tiles/tiles.h"
#include "test_identical.h"
#include "test_threads.h"

namespace focal {
namespace {

using test::expect_identical;

AnalyticSurface cloud(SurfaceKind kind, int points, std::uint64_t seed, double noise, double graded,
                      double outliers) {
  CloudSampleOptions o;
  o.surface.kind = kind;
  o.surface.target_vertices = points;
  o.surface.seed = seed;
  o.position_noise = noise;
  o.graded = graded;
  o.outliers = outliers;
  return sample_cloud(o);
}

struct Case {
  std::string name;
  AnalyticSurface s;
};

std::vector<Case> clouds() {
  std::vector<Case> out;
  out.push_back({"torus", cloud(SurfaceKind::torus, 2500, 1, 0.0, 0.0, 0.0)});
  out.push_back({"graded saddle", cloud(SurfaceKind::saddle, 2000, 2, 0.0, 0.6, 0.0)});
  out.push_back({"ellipsoid 2% outliers", cloud(SurfaceKind::ellipsoid, 2500, 2, 0.0, 0.0, 0.02)});
  // 10% position noise: the default plans 64 neighbours and quadratic jets.
  out.push_back({"noisy pear", cloud(SurfaceKind::pear, 2000, 3, 0.1, 0.0, 0.0)});
  // A point with a NaN coordinate and exact duplicates (ties broken by index in the tiles too).
  AnalyticSurface odd = cloud(SurfaceKind::sphere, 1500, 4, 0.0, 0.0, 0.0);
  odd.mesh.V.row(7).setConstant(NAN);
  odd.mesh.V.row(20) = odd.mesh.V.row(21);
  odd.mesh.N.row(20) = odd.mesh.N.row(21);
  out.push_back({"sphere NaN duplicates", odd});
  return out;
}

TEST(CloudTiles, TheTilesGiveTheWholeCloudsBits) {
  const std::vector<CloudOptions> options{{},
                                          {.k = 10},
                                          {.radius = 0.15},
                                          {.outlier_ratio = 0.0},
                                          {.k = 8, .solver = Solver::levenberg_marquardt}};
  const std::vector<std::string> names{"default", "k 10", "radius 0.15", "no outlier test",
                                       "k 8 levenberg-marquardt"};
  bool wide_plan = false, outliers = false, estimated = false, corrected = false;
  for (const Case& c : clouds()) {
    for (std::size_t o = 0; o < options.size(); ++o) {
      for (const bool normals : {true, false}) {
        if (o == 4 && !normals) continue;  // the solver is the same without normals
        const std::optional<NormalsRef> N =
            normals ? std::optional<NormalsRef>(c.s.mesh.N) : std::nullopt;
        const std::string what =
            c.name + ", " + names[o] + (normals ? ", the file's normals" : ", no normals");
        // The whole run on 3 threads, the tiled one on 1: no thread count shows in the bits.
        const CloudCurvature whole = test::on_threads(
            3, [&] { return estimate_cloud_curvature(c.s.mesh.V, N, options[o]); });
        const TileEstimate tiled = test::on_threads(1, [&] {
          return estimate_cloud_tiled(c.s.mesh.V, N, options[o], {.tile_vertices = 313});
        });
        expect_identical(whole.curvature, tiled.curvature, what);
        EXPECT_EQ(tiled.crease.size(), 0) << what;
        wide_plan |= whole.k == 4 * default_cloud_neighbours;
        outliers |= std::count(whole.outlier.begin(), whole.outlier.end(), 1) > 0;
        estimated |= whole.normals_estimated;
        corrected |= whole.corrected;
      }
    }
  }
  // The cases reach every branch of the plan: 64 neighbours, outliers left out, normals
  // estimated, the corrected step on local triangulations.
  EXPECT_TRUE(wide_plan && outliers && estimated && corrected);
}

TEST(CloudTiles, EveryPointIsOwnedOnceWithItsNeighboursInItsTile) {
  const AnalyticSurface s = cloud(SurfaceKind::torus, 2000, 5, 0.0, 0.3, 0.0);
  const Neighbourhoods nb = nearest_neighbours(s.mesh.V, 16);
  const auto n = static_cast<int>(s.mesh.V.rows());
  for (const int depth : {1, 2}) {
    const Tiling tiling = partition_cloud(s.mesh.V, nb, depth, {.tile_vertices = 170});
    EXPECT_EQ(tiling.halo_rings, depth);
    std::vector<int> owner(static_cast<std::size_t>(n), -1);
    for (std::size_t t = 0; t < tiling.tiles.size(); ++t) {
      const Tile& tile = tiling.tiles[t];
      ASSERT_TRUE(std::is_sorted(tile.vertices.begin(), tile.vertices.end()));
      EXPECT_TRUE(tile.faces.empty());
      std::vector<char> in(static_cast<std::size_t>(n), 0);
      for (int v : tile.vertices) in[static_cast<std::size_t>(v)] = 1;
      for (int r : tile.owned) {
        const int v = tile.vertices[static_cast<std::size_t>(r)];
        EXPECT_EQ(owner[static_cast<std::size_t>(v)], -1) << v << " owned twice";
        owner[static_cast<std::size_t>(v)] = static_cast<int>(t);
        for (const int* j = nb.begin(v); j != nb.end(v); ++j) {
          ASSERT_TRUE(in[static_cast<std::size_t>(*j)]);
          if (depth == 2) {
            for (const int* l = nb.begin(*j); l != nb.end(*j); ++l)
              ASSERT_TRUE(in[static_cast<std::size_t>(*l)]);
          }
        }
      }
    }
    for (int v = 0; v < n; ++v) EXPECT_NE(owner[static_cast<std::size_t>(v)], -1) << v;
  }
  // Any thread count: the same tiles.
  const auto partition = [&] { return partition_cloud(s.mesh.V, nb, 1, {.tile_vertices = 170}); };
  const Tiling one = test::on_threads(1, partition);
  const Tiling three = test::on_threads(3, partition);
  ASSERT_EQ(one.tiles.size(), three.tiles.size());
  for (std::size_t t = 0; t < one.tiles.size(); ++t) {
    EXPECT_EQ(one.tiles[t].vertices, three.tiles[t].vertices);
    EXPECT_EQ(one.tiles[t].owned, three.tiles[t].owned);
  }
}

TEST(CloudTiles, AHaloOneStepShortChangesTheResult) {
  // Depth 0 (the owned points alone): the points at a tile's border lose neighbours.
  const AnalyticSurface s = cloud(SurfaceKind::torus, 2500, 6, 0.0, 0.0, 0.02);
  for (const bool normals : {true, false}) {
    const std::optional<NormalsRef> N =
        normals ? std::optional<NormalsRef>(s.mesh.N) : std::nullopt;
    const CloudOptions options{};
    const CloudCurvature plan = plan_cloud_curvature(s.mesh.V, N, options);
    CloudCurvature whole = plan;
    fit_cloud_curvature(s.mesh.V, whole, options);
    const CloudWideChoices choices{plan.spacing, plan.k, plan.corrected};
    for (const int depth : {0, 1}) {
      const Tiling tiling =
          partition_cloud(s.mesh.V, plan.neighbours, depth, {.tile_vertices = 300});
      TileEstimate tiled{whole.curvature, {}};
      for (const Tile& tile : tiling.tiles) {
        scatter_rows(estimate_cloud_tile(extract_cloud_tile(s.mesh.V, plan.N, plan.outlier, tile),
                                         choices, options),
                     tile.owned, tile.vertices, tiled);
      }
      if (depth == 1) {
        expect_identical(whole.curvature, tiled.curvature, "depth 1");
      } else {
        EXPECT_FALSE(tiled.curvature.k1.cwiseEqual(whole.curvature.k1).all()) << normals;
      }
    }
  }
}

TEST(CloudTiles, RejectsBadArguments) {
  const AnalyticSurface s = cloud(SurfaceKind::sphere, 200, 1, 0.0, 0.0, 0.0);
  const Neighbourhoods nb = nearest_neighbours(s.mesh.V, 8);
  EXPECT_THROW((void)partition_cloud(s.mesh.V, nb, -1), InvalidInput);
  EXPECT_THROW((void)partition_cloud(s.mesh.V, nb, 1, {.tile_vertices = 0}), InvalidInput);
  EXPECT_THROW((void)partition_cloud(s.mesh.V.topRows(100), nb, 1), InvalidInput);
  Tile tile{{0, 1, static_cast<int>(s.mesh.V.rows())}, {}, {0}};
  EXPECT_THROW((void)extract_cloud_tile(s.mesh.V, s.mesh.N, {}, tile), InvalidInput);
  tile.vertices.pop_back();
  EXPECT_THROW((void)extract_cloud_tile(s.mesh.V, s.mesh.N.topRows(10), {}, tile), InvalidInput);
  EXPECT_THROW((void)extract_cloud_tile(s.mesh.V, s.mesh.N, std::vector<char>(3, 0), tile),
               InvalidInput);
  // Adaptive radii read beyond the halo: refused, not silently different.
  CloudOptions adaptive;
  adaptive.adaptive_radius = 1.0;
  EXPECT_THROW((void)estimate_cloud_tiled(s.mesh.V, s.mesh.normals(), adaptive), InvalidInput);
}

}  // namespace
}  // namespace focal
