#pragma once
/// \file recommended.h
/// The recommended estimator: what `focal curvature` (and focal::curvature, focal/curvature.h)
/// runs when no estimator is chosen, and what `focal eval` reports as "focal default", on a mesh
/// whose normals come from a file (and may be noisy) or that has none. It runs the paper's fits
/// (the closed-form two-slit fit, and on clean positions the per-triangle characteristic
/// equation) on better normals and, where the positions are noisy, over a wider neighbourhood:
/// jets of the positions measure the noise and give normals, the file's normals are judged
/// against them (used, repaired at outliers, or ignored but for their side), the rings and
/// weights follow the noise, creases are not fitted across, wild rays are rejected, and every
/// vertex where a fit is possible gets one. Its steps, one by one, with the reasons for each
/// threshold: docs/METHOD.md, "The recommended estimator"; what they measure:
/// docs/ACCURACY.md.
///
/// Deterministic for any thread count. Vertices the fit cannot handle are `undefined` (NaN) as
/// in estimate_curvature; the paper's method as written remains estimate_curvature with default
/// CurvatureOptions.

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "focal/curvature/curvature.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// Position noise (median jet residual / mean edge length) above which the fit uses 2 rings.
inline constexpr double kNoiseForTwoRings = 0.015;
/// ... and above which it uses 3 rings.
inline constexpr double kNoiseForThreeRings = 0.035;
/// Position noise above which the jets of the positions' normals fit twice (the second time in
/// the frame of the first): beyond the paper's 10% noise (0.058), at 30% and more (0.17), the
/// faces tilt so much that Max's normals, the first frame, are far off (measured on the hard
/// cases of focal eval: 50% vertex noise, sphere 3.4 -> 0.45 relative H error, torus
/// 8.1 -> 0.39; at 10% a second fit changes the standard suite both ways by up to 7%).
inline constexpr double kNoiseForRefittedJets = 0.1;

/// Rings beyond the plan's that the recommended estimator reads where the plan's neighbourhood
/// gives no fit (never NaN where a wider fit is possible).
inline constexpr int kMaxExtraRings = 2;

/// The choices of steps 1 to 3 that are made once per mesh, from a sample of about 4,096 of its
/// vertices chosen by index (medians and a majority): given in RecommendedOptions::mesh_wide
/// instead of measured, they let a part of a mesh (a tile with its halo, focal/tiles/tiles.h) be
/// estimated exactly as in the whole mesh.
struct RecommendedMeshWide {
  double noise = NAN;  ///< RecommendedPlan::noise: judges the file's normals
  /// RecommendedPlan::position_noise: decides the plan (a tile could not measure it alone).
  double position_noise = NAN;
  double file_disagreement = NAN;  ///< RecommendedResult::file_disagreement (NaN: no normals)
  /// +1, or -1 when most file normals point against the jet normals (the positions' normals are
  /// then turned to the file's side).
  double side = 1.0;
  /// Median roughness of the file's normals (the RMS misfit of the rays of a vertex's 1-ring
  /// two-slit fit with them, slope units; NaN: no normals): a used file normal much rougher than
  /// this is in doubt and compared with the positions' normals (docs/METHOD.md, step 3). NaN
  /// with normals puts every file normal in doubt.
  double file_roughness = NAN;
  /// Median over the sample of how much of a quartic height fit's misfit remains of the cubic's
  /// over the same 2-ring of positions (docs/METHOD.md, step 5): small where the positions are
  /// exact to the fits' truncation, near 1 where noise, however small, dominates. The quartic
  /// fit of positions alone runs only on meshes where it is at most 0.15. NaN: no such fit at
  /// the sample (the fit does not run), or the file's normals are used (not measured on a whole
  /// mesh then; a part's statistics measure it all the same, and the estimate does not read it).
  double height_share = NAN;
};

/// Options of the recommended estimator. The defaults are the measured choices of
/// docs/METHOD.md; each field is a knob of one of its steps (docs/METHOD.md, "The recommended
/// estimator", numbered as there).
struct RecommendedOptions {
  /// Step 2: position noise (median cubic-jet residual over the mean edge length) above which the
  /// two-slit fit uses 2 Gaussian-weighted rings...
  double noise_for_two_rings = kNoiseForTwoRings;  // 0.015
  /// ... and above which it uses 3.
  double noise_for_three_rings = kNoiseForThreeRings;  // 0.035
  /// Step 3: the file's normals are used when their median angle to the jet normals (radians) is
  /// at most this many times the position noise (the jets' own error is about the noise).
  double file_agreement = 2.0;
  /// Step 3: among used file normals, one more than this many times the noise from its jet normal
  /// (and rougher than the positions' normal by half) is an outlier, replaced.
  double outlier_disagreement = 10.0;
  /// Step 8: on clean positions, an edge whose two faces' normals differ by more than this
  /// (radians; 0 turns crease handling off) is a crease; its corners are crease vertices.
  /// 60 degrees: above the 46 degrees that faces of the coarsest suite meshes (spacing 0.8 /
  /// max |curvature|) turn between neighbours on smooth surfaces.
  double crease_angle = 1.0471975511965976;  // 60 degrees
  /// The classes' tolerances (core/point_class.h).
  Tolerances tolerances{};
  /// The per-mesh choices, when given, instead of measuring them on this mesh: a tile takes
  /// recommended_mesh_wide() of the whole mesh (with PrepareOptions::mean_edge_length, the scale
  /// they are measured in).
  std::optional<RecommendedMeshWide> mesh_wide{};
};

