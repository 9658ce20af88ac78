// `focal normals IN -o OUT`: estimated, oriented normals written with the positions (and faces).
// Meshes: the normals focal's estimator fits (the recommended estimator's choice: file normals
// where they agree with the positions, else jet normals; or the paper's with --paper ...).
// Point clouds: PCA + jet normals over the k nearest neighbours, oriented by the file's normals
// where it has them (each takes the side of the given one), else towards --viewpoint, else by a
// minimum spanning tree (focal/normals/cloud_normals.h). The paper's future work: "use focal
// surfaces to fix vertex normals of scanned surfaces".

#include <memory>

#include "commands.h"
#include "estimator_flags.h"
#include "focal/io/mesh_io.h"
#include "focal/normals/cloud_normals.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct NormalsFlags {
  std::string input;
  std::string output;
  bool force = false;
  EstimatorFlags estimator;
};

/// Estimated normals of a cloud; where the file has a normal, the estimate takes its side.
RowMatrixX3d cloud_normals_of(const Mesh& cloud, const EstimatorFlags& flags) {
  const CloudOptions o = flags.cloud_options();
  CloudNormalOptions normals = o.normals;
  normals.threads = o.threads;
  RowMatrixX3d N = cloud_normals(cloud.V, cloud_neighbourhoods(cloud.V, o), normals);
  if (cloud.has_normals() && !normals.viewpoint) {
    for (Eigen::Index i = 0; i < N.rows(); ++i) {
      if (N.row(i).dot(cloud.N.row(i)) < 0.0) N.row(i) *= -1.0;
    }
  }
  return N;
}

void run_normals(NormalsFlags& f, const Log& log) {
  Input input(f.input, f.estimator, log);
  RowMatrixX3d N;
  if (input.cloud) {
    Stage stage(log, "cloud normals");
    N = cloud_normals_of(input.mesh, f.estimator);
  } else {
    Estimate e = run_estimate(input, f.input, f.estimator, log);
    N = e.N ? std::move(*e.N) : input.mesh.N;
    if (e.F) input.mesh.F = std::move(*e.F);
  }
  Stage stage(log, "write");
  input.mesh.N = std::move(N);
  write_mesh(f.output, input.mesh);
}

}  // namespace

void add_normals_command(CLI::App& app, const Log& log) {
  auto* cmd = app.add_subcommand("normals", "Estimated, oriented vertex normals (meshes, clouds)");
  auto f = std::make_shared<NormalsFlags>();
  cmd->add_option("input", f->input,
                  "mesh or point cloud (.obj .ply .off .stl .xyz .pwn .pts .txt .csv)")
      ->required();
  cmd->add_option("-o,--output", f->output,
                  "OUT.ply, .obj, .off or .xyz: positions, faces, normals")
      ->required();
  f->estimator.add_to(*cmd);
  cmd->add_flag("--force", f->force, "replace a read-only output file");
  cmd->footer(
      "Examples:\n"
      "  focal normals scan.xyz -o scan-normals.ply              # PCA + jet, MST-oriented\n"
      "  focal normals scan.xyz -o out.xyz --viewpoint 0,0,10 --k 24\n"
      "  focal normals bunny.off -o bunny-normals.ply            # what the estimator fits\n"
      "Clouds with normals keep each normal's side; meshes get the recommended estimator's\n"
      "normals (docs/POINTS.md, docs/ESTIMATOR.md).");
  cmd->parse_complete_callback([f] {
    require_extension("-o", f->output, {".ply", ".obj", ".off", ".xyz"});
    check_output("-o", f->output, f->input, f->force);
  });
  cmd->callback([f, &log] { run_normals(*f, log); });
}

}  // namespace focal::cli
