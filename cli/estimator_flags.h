#pragma once
// Options shared by `focal curvature` and `focal focal-mesh`: how normals are obtained and how
// the estimator runs.

#include <CLI/CLI.hpp>
#include <vector>

#include "focal/curvature/curvature.h"
#include "focal/core/mesh.h"
#include "focal/mesh/check.h"
#include "log.h"

namespace focal::cli {

enum class NormalsSource { automatic, file, area, angle, max };

struct EstimatorFlags {
  CurvatureOptions options;
  NormalsSource normals = NormalsSource::automatic;
  bool strict = false;  ///< --strict: problems found in the input are errors (input_check.h)
  bool paper = false;   ///< --paper: the paper's method as configured by the options above
  /// --method, --solver, --rings, --weights, --normals: giving any selects the paper's method.
  std::vector<CLI::Option*> method_options;

  void add_to(CLI::App& command);
  /// Whether the run uses focal's recommended estimator (recommended.h): no estimator option and
  /// no --paper were given.
  [[nodiscard]] bool recommended() const;
  /// Whether the run uses the normals read from the file (rather than estimating them).
  [[nodiscard]] bool uses_file_normals(const Mesh& mesh) const;
};

/// A mesh read for a run, and what check_mesh found in it.
struct Input {
  Mesh mesh;
  /// Findings for mesh.V, mesh.F and the normals the run uses (the file's, else none). The
  /// normals stage reuses them instead of recomputing the orientation and the face normals.
  MeshFindings findings;
};

/// Pins every parallel stage of the run (reading, the check, normals, writing) to --threads:
/// the library's functions without a `threads` option take theirs from FOCAL_NUM_THREADS.
/// Reads the mesh and reports (or, with --strict, rejects) what is wrong with it.
/// \throw InvalidInput / IoError for unreadable files or (with --strict) problems found.
[[nodiscard]] Input read_input(const std::string& path, const EstimatorFlags& flags,
                               const Log& log);

/// The normals and fields of a run.
struct Estimate {
  RowMatrixX3d normals;  ///< the unit normals the fit used (written to PLY outputs, focal meshes)
  CurvatureResult fields;
};

/// Prepares the normals and runs the estimator the flags select, with stage timings and, with -v,
/// a summary. May re-orient inward closed components of input.mesh.F when normals are estimated;
/// input.mesh.N is left empty when the estimate used the file's normals (they are in the
/// result's `normals`, made unit; no copy of them is made).
/// \throw InvalidInput when `--normals file` is asked for and the file has none.
[[nodiscard]] Estimate estimate(Input& input, const std::string& mesh_name,
                                const EstimatorFlags& flags, const Log& log);

/// The unit normals the estimator uses: the file's (moved out of mesh.N), or estimated from the
/// faces (with inward closed components re-oriented). Warns about what it fixed or suspects.
/// `findings`: read_input's, for this mesh and these file normals.
/// \throw InvalidInput when `--normals file` is asked for and the file has none.
[[nodiscard]] RowMatrixX3d prepare_normals(Mesh& mesh, const MeshFindings& findings,
                                           const std::string& mesh_name, NormalsSource source,
                                           const Log& log);

/// Runs the estimator with stage timings and, with -v, a summary of the result.
[[nodiscard]] CurvatureResult run_estimator(const Mesh& mesh, const RowMatrixX3d& normals,
                                            const EstimatorFlags& flags, const Log& log);

}  // namespace focal::cli