/// What the recommended estimator does for a mesh, decided from its positions alone.
struct RecommendedPlan {
  /// median cubic-jet residual (over the sample of RecommendedMeshWide) over the mean edge
  /// length; NaN: none
  double noise = NAN;
  /// The part of it that is position noise, the jets' truncation error taken out (see
  /// recommended_plan): what decides the rings. Equals `noise` from recommended_plan_for_noise.
  double position_noise = NAN;
  int rings = 1;           ///< rings of the two-slit fit
  bool gaussian = false;   ///< Gaussian ray weights (width = mean edge length x rings)
  int jet_rings = 2;       ///< rings of the jets whose normals are used without file normals
  int jet_degree = 3;      ///< their degree
  int jet_iterations = 1;  ///< their fits per vertex (2 above kNoiseForRefittedJets)
};

/// The plan for a given noise level (docs/METHOD.md, steps 1-2); reads the noise thresholds.
[[nodiscard]] RecommendedPlan recommended_plan_for_noise(double noise,
                                                         const RecommendedOptions& options = {});

/// The plan for a mesh: measures its noise (cubic jets over the 2-ring) and plans for its
/// position noise. A jet's residual r mixes the position noise s with the truncation error t of
/// a cubic, which grows as the 4th power of the neighbourhood's radius: on a sample of the
/// vertices the 3-ring jet's residual r3 (radius about 3/2 times the 2-ring's) then gives
/// t2^2 = (r3^2 - r2^2) / ((3/2)^4 - 1) and s^2 = r2^2 - t2^2 per vertex (the thresholds were
/// measured with this divisor; see recommended_plan.cpp); position_noise is the
/// median s over the mean edge length. On coarse meshes of curved surfaces t dominates r.
/// \throw InvalidInput when an option is out of range.
[[nodiscard]] RecommendedPlan recommended_plan(const PreparedMesh& mesh,
                                               const RecommendedOptions& options = {});

/// recommended_plan of the arrays. \throw InvalidInput also when F indexes outside V.
[[nodiscard]] RecommendedPlan recommended_plan(PositionsRef V, FacesRef F,
                                               const RecommendedOptions& options = {});

/// The per-mesh choices of the recommended estimator on `mesh` (its normals as the file's, as
/// estimate_curvature_recommended takes them): cubic jets over the 2-ring of every
/// (n / 4,096)-th vertex by index.
/// \throw InvalidInput when an option is out of range.
[[nodiscard]] RecommendedMeshWide recommended_mesh_wide(const PreparedMesh& mesh,
                                                        const RecommendedOptions& options = {});

/// Rings around a vertex that its share of recommended_statistics reads: the 3-ring jet of a
/// sampled vertex (positions 3 rings out, the 1-rings of the vertices 2 rings out). A part
/// holding every face within this many rings minus one of its listed vertices (a tile with this
/// halo, focal/tiles/tiles.h) gives them the whole mesh's values.
inline constexpr int kRecommendedStatisticsReach = 3;

/// A part's share of what recommended_mesh_wide measures over a whole mesh, for a mesh that no
/// process holds whole (streamed tile by tile, python/focal/stream.py): per listed vertex the
/// values the medians run over (NaN at a vertex outside the whole mesh's sample, whose whole-mesh
/// id is not a multiple of max(1, whole_vertex_count / 4096)), and the counts of the majority. The
/// whole mesh's choices are then recommended_mesh_wide_from the medians over all parts.
struct RecommendedStatistics {
  /// Per listed vertex: the residual of its 2-ring cubic jet (length units; NaN: no fit).
  Eigen::VectorXd jet_residual;
  /// Per listed vertex, with mesh normals (else empty): the angle (radians) between its normal
  /// and the jet normal (along), and the jet normal turned round (against); NaN where either is
  /// unusable.
  Eigen::VectorXd angle_along, angle_against;
  /// Listed vertices of the sample whose normal points along / against the jet normal.
  std::int64_t along = 0, against = 0;
  /// Per listed vertex, with mesh normals (else empty): the roughness of its normal (that of
  /// RecommendedMeshWide::file_roughness); NaN where its fit is unusable.
  Eigen::VectorXd file_roughness;
  /// Per listed vertex: its share of RecommendedMeshWide::height_share; NaN where the fit is
  /// refused.
  Eigen::VectorXd height_share;
  /// Whole-mesh ids of the listed vertices in the position noise's sample (recommended_plan) ...
  std::vector<int> sample;
  Eigen::VectorXd sample_noise;  ///< ... and their position noise (length units)
};

