// `focal normals IN -o OUT`: estimated, oriented normals written with the positions (and faces).
// Meshes: the normals focal's estimator fits (the recommended estimator's choice: file normals
// where they agree with the positions, else jet normals; or the paper's with --paper ...).
// Point clouds: the normals the cloud curvature default fits with (estimate_cloud_normals,
// focal/curvature/cloud_curvature.h: jets over 16 neighbours, or 64 on noisy positions, the file's
// where they agree); with --k, --radius or --adaptive-radius PCA + jet normals over those
// neighbours, each on the side of the file's normal where it has one, else towards --viewpoint,
// else by a minimum spanning tree (focal/normals/cloud_normals.h). The paper's future work: "use
// focal surfaces to fix vertex normals of scanned surfaces".

#include <memory>
#include <string>

#include "commands.h"
#include "estimator_flags.h"
#include "focal/core/execution.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/io/mesh_io.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct NormalsFlags {
  std::string input;
  std::string output;
  bool force = false;
  EstimatorFlags estimator;
  OutputFlags out;
};

void run_normals(NormalsFlags& f, const Log& log) {
  const ExecutionScope scope({.threads = f.estimator.threads});
  Input input(f.input, f.estimator, log);
  RowMatrixX3d N;
  if (input.cloud) {
    Stage stage(log, "cloud normals");
    N = estimate_cloud_normals(input.mesh.V, input.mesh.normals(), f.estimator.cloud_options());
    const Eigen::Index missing = (!N.array().isFinite()).rowwise().any().count();
    if (missing > 0) {
      log.warning(std::to_string(missing) + " of " + std::to_string(N.rows()) +
                  " points have no normal (NaN): outliers left out (--outlier-ratio 0 "
                  "--off-surface-ratio 0 keep every point) or points without neighbours");
    }
  } else {
    Estimate e = run_estimate(input, f.estimator, log);
    N = e.N ? std::move(*e.N) : input.mesh.N;
    if (e.F) input.mesh.F = std::move(*e.F);
  }
  Stage stage(log, "write");
  input.mesh.N = std::move(N);
  write_mesh(f.output, input.mesh, {.precision = f.out.precision()});
}

}  // namespace

void add_normals_command(CLI::App& app, const Log& log) {
  auto* cmd = app.add_subcommand("normals", "Estimated, oriented vertex normals (meshes, clouds)");
  auto f = std::make_shared<NormalsFlags>();
  cmd->add_option("input", f->input,
                  "mesh or point cloud (.obj .ply .off .stl .xyz .xyzn .xyzrgb .pwn .pts .txt .csv "
                  ".pcd .las)")
      ->required();
  cmd->add_option("-o,--output", f->output,
                  "OUT.ply, .obj, .off, .xyz or .xyzn: positions, faces, normals")
      ->required();
  f->out.add_to(*cmd);
  f->estimator.add_to(*cmd);
  cmd->add_flag("--force", f->force, "replace a read-only output file");
  cmd->footer(
      "Examples:\n"
      "  focal normals scan.xyz -o scan-normals.ply              # those `curvature` uses\n"
      "  focal normals scan.xyz -o out.xyz --viewpoint 0,0,10 --k 24\n"
      "  focal normals bunny.off -o bunny-normals.ply            # what the estimator fits\n"
      "Clouds get the normals of the curvature default (jets over 16 neighbours, 64 on noisy\n"
      "positions; the file's where they agree with them); with --k/--radius PCA + jets over\n"
      "those, on the side of the file's normals. Meshes get the recommended estimator's\n"
      "normals (docs/POINTS.md, docs/METHOD.md).");
  cmd->parse_complete_callback([f] {
    require_extension("-o", f->output, {".ply", ".obj", ".off", ".xyz", ".xyzn"});
    check_output("-o", f->output, f->input, f->force);
  });
  cmd->callback([f, &log] { run_normals(*f, log); });
}

}  // namespace focal::cli
