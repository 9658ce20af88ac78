// The front door (focal/curvature.h): one call for meshes and clouds that gives, field for field
// and bit for bit, what the steps it runs give when called one by one, and reports its stages,
// warnings and cancellation through Execution.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/curvature.h"
#include "focal/curvature/baselines.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/tiles/tiles.h"
#include "test_clouds.h"
#include "test_identical.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

Mesh torus(int vertices = 1500) {
  return test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, vertices, 0.0, 3)
      .mesh;
}

EstimateOptions with(Estimator estimator) {
  EstimateOptions o;
  o.estimator = estimator;
  return o;
}

TEST(FrontDoor, MeshGivesTheTwoStepsBitForBit) {
  const Mesh mesh = torus();
  for (const Estimator estimator : {Estimator::recommended, Estimator::paper}) {
    const PreparedMesh prepared(mesh);
    const EstimateOptions o = with(estimator);
    const Estimate steps = estimate(prepared, o);
    const Estimate door = curvature(mesh, o);
    test::expect_identical(door.curvature, steps.curvature, "front door");
    EXPECT_EQ(door.crease, steps.crease);
    EXPECT_EQ(door.file_normals_used, steps.file_normals_used);
    EXPECT_EQ(door.undefined_count, 0);
    EXPECT_FALSE(door.cloud.has_value());
  }
}

TEST(FrontDoor, TheSameBitsForAnyThreadCount) {
  const Mesh mesh = torus();
  EstimateOptions one;
  one.execution.threads = 1;
  EstimateOptions three;
  three.execution.threads = 3;
  test::expect_identical(curvature(mesh, one).curvature, curvature(mesh, three).curvature,
                         "threads 1 vs 3");
  // An enclosing scope's count is taken where the options' is 0, and theirs wins over it.
  const EstimateOptions defaults;
  test::expect_identical(test::on_threads(2, [&] { return curvature(mesh, defaults); }).curvature,
                         test::on_threads(2, [&] { return curvature(mesh, three); }).curvature,
                         "scope of 2, options 0 vs 3");
}

TEST(FrontDoor, TilesGiveTheWholeMeshBits) {
  const Mesh mesh = torus(3000);
  EstimateOptions tiled;
  tiled.tile_vertices = 700;
  const Estimate whole = curvature(mesh);
  const Estimate tiles = curvature(mesh, tiled);
  test::expect_identical(tiles.curvature, whole.curvature, "tiles of 700");
  EXPECT_EQ(tiles.crease, whole.crease);
}

TEST(FrontDoor, BaselinesAreTheirOwnFunctions) {
  const Mesh mesh = torus();
  test::expect_identical(curvature(mesh, with(Estimator::meyer_2003)).curvature,
                         baselines::meyer_2003(mesh.V, mesh.F), "MDSB03");
  test::expect_identical(curvature(mesh, with(Estimator::lachaud_2020)).curvature,
                         baselines::lachaud_2020(mesh.V, mesh.F, mesh.normals()), "LRTC20");
  test::expect_identical(curvature(mesh, with(Estimator::grinspun_2006)).curvature,
                         baselines::grinspun_2006(mesh.V, mesh.F), "GGRZ06");
}

TEST(FrontDoor, CloudGivesTheCloudEstimateAndItsPlan) {
  const AnalyticSurface s = test::cloud_of(SurfaceKind::ellipsoid, 3000);
  Mesh cloud = s.mesh;
  cloud.N.resize(0, 3);  // normals estimated from the positions
  ASSERT_TRUE(cloud.is_cloud());
  const CloudCurvature direct = estimate_cloud_curvature(cloud.V, std::nullopt);
  const Estimate door = curvature(cloud);
  test::expect_identical(door.curvature, direct.curvature, "cloud");
  ASSERT_TRUE(door.cloud.has_value());
  EXPECT_TRUE(door.cloud->normals_estimated);
  EXPECT_EQ(door.cloud->k, direct.k);
  EXPECT_EQ(door.cloud->spacing, direct.spacing);
  ASSERT_TRUE(door.N.has_value());
  EXPECT_TRUE(((door.N->array() == direct.N.array()) ||
               (door.N->array().isNaN() && direct.N.array().isNaN()))
                  .all());
  // The analytic truth: the ellipsoid's mean curvature within the cloud tests' bound.
  EXPECT_LT(test::h_error(s, door.curvature).relative_rms, 0.05);
}

TEST(FrontDoor, StagesAreReportedInOrderAndClosed) {
  std::vector<std::string> events;
  EstimateOptions o;
  o.execution.progress = [&](const Progress& p) {
    events.push_back(std::string(p.stage) + (p.fraction == 0.0 ? " begins" : " ends"));
  };
  (void)curvature(torus(), o);
  const std::vector<std::string> expected = {"normals begins", "normals ends", "curvature begins",
                                             "curvature ends"};
  EXPECT_EQ(events, expected);
}

TEST(FrontDoor, WarningsGoToTheSink) {
  Mesh mesh = torus();
  mesh.N.row(7) << 0.0, 0.0, 0.0;  // a zero file normal: filled from the faces
  std::vector<std::string> warnings;
  EstimateOptions o = with(Estimator::paper);
  o.execution.warning = [&](const std::string& w) { warnings.push_back(w); };
  (void)curvature(mesh, o);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "1 vertices have no usable normal in the file; estimated them from the faces");
}

TEST(FrontDoor, CancelledBeforeAStageStops) {
  std::atomic<bool> cancel{true};
  EstimateOptions o;
  o.execution.cancel = &cancel;
  EXPECT_THROW((void)curvature(torus(), o), Cancelled);
}

TEST(FrontDoor, OptionsThatDoNotApplyAreErrors) {
  Mesh cloud = test::cloud_of(SurfaceKind::sphere, 500).mesh;
  EXPECT_THROW((void)curvature(cloud, with(Estimator::meyer_2003)), InvalidInput);
  EstimateOptions area;
  area.estimator = Estimator::paper;
  area.normals = NormalsSource::area;
  EXPECT_THROW((void)curvature(cloud, area), InvalidInput);
  Mesh bare = torus();
  bare.N.resize(0, 3);
  EstimateOptions file;
  file.normals = NormalsSource::file;
  EXPECT_THROW((void)curvature(bare, file), InvalidInput);
  EstimateOptions negative;
  negative.execution.threads = -1;  // ExecutionScope's check
  EXPECT_THROW((void)curvature(bare, negative), InvalidInput);
}

TEST(FrontDoor, TheDeviceRunsThePaperFitOrSaysWhyNot) {
  const Mesh mesh = torus();
  EstimateOptions o = with(Estimator::paper);
  o.device = Device::cuda;
  Estimate device;
  try {
    device = curvature(mesh, o);
  } catch (const DeviceError& e) {
    // No GPU here, or a build without CUDA: an error that says so, never CPU results.
    EXPECT_EQ(std::getenv("FOCAL_REQUIRE_GPU"), nullptr) << e.what();
    return;
  }
  // float32 on the device against the double CPU path: |k| <= ~3 here, so 1e-3 is far above
  // float rounding of the 2x2 solve and far below any estimator difference.
  const Estimate cpu = curvature(mesh, with(Estimator::paper));
  ASSERT_EQ(device.curvature.H.size(), cpu.curvature.H.size());
  EXPECT_LT((device.curvature.H - cpu.curvature.H).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace focal