/// recommended_statistics of the vertices `rows` of `part` (a piece of a mesh with its vertices
/// in the whole mesh's order and the whole mesh's mean edge length, PrepareOptions; its normals
/// as the estimator takes them: prepare_normals'). `ids`: the whole-mesh id of every vertex of
/// the part; `whole_vertex_count`: the whole mesh's. 	hrow InvalidInput when ids is not one per
/// vertex, a row is out of range, or an option is out of range.
[[nodiscard]] RecommendedStatistics recommended_statistics(const PreparedMesh& part,
                                                           const std::vector<int>& rows,
                                                           const std::vector<int>& ids,
                                                           Eigen::Index whole_vertex_count,
                                                           const RecommendedOptions& options = {});

/// The medians and counts of recommended_statistics over every vertex of a whole mesh (its
/// sample's values: the others are NaN).
struct RecommendedMedians {
  double jet_residual = NAN;     ///< median of the finite jet_residual (nth_element at size / 2)
  Eigen::VectorXd sample_noise;  ///< every part's sample_noise (any order)
  std::int64_t along = 0, against = 0;            ///< summed over the parts
  double angle_along = NAN, angle_against = NAN;  ///< medians of the finite angles
  double file_roughness = NAN;                    ///< median of the finite file_roughness
  double height_share = NAN;                      ///< median of the finite height_share
  bool has_normals = false;                       ///< whether the mesh has normals
};

/// recommended_mesh_wide of the whole mesh from its medians: the same values (bit for bit) when
/// the medians are of every vertex's recommended_statistics.
[[nodiscard]] RecommendedMeshWide recommended_mesh_wide_from(const RecommendedMedians& whole,
                                                             double mean_edge_length);

/// How far the recommended estimate of one vertex reads the mesh, in rings, for a plan: a tile
/// needs a halo this wide (focal/tiles/tiles.h) for its owned vertices to get the whole-mesh
/// result (the plan and the verdict on the file's normals are global: RecommendedMeshWide, decided
/// once and passed). A vertex's normal reads at most max(5, jet_rings + 2) rings (2-ring jets,
/// 3-ring within a ring of a boundary, from Max's normals, rated by 1-ring fits; noisy:
/// jet_rings-ring jets from Max's normals, turned with the 1-ring); the fit reads the normals of
/// rings + kMaxExtraRings rings, and the normals that the refit of undefined vertices replaced by
/// their neighbours' mean one ring further; on clean positions every position read may be a spike's
/// repaired one, which reads 4 rings further (2 with trusted normals). 13 on clean positions,
/// 12 on the widest noisy plan (3 rings, 4-ring jets), so 13 at most (kRecommendedMaxReach).
/// Derived in recommended_plan.cpp.
[[nodiscard]] int recommended_reach(const RecommendedPlan& plan);

/// The largest recommended_reach of any plan (the clean plan's).
inline constexpr int kRecommendedMaxReach = 13;

/// The recommended estimate with what it decided and the normals it fitted.
struct RecommendedResult {
  CurvatureResult curvature;
  RowMatrixX3d N;  ///< #V x 3 unit normals the two-slit fit used (NaN rows where there is none)
  RecommendedPlan plan;
  /// Median angle (radians) between the file's normals and the jet normals over the sample of
  /// RecommendedMeshWide; NaN without normals.
  double file_disagreement = NAN;
  /// Whether the file's normals were used: they agree with the positions (file_disagreement at
  /// most file_agreement times the noise). Otherwise they are ignored as a whole, except for
  /// their side.
  bool file_normals_used = false;
  /// #V flags, 1 at crease vertices (step 8; clean positions only, else all 0 or empty): the
  /// curvature does not exist there, their values are not to be trusted.
  VectorXu8 crease;
};

/// The recommended estimate of a mesh, with its normals as the file's when it has them (they may
/// be noisy, need not be unit; zero or non-finite rows take the positions' normal) or from the
/// positions alone when it has none.
/// \throw InvalidInput when an option is out of range.
[[nodiscard]] RecommendedResult estimate_curvature_recommended(
    const PreparedMesh& mesh, const RecommendedOptions& options = {});

/// The recommended estimate of the arrays. \param N #V x 3 normals from the file, or std::nullopt
/// (not a matrix of 0 rows) when there are none.
/// \throw InvalidInput also when F indexes outside V or N does not have #V rows.
[[nodiscard]] RecommendedResult estimate_curvature_recommended(
    PositionsRef V, FacesRef F, std::optional<NormalsRef> N,
    const RecommendedOptions& options = {});

}  // namespace focal
