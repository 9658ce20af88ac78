#include <cstdio>
#include <filesystem>
#include <memory>
#include <system_error>

#include "commands.h"
#include "estimator_flags.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/io/fields_io.h"
#include "focal/io/mesh_io.h"
#include "input_check.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct CurvatureFlags {
  std::string input;
  std::string output;
  bool ascii = false;
  bool force = false;
  int tiles = 0;  ///< --tiles: 0, the whole mesh at once
  EstimatorFlags estimator;
  OutputFlags out;

  [[nodiscard]] WriteOptions csv_options() const { return {.precision = out.precision()}; }
  [[nodiscard]] PlyWriteOptions ply_options() const {
    return {.binary = !ascii, .comments = {}, .precision = out.precision()};
  }
};

struct FocalMeshFlags {
  std::string input;
  std::string prefix;
  bool ascii = false;
  bool force = false;
  EstimatorFlags estimator;
  FocalMeshOptions focal;
  OutputFlags out;
};

void run_curvature(CurvatureFlags& f, const Log& log) {
  const ExecutionScope scope({.threads = f.estimator.threads});
  Input input(f.input, f.estimator, log);
  Estimate e = run_estimate(input, f.estimator, log, f.tiles);
  Stage stage(log, "write");
  if (lower_extension(f.output) == ".csv") {
    write_curvature_csv(f.output, e.curvature, e.crease, f.csv_options());
    return;
  }
  // The mesh as the estimator saw it (input.prepared is not used after this).
  Mesh& mesh = input.mesh;
  if (e.F) mesh.F = std::move(*e.F);
  if (e.N) mesh.N = std::move(*e.N);
  write_curvature_ply(f.output, mesh, e.curvature, f.ply_options(), e.crease);
}

/// The focal meshes of a mesh, or the focal point clouds (no faces) of a point cloud.
FocalMeshes focal_meshes_of(const Input& input, FocalMeshFlags& f, const Log& log) {
  const FocalMeshOptions& o = f.focal;
  const Estimate e = run_estimate(input, f.estimator, log);
  if (input.cloud) {
    Stage stage(log, "focal points");
    return focal_meshes(input.mesh.V, RowMatrixX3i(0, 3), *e.N, e.curvature, o);
  }
  Stage stage(log, "focal meshes");
  return focal_meshes(estimated_mesh(input, e), e.curvature, o);
}

void run_focal_mesh(FocalMeshFlags& f, const Log& log) {
  const ExecutionScope scope({.threads = f.estimator.threads});
  const Input input(f.input, f.estimator, log);
  const FocalMeshes meshes = focal_meshes_of(input, f, log);
  Stage stage(log, "write");
  const PlyWriteOptions o{.binary = !f.ascii, .comments = {}, .precision = f.out.precision()};
  // All or nothing: a failed run leaves neither new focal mesh, and existing files as they were.
  write_focal_meshes_ply(f.prefix + ".focal1.ply", f.prefix + ".focal2.ply", meshes, o);
  std::printf("wrote %s.focal1.ply (%lld faces) and %s.focal2.ply (%lld faces)\n", f.prefix.c_str(),
              static_cast<long long>(meshes.gamma1.mesh.F.rows()), f.prefix.c_str(),
              static_cast<long long>(meshes.gamma2.mesh.F.rows()));
}

}  // namespace

void add_curvature_command(CLI::App& app, const Log& log) {
  auto* cmd = app.add_subcommand("curvature", "Principal curvatures and directions per vertex");
  auto f = std::make_shared<CurvatureFlags>();
  cmd->add_option("input", f->input,
                  "mesh or point cloud (.obj .ply .off .stl .xyz .xyzn .xyzrgb .pwn .pts .txt .csv "
                  ".pcd .las)")
      ->required();
  cmd->add_option("-o,--output", f->output,
                  "OUT.csv (one row per input vertex) or OUT.ply (the mesh with per-vertex "
                  "properties k1,k2,H,K,d1x..d2z,residual,class, and crease from the recommended "
                  "estimator)")
      ->required();
  cmd->add_flag("--ascii", f->ascii, "write ascii PLY instead of binary");
  f->out.add_to(*cmd);
  f->estimator.add_to(*cmd);
  cmd->footer(
      "Columns: k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,residual,class (k1 >= k2; outward normals;\n"
      "a sphere of radius r has k1 = k2 = +1/r), then crease (1 at a vertex on a sharp edge,\n"
      "where the curvature does not exist) from the recommended estimator. Examples:\n"
      "  focal curvature bunny.off -o bunny.csv          # the recommended estimator\n"
      "  focal curvature bunny.off -o bunny.csv --paper  # the paper's method as written\n"
      "  focal curvature scan.ply -o scan-curvature.ply --rings 2 --normals max -v\n"
      "  focal curvature scan.ply -o scan.csv --float32   # floats: CSV ~40% smaller\n"
      "With no estimator option, the recommended estimator runs: the two-slit fit of the file's\n"
      "normals fused with normals from local cubic fits of the positions (or of those alone),\n"
      "on a wider neighbourhood where the positions are noisy (docs/METHOD.md).");
  cmd->add_flag("--force", f->force, "replace a read-only output file");
  cmd->add_option("--tiles", f->tiles,
                  "estimate the mesh (or cloud) in N spatial tiles with halos, one after the "
                  "other: the same numbers, the memory of one tile's estimate (docs/SCALE.md; "
                  ".csv output). "
                  "On a Dask cluster: python -m focal.distributed")
      ->check(CLI::PositiveNumber);
  cmd->parse_complete_callback([f] {
    if (f->tiles > 0) require_extension("-o", f->output, {".csv"});
    require_extension("-o", f->output, {".csv", ".ply"});
    check_output("-o", f->output, f->input, f->force);
  });
  cmd->callback([f, &log] { run_curvature(*f, log); });
}

void add_focal_mesh_command(CLI::App& app, const Log& log) {
  auto* cmd =
      app.add_subcommand("focal-mesh", "The two focal meshes Gamma_1, Gamma_2 (paper eq. 2)");
  auto f = std::make_shared<FocalMeshFlags>();
  cmd->add_option("input", f->input,
                  "mesh or point cloud (.obj .ply .off .stl .xyz .xyzn .xyzrgb .pwn .pts .txt .csv "
                  ".pcd .las)")
      ->required();
  cmd->add_option("-o,--output", f->prefix, "writes PREFIX.focal1.ply and PREFIX.focal2.ply")
      ->required();
  cmd->add_option("--max-distance", f->focal.max_distance,
                  "clamp focal points farther than this (0 = 10 x bounding-box diagonal)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--drop-infinite", f->focal.drop_faces_at_infinity,
                "leave out faces touching a focal point at infinity or undefined");
  cmd->add_flag("--ascii", f->ascii, "write ascii PLY instead of binary");
  f->out.add_to(*cmd);
  f->estimator.add_to(*cmd);
  cmd->footer(
      "Example:\n  focal focal-mesh bunny.off -o bunny   # bunny.focal1.ply, bunny.focal2.ply");
  cmd->add_flag("--force", f->force, "replace read-only output files");
  cmd->parse_complete_callback([f] {
    check_output("-o", f->prefix + ".focal1.ply", f->input, f->force);
    check_output("-o", f->prefix + ".focal2.ply", f->input, f->force);
  });
  cmd->callback([f, &log] { run_focal_mesh(*f, log); });
}

}  // namespace focal::cli
