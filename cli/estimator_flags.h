#pragma once
// Options shared by `focal curvature`, `focal focal-mesh` and `focal render`: which estimator runs
// on which normals (focal/curvature/estimate.h, the library's pipeline), and the stages of a run
// with their timings and messages.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/estimate.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/check.h"
#include "focal/mesh/prepared.h"
#include "focal/tiles/tiles.h"
#include "log.h"

namespace focal::cli {

struct EstimatorFlags {
  CurvatureOptions options;  ///< --method, --solver, --rings, --weights (the paper's method)
  NormalsSource normals = NormalsSource::automatic;
  int threads = 0;      ///< --threads: every stage of the run (0 = FOCAL_NUM_THREADS or all)
  bool strict = false;  ///< --strict: problems found in the input are errors (input_check.h)
  bool paper = false;   ///< --paper: the paper's method as configured by the options above
  ReadOptions read;     ///< --no-weld, --weld-tolerance (STL); threads set from --threads
  /// --method, --solver, --rings, --weights, --normals: giving any selects the paper's method.
  std::vector<CLI::Option*> method_options;
  /// Point clouds: --k, --radius, --viewpoint, --cloud-normals (and --solver, --threads).
  CloudOptions cloud;
  std::vector<double> viewpoint;

  /// The options of a point-cloud run. \throw InvalidInput when an option that only meshes
  /// have (--method, --rings, --weights, --normals) was given.
  [[nodiscard]] CloudOptions cloud_options() const;

  void add_to(CLI::App& command);
  void add_cloud_flags(CLI::App& command);
  /// Whether the run uses focal's recommended estimator (recommended.h): no estimator option and
  /// no --paper were given.
  [[nodiscard]] bool recommended() const;
  /// Whether the run uses the normals read from the file (rather than estimating them).
  [[nodiscard]] bool uses_file_normals(const Mesh& mesh) const;
  /// The library's options for this run.
  [[nodiscard]] EstimateOptions estimate_options() const;
};

/// --weld-tolerance and --no-weld (STL welding, ReadOptions) on `command`, stored in `read`.
void add_read_flags(CLI::App& command, ReadOptions& read);

/// A mesh read for a run, prepared once for every stage, and what check_mesh found in it.
/// Not copyable: `prepared` views `mesh`.
struct Input {
  /// Reads the mesh and reports (or, with --strict, rejects) what is wrong with it.
  /// \throw InvalidInput / IoError for unreadable files or (with --strict) problems found.
  Input(const std::string& path, const EstimatorFlags& flags, const Log& log);
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;

  std::string path;  ///< as given, for messages
  Mesh mesh;
  /// The file has no faces: a point cloud (`prepared` is then empty; the cloud functions take
  /// mesh.V and mesh.N).
  bool cloud = false;
  /// mesh.V, mesh.F and the normals the run uses (the file's, else none).
  std::optional<PreparedMesh> prepared;
  /// check_mesh of `prepared` (also kept in it, where the normals stage reads it again).
  MeshFindings findings;
};

/// Prepares the normals and runs the estimator the flags select (focal::estimate, in two stages
/// with their timings and warnings) and with -v prints a summary.
/// \throw InvalidInput when `--normals file` is asked for and the file has none.
[[nodiscard]] Estimate run_estimate(const Input& input, const std::string& mesh_name,
                                    const EstimatorFlags& flags, const Log& log);

/// run_estimate's curvature and crease flags, tile by tile (estimate_tiled, focal/tiles/tiles.h:
/// the same bits, the memory of the largest tile's estimate in place of the whole mesh's) in
/// `tiles` tiles of about equal vertex counts; of a point cloud, run_cloud_estimate's curvature
/// (estimate_cloud_tiled: the plan on the whole cloud, the fit tile by tile). \throw InvalidInput
/// as run_estimate and run_cloud_estimate.
[[nodiscard]] TileEstimate run_tiled_estimate(const Input& input, const std::string& mesh_name,
                                              const EstimatorFlags& flags, int tiles,
                                              const Log& log);

/// The curvature of a point cloud (cloud_curvature.h) with the flags' options, timed in stages,
/// with -v a summary. \throw InvalidInput as EstimatorFlags::cloud_options.
[[nodiscard]] CloudCurvature run_cloud_estimate(const Input& input, const EstimatorFlags& flags,
                                                const Log& log);

/// The mesh the estimate ran on: the input's positions with the estimate's faces and normals.
/// Views input and e, which must outlive it.
[[nodiscard]] PreparedMesh estimated_mesh(const Input& input, const Estimate& e);

}  // namespace focal::cli
