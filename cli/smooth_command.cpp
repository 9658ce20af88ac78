// `focal smooth IN -o OUT`: a mesh or point cloud denoised onto the smooth surface fitted around
// each point (focal/smoothing/smooth.h); rows, their order and the faces kept, the fitted
// normals written with --normals.

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "commands.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/io/mesh_io.h"
#include "focal/smoothing/smooth.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct SmoothFlags {
  std::string input;
  std::string output;
  bool force = false;
  bool normals = false;
  int iterations = 0;
  int rings = 0;
  int k = 0;
  bool keep_creases = false;
  double crease_angle = 60.0;
  bool no_robust = false;
  int threads = 0;
  OutputFlags out;
};

void run_smooth(const SmoothFlags& f, const Log& log) {
  const ExecutionScope scope({.threads = f.threads});
  Mesh mesh;
  {
    Stage stage(log, "read");
    mesh = read_mesh(f.input);
    if (mesh.V.rows() == 0) throw IoError(f.input + ": no vertices, nothing to smooth");
    log.info("  " + std::to_string(mesh.V.rows()) + " vertices, " + std::to_string(mesh.F.rows()) +
             " triangles");
  }
  if (mesh.is_cloud() && f.rings > 0)
    throw InvalidInput("--rings: " + f.input + " is a point cloud (use --k)");
  if (!mesh.is_cloud() && f.k > 0)
    throw InvalidInput("--k: " + f.input + " is a mesh (use --rings)");
  SmoothOptions o;
  o.iterations = f.iterations;
  o.rings = f.rings;
  o.neighbours = f.k;
  o.keep_creases = f.keep_creases;
  o.crease_angle = f.crease_angle * M_PI / 180.0;
  o.robust = !f.no_robust;
  o.execution = execution_for(log, f.input);
  SmoothResult r = smooth(mesh, o);
  std::ostringstream plan;
  plan << "  " << r.iterations << " pass(es) kept over "
       << (mesh.is_cloud() ? std::to_string(r.neighbours) + " neighbours"
                           : std::to_string(r.rings) + " rings")
       << "; position noise";
  for (const double x : r.noise) plan << " " << x;
  plan << "; " << r.outliers_moved << " outlier(s) moved back, " << r.crease_points
       << " crease point(s), " << r.unfitted << " left unfitted";
  log.info(plan.str());
  if (r.unfitted > 0) {
    log.warning(f.input + ": " + std::to_string(r.unfitted) + " of " +
                std::to_string(mesh.V.rows()) +
                " points have no well-posed fit (too few neighbours) and were left where they are");
  }
  Stage stage(log, "write");
  mesh.V = std::move(r.V);
  if (f.normals) {
    mesh.N = std::move(r.N);
  } else {
    mesh.N.resize(0, 3);
  }
  write_mesh(f.output, mesh, {.precision = f.out.precision()});
}

}  // namespace

void add_smooth_command(CLI::App& app, const Log& log) {
  auto* cmd = app.add_subcommand(
      "smooth", "Denoise a mesh or point cloud onto the surface fitted around each point");
  auto f = std::make_shared<SmoothFlags>();
  cmd->add_option("input", f->input,
                  "mesh or point cloud (.obj .ply .off .stl .xyz .xyzn .xyzrgb .pwn .pts .txt .csv "
                  ".pcd .las)")
      ->required();
  cmd->add_option("-o,--output", f->output,
                  "OUT.ply, .obj, .off, .xyz or .xyzn: smoothed positions, the input's faces")
      ->required();
  cmd->add_flag("--normals", f->normals, "write the fitted surfaces' normals too");
  cmd->add_option("--iterations", f->iterations,
                  "passes; 0 (default): until the measured position noise stops falling")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--rings", f->rings, "meshes: rings of each fit; 0 (default): from the noise")
      ->check(CLI::Range(0, 16));
  cmd->add_option("--k", f->k, "clouds: neighbours of each fit; 0 (default): from the noise")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--keep-creases", f->keep_creases,
                "fit each side of a sharp crease separately, keep its points on both sides");
  cmd->add_option("--crease-angle", f->crease_angle,
                  "degrees between the two sides' normals that make a crease (default 60)")
      ->check(CLI::Range(1.0, 179.0));
  cmd->add_flag("--no-robust", f->no_robust,
                "keep every point in every fit (spikes and outliers then pull their neighbours)");
  cmd->add_option("--threads", f->threads, "threads (0: all CPUs or FOCAL_NUM_THREADS)")
      ->check(CLI::NonNegativeNumber);
  f->out.add_to(*cmd);
  cmd->add_flag("--force", f->force, "replace a read-only output file");
  cmd->footer(
      "Examples:\n"
      "  focal smooth scan.ply -o scan-smooth.ply\n"
      "  focal smooth part.stl -o part-smooth.ply --keep-creases --normals\n"
      "  focal smooth scan.xyz -o scan-smooth.xyzn --normals   # point clouds too\n"
      "Each point moves along its normal onto the quadric fitted over its neighbourhood (as wide\n"
      "as the measured noise asks), points far off their neighbours' surface left out of the fit\n"
      "and moved back; repeated until the noise stops falling (docs/SMOOTH.md).");
  cmd->parse_complete_callback([f] {
    require_extension("-o", f->output, {".ply", ".obj", ".off", ".xyz", ".xyzn"});
    check_output("-o", f->output, f->input, f->force);
  });
  cmd->callback([f, &log] { run_smooth(*f, log); });
}

}  // namespace focal::cli
