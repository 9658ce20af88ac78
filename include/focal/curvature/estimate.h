#pragma once
/// \file estimate.h
/// The whole estimate of `focal curvature` (and of `focal-mesh` and `render`) as a library call,
/// so that the command line and the bindings run the same thing: the normals chosen by their
/// source, the chosen estimator run on them, the fields and the normals used returned. What the
/// command line adds is flag parsing, stage timings and the messages (from NormalsReport and the
/// recommended estimator's decisions in Estimate).
///
/// Two steps, which estimate() runs one after the other (the command line times them apart):
///  1. prepare_normals: the normals the estimator gets.
///     - The mesh's own normals (NormalsSource::automatic when it has them, or `file`): rows that
///       are zero or not finite are filled with Max's normals from the faces, rows not of unit
///       length within 1e-6 are normalised (a copy is made only when some row needs it).
///     - For the paper's estimator without them (`automatic`), or when asked (`area`, `angle`,
///       `max`): normals from the faces (vertex_normals), after the faces of closed components
///       that are consistently oriented inward have been reversed (orientation_report,
///       orient_outward), so that the normals point outward.
///     - For the recommended estimator without them: none (it estimates its own from the
///       positions), the faces made outward as above since its normals take their side from them.
///     It reads check_mesh(mesh)'s findings (computed if the mesh has none yet) to skip the scans
///     a clean mesh does not need.
///  2. estimate: the estimator on the prepared normals and faces.
///
/// Deterministic for any thread count, like the functions it calls.

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "focal/core/execution.h"
#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/recommended.h"
#include "focal/mesh/prepared.h"

