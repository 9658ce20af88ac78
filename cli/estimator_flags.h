#pragma once
// Options shared by `focal curvature`, `focal focal-mesh`, `focal normals` and `focal render`:
// the flags that choose the estimator and its normals, parsed into the library's EstimateOptions,
// and the input read and checked once for every stage of a run.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/curvature.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/estimate.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/check.h"
#include "focal/mesh/prepared.h"
#include "log.h"

namespace focal::cli {

struct EstimatorFlags {
  CurvatureOptions options;  ///< --method, --solver, --rings, --weights (the paper's method)
  NormalsSource normals = NormalsSource::automatic;
  int threads = 0;      ///< --threads: every stage of the run (0 = FOCAL_NUM_THREADS or all)
  bool strict = false;  ///< --strict: problems found in the input are errors (input_check.h)
  bool paper = false;   ///< --paper: the paper's method as configured by the options above
  bool ignore_normals = false;  ///< --ignore-normals: read the input as if it had no normals
  ReadOptions read;     ///< --no-weld, --weld-tolerance (STL)
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
  /// The file has no faces: a point cloud.
  bool cloud = false;
  /// mesh.V, mesh.F and the normals the run uses (the file's, else none); a cloud's with its
  /// normals when it has them.
  std::optional<PreparedMesh> prepared;
  /// check_mesh of `prepared` (also kept in it, where the normals stage reads it again).
  MeshFindings findings;
};

/// The curvature of the input (a mesh, or a point cloud: EstimatorFlags::cloud_options) with
/// the estimator the flags select, through focal::curvature (focal/curvature.h): its stages timed
/// with -v, its warnings on stderr naming the file; in `tiles` tiles of about equal vertex
/// counts when > 0. With -v a summary of the classes and ranges.
/// \throw InvalidInput when `--normals file` is asked for and the file has none, or a mesh-only
/// option is given for a point cloud.
[[nodiscard]] Estimate run_estimate(const Input& input, const EstimatorFlags& flags, const Log& log,
                                    int tiles = 0);

/// The mesh the estimate ran on: the input's positions with the estimate's faces and normals.
/// Views input and e, which must outlive it.
[[nodiscard]] PreparedMesh estimated_mesh(const Input& input, const Estimate& e);

}  // namespace focal::cli
