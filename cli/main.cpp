// The `focal` command: curvature and focal meshes of triangle meshes.
// Exit codes: 0 success, 1 usage error, 2 input/output or data error, 3 internal error.

#include <CLI/CLI.hpp>
#include <climits>
#include <cstdio>
#include <exception>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <string>

#include "commands.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/io/interrupted_writes.h"
#include "log.h"

namespace {

constexpr int kUsageError = 1;
constexpr int kInputError = 2;
constexpr int kInternalError = 3;

int run(int argc, char** argv) {
  focal::cli::Log log;
  // The outermost execution settings of every command: FOCAL_NUM_THREADS read (an error when it
  // is not a number) and a thread count clamped by a command's scope reported as a warning.
  focal::Execution settings;
  settings.warning = [&log](const std::string& message) { log.warning(message); };
  settings.pass_progress = focal::cli::ProgressLine::report;
  const focal::ExecutionScope scope(settings);
  CLI::App app{
      "focal: principal curvatures, directions and focal meshes of triangle meshes\n"
      "(Yu et al., Focal Surfaces of Discrete Geometry, SGP 2007)"};
  app.set_version_flag("--version", "focal 0.1.0");
  app.add_flag_callback(
      "-v,--verbose", [&log] { log.set_verbose(true); }, "stage timings and a summary on stderr");
  app.add_flag_callback(
      "-q,--quiet", [&log] { log.set_quiet(true); },
      "no progress line on a terminal (a stage running over a second shows one on stderr: "
      "stage, seconds, fraction of the pass and the time it has left; never on pipes)");
  // At most one command; "at least one" is checked after parsing, so that a misspelt command is
  // reported by name ("not expected: curvatre") rather than as a missing command.
  app.require_subcommand(0, 1);
  app.fallthrough();
  focal::cli::add_info_command(app, log);
  focal::cli::add_generate_command(app, log);
  focal::cli::add_curvature_command(app, log);
  focal::cli::add_focal_mesh_command(app, log);
  focal::cli::add_normals_command(app, log);
  focal::cli::add_smooth_command(app, log);
  focal::cli::add_eval_command(app, log);
  focal::cli::add_render_command(app, log);
  focal::cli::add_devices_command(app, log);
  app.footer(
      "Examples:\n"
      "  focal info mesh.ply\n"
      "  focal generate torus --vertices 5000 -o torus.ply --truth truth.csv\n"
      "  focal curvature mesh.ply -o fields.csv\n"
      "  focal -v curvature mesh.ply -o fields.ply --rings 2\n"
      "  focal focal-mesh mesh.ply -o prefix   # prefix.focal1.ply, prefix.focal2.ply\n"
      "  focal curvature scan.xyz -o fields.csv --k 16   # point clouds (no faces) too\n"
      "  focal normals scan.xyz -o scan-normals.ply      # estimated, oriented normals\n"
      "  focal smooth scan.ply -o scan-smooth.ply        # denoised onto the fitted surface\n"
      "  focal eval --markdown eval.md         # every estimator against analytic truth\n"
      "  focal render mesh.ply -o mesh-H.png --field H   # a picture of H\n"
      "  focal devices                      # the GPUs the CUDA backend can use\n"
      "Run 'focal COMMAND -h' for the options and examples of a command.\n"
      "Exit codes: 0 success, 1 usage error, 2 unreadable input or invalid data, 3 internal "
      "error.");
  try {
    app.parse(argc, argv);
    if (app.get_subcommands().empty()) throw CLI::RequiredError("A subcommand");
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr,
                 "Error: %s\nUsage: focal [-v] "
                 "info|generate|curvature|focal-mesh|normals|smooth|eval|render|devices ... "
                 "(see focal -h)\n",
                 focal::cli::one_line(e.what()).c_str());
    return kUsageError;
  }
  return 0;
}

/// One process, one command: memory a pass frees is kept for the next pass rather than handed
/// back to Linux. glibc would otherwise map each large array afresh and unmap it when freed, so
/// that every pass's arrays (tens of MB at 1M vertices) are zero-filled and faulted in 4 KiB at a
/// time again. The peak stays about the same: what is freed is reused.
void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_MAX, 0);              // large blocks from the heap, reused once freed
  mallopt(M_TRIM_THRESHOLD, INT_MAX);  // the heap's free top is not returned
#endif
}

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory();
  // A run stopped by Ctrl-C or kill leaves no temporary file of the output it was writing.
  focal::remove_temporary_files_on_signals();
  try {
    return run(argc, argv);
  } catch (const focal::Error& e) {
    std::fprintf(stderr, "Error: %s\n", focal::cli::one_line(e.what()).c_str());
    return kInputError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "Error: internal: %s\n", focal::cli::one_line(e.what()).c_str());
    return kInternalError;
  }
}