namespace focal {

enum class Estimator {
  recommended,  ///< estimate_curvature_recommended (recommended.h): what `focal curvature` runs
  paper,        ///< estimate_curvature (curvature.h), the paper's method, per vertex or triangle
  // The estimators of the literature (baselines.h), for comparison; meshes only, on the CPU,
  // without tiles. Each reads the tolerances (and CSM03 the rings) of EstimateOptions::paper.
  meyer_2003,                 ///< MDSB03: cotangent Laplacian and angle defect
  cohen_steiner_morvan_2003,  ///< CSM03: normal cycle
  lachaud_2020,               ///< LRTC20: interpolated corrected curvature measures
  yang_2006,                  ///< YLHP06: integral invariants
  grinspun_2006,              ///< GGRZ06: mid-edge shape operator
};

/// Where the estimate runs. The CPU is the reference; the device runs the paper's estimator in
/// float32 (focal/cuda/curvature.h) and throws DeviceError where there is none.
enum class Device {
  cpu,
  cuda,
};

/// Where the estimator's normals come from.
enum class NormalsSource {
  automatic,  ///< the mesh's normals when it has them; else Max's from the faces (paper) or none
              ///< (recommended, which estimates its own)
  file,       ///< the mesh's normals (from the file); an error when it has none
  area,       ///< from the faces, NormalWeighting::area (paper's estimator only)
  angle,      ///< from the faces, NormalWeighting::angle (paper's estimator only)
  max,        ///< from the faces, NormalWeighting::max (paper's estimator only)
};

struct EstimateOptions {
  Estimator estimator = Estimator::recommended;
  NormalsSource normals = NormalsSource::automatic;
  /// Estimator::paper: its options (the paper with the closed-form solver by default).
  CurvatureOptions paper{};
  /// Estimator::recommended: its options.
  RecommendedOptions recommended{};
  /// Point clouds (an input without faces): their options (the adaptive default by default).
  CloudOptions cloud{};
  Device device = Device::cpu;
  /// > 0: the estimate in spatial tiles of at most this many owned vertices (or points), one
  /// after the other (focal/tiles/tiles.h): the same bits, the memory of one tile's estimate.
  int tile_vertices = 0;
  /// Whether prepare_normals reverses the faces of closed components oriented inward (when the
  /// normals do not come from the mesh). false: the faces are taken as they are, e.g. a tile's,
  /// cut from the faces that MeshWideChoices::F oriented over the whole mesh.
  bool orient_faces = true;
  /// Thread count, progress, messages and cancellation of focal::curvature (focal/curvature.h),
  /// current for the whole call (an ExecutionScope).
  Execution execution{};
};

/// The rings around a vertex whose positions, faces and normals its estimate reads: a part of a
/// mesh (a tile, focal/tiles/tiles.h) holding every face within this many rings of its vertices
/// gives them the whole mesh's estimate. Paper, per vertex: its rings + 1 (the normals of the
/// ring's vertices read their faces); per triangle: 2 (the corners' normals); recommended:
/// recommended_reach of the plan of options.recommended.mesh_wide, or the widest plan's.
[[nodiscard]] int estimate_reach(const EstimateOptions& options);

/// What an estimate takes from the whole mesh, measured once on it, so that a part of the mesh
/// (with its halo of estimate_reach rings) is estimated exactly as in the whole.
struct MeshWideChoices {
  /// #F x 3 faces with the closed components oriented inward reversed (prepare_normals), when
  /// some were; std::nullopt: F as given. A tile cuts its faces from these.
  std::optional<RowMatrixX3i> F;
  /// The mean edge length of the faces the estimator fits: PrepareOptions::mean_edge_length of
  /// a tile.
  double mean_edge_length = NAN;
  /// Estimator::recommended: recommended_mesh_wide of the mesh the estimator gets.
  std::optional<RecommendedMeshWide> recommended;
};

/// The choices of a whole mesh, and the options that make an estimate on a part of it take them
/// (orient_faces off, recommended.mesh_wide given). The mean edge length goes into the part's
/// PrepareOptions. \throw InvalidInput as prepare_normals.
[[nodiscard]] MeshWideChoices mesh_wide_choices(const PreparedMesh& mesh,
                                                const EstimateOptions& options = {});
[[nodiscard]] EstimateOptions options_for_part(const EstimateOptions& options,
                                               const MeshWideChoices& choices);

/// What prepare_normals did, for a caller to report.
struct NormalsReport {
  /// Closed components, consistently oriented inward, whose faces were reversed (only when the
  /// normals do not come from the mesh).
  int reoriented_component_count = 0;
  int filled_normal_count = 0;    ///< mesh normals that were zero or not finite: Max's instead
  int rescaled_normal_count = 0;  ///< mesh normals not of unit length within 1e-6: normalised
  /// Most of the mesh's normals point against the area-weighted normals of their faces (inward
  /// normals?). The curvature signs follow the normals.
  bool normals_against_faces = false;
};

/// The normals and faces the estimator gets (step 1).
struct PreparedNormals {
  /// #V x 3 normals when they are not the mesh's own as given: the mesh's with rows filled or
  /// normalised, or normals from the faces. std::nullopt: the mesh's normals as given (or, for
  /// the recommended estimator, none when the mesh has none).
  std::optional<RowMatrixX3d> N;
  /// #F x 3: F with the faces of inward components reversed; std::nullopt: F as given.
  std::optional<RowMatrixX3i> F;
  NormalsReport report;
};

/// Step 1. \throw InvalidInput when NormalsSource::file is asked for and the mesh has no
/// normals, or when the recommended estimator is asked for with normals from the faces (it
/// chooses its own).
[[nodiscard]] PreparedNormals prepare_normals(const PreparedMesh& mesh,
                                              const EstimateOptions& options = {});

/// What the estimate of a point cloud chose (cloud_curvature.h, CloudCurvature).
struct CloudPlan {
  bool normals_estimated = false;  ///< the cloud had no normals: they were estimated
  double spacing = 0.0;            ///< mean_spacing of the cloud
  double noise = NAN;              ///< the default's median jet residual over the spacing
  int k = 0;                       ///< neighbours of the fit
  bool corrected = false;          ///< the default's corrected step ran
  /// #V flags of the points left out as outliers (empty when no outlier test ran).
  std::vector<char> outlier;
};

/// The fields and what produced them.
struct Estimate {
  CurvatureResult curvature;
  /// #V x 3 normals the estimator used, when they are not the mesh's own as given (they are
  /// unit rows, NaN where none): those of step 1, or the recommended estimator's choice.
  /// std::nullopt: the mesh's normals as given (the paper's estimator on mesh normals that
  /// needed no fixing).
  std::optional<RowMatrixX3d> N;
  /// #F x 3 faces the estimator used when they are not F: step 1 reversed some.
  std::optional<RowMatrixX3i> F;
  NormalsReport normals_report;  ///< step 1's
  /// Estimator::recommended: its plan, the file normals' median angle to the jet normals (NaN
  /// without mesh normals) and whether it used them (RecommendedResult).
  RecommendedPlan plan;
  double file_disagreement = NAN;
  bool file_normals_used = false;
  /// Estimator::recommended: #V flags, 1 at crease vertices (RecommendedResult::crease; all 0
  /// where it did not look for creases: noisy positions, crease_angle 0). Empty for the paper's.
  VectorXu8 crease;
  /// Point clouds (focal::curvature on an input without faces): what the cloud estimate chose.
  std::optional<CloudPlan> cloud;
  /// Vertices (or points) without an estimate: class undefined, NaN in every field.
  std::int64_t undefined_count = 0;
  /// Vertices with more than kMaxNeighbourhoodSize vertices within `crowded_rings` rings (the
  /// widest neighbourhood the estimate gathered): undefined, or for the recommended estimator on
  /// clean positions fitted over their 1-ring on Max's normals. Counted by focal::curvature
  /// where it can matter (some vertex undefined, or the recommended 1-ring path).
  std::int64_t crowded_count = 0;
  int crowded_rings = 0;
};

/// Step 2: the estimator on `normals` (from prepare_normals for the same mesh and options),
/// which are moved into the result. Frees the mesh's kept vertex-face incidence when the
/// per-vertex fit no longer needs it (the fit is the peak of a run; it is rebuilt if needed).
/// \throw InvalidInput as the estimator.
[[nodiscard]] Estimate estimate(const PreparedMesh& mesh, PreparedNormals normals,
                                const EstimateOptions& options = {});

/// Both steps.
[[nodiscard]] Estimate estimate(const PreparedMesh& mesh, const EstimateOptions& options = {});

}  // namespace focal
