#pragma once
// Internal: the steps of the recommended estimator (focal/curvature/recommended.h) and the state
// they share, for the files that hold them: recommended_context.cpp (the context and the fits
// every step calls), recommended_plan.cpp (the mesh-wide measurements and the plan),
// recommended_normals.cpp (steps 1 to 3: the normals to fit) and recommended.cpp (the fit and
// the steps after it).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/recommended.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"
#include "focal/normals/jets.h"

namespace focal::detail::recommended {

/// \throw InvalidInput (the message names `what`) when an option is out of range.
void validate_options(const RecommendedOptions& o, const char* what);

/// Everything the steps share: the mesh (its incidence and edge length kept there), its 1-ring
/// (the mesh's if kept, else built here once and dropped before the per-triangle pass) and Max's
/// normals (the jets' starting frames, and a candidate field of their own).
struct Context {
  const PreparedMesh& mesh;
  const RecommendedOptions& options;
  double edge_length;
  mutable std::shared_ptr<const Neighbourhoods> one_ring;  ///< dropped and rebuilt on demand
  RowMatrixX3d max;                                        ///< freed once the normals are chosen
};

/// The context of `mesh` with `options`: its 1-ring and Max's normals.
Context make_context(const PreparedMesh& mesh, const RecommendedOptions& options);

/// The paper's estimator options with the recommended estimator's classes.
CurvatureOptions paper_options(const Context& c);

/// The paper's per-vertex closed-form two-slit fit of the normals of `normals` (the mesh with
/// some normal field) over `rings` rings, on the context's 1-ring (estimate_curvature would build
/// the k-ring from scratch per call).
CurvatureResult two_slit_fit(const Context& c, const PreparedMesh& normals, int rings,
                             bool gaussian);

/// How rough a normal field is at each vertex: the RMS misfit (residual, slope units) of its
/// 1-ring two-slit fit, NaN (no usable fit) where the fit had to leave out a neighbour's ray —
/// a normal more than 90 degrees from the vertex's, as a flipped or wild normal makes it; the
/// residual of the few rays left says nothing then. Only the residual is computed and stored
/// (detail::fit_roughness), with the bits of the full fit's residual.
Eigen::VectorXd roughness_of(const Context& c, NormalsRef normals);

/// roughness_of at the listed vertices only (entry k: vertex vertices[k]; the same bits).
Eigen::VectorXd roughness_at(const Context& c, NormalsRef normals,
                             const std::vector<int>& vertices);

/// Median of the finite entries; NaN when there are none.
double finite_median(const Eigen::VectorXd& x);

/// Jet options of `rings` rings and `degree`, one fit.
JetOptions jet_options(int rings, int degree);

/// Jets from Max's normals: unit or NaN rows by construction, so not checked again.
JetNormals local_jets(const Context& c, int rings, int degree);

/// Rings from a boundary within which a vertex's 2-ring is cut by it (distances 0 and 1), and
/// the rings of the jets there (recommended_reach).
constexpr int kBoundaryJetDistance = 1;
constexpr int kBoundaryJetRings = 3;

/// The plan for the mesh from its measured (or given) per-mesh choices: rings from the position
/// noise, `noise` the 2-ring cubic jets' plain residual (the file's normals are judged against
/// the jets' error, truncation included).
RecommendedPlan plan_for(const RecommendedMeshWide& m, const RecommendedOptions& options);

/// The file's normals agree with the positions when their median angle to the jet normals is
/// within `agreement` (RecommendedOptions::file_agreement, 2) times the position noise. The jets'
/// own normal error is about the noise (median angle / noise measured 0.8 to 1.05 with exact file
/// normals under 10% vertex noise, 0.09 to 0.95 on clean meshes), so a median angle beyond twice
/// it means file normals whose own error is larger than the jets' (measured 5.3 to 4600 under 5%
/// normal noise). Outliers among agreeing normals (replace_outliers) are those more than
/// RecommendedOptions::outlier_disagreement (10) times the noise from the jet normal: an order of
/// magnitude beyond the jets' own error. (The suite's results are the same for 4, 10 and no
/// replacement at all; the factor matters for files with isolated bad normals.)
bool file_normals_agree(double median_angle, double noise, double agreement);

/// Angle (radians) between a and b: NaN where either is zero or not finite.
double normal_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// The per-mesh choices measured on the context's mesh: medians (and the file normals' majority
/// side) over a sample of about 4,096 of its vertices, every (n / 4,096)-th by index, from their
/// 2-ring cubic jets (the sample's rows of `all`, local_jets(c, 2, 3) of every vertex, when
/// given: the same bits).
RecommendedMeshWide measure_mesh_wide(const Context& c, const JetNormals* all = nullptr);

/// Vertices within `rings` rings of a flagged one (not flagged themselves).
std::vector<int> near_flagged(const Context& c, const std::vector<char>& flagged, int rings);

/// Steps 1 to 3 of recommended.h: the plan (from the jets' residuals), whether the file's
/// normals (the mesh's, if any) are used, and the normals to fit, into `out`. Returns the
/// mesh-wide choices it used (given or measured).
RecommendedMeshWide choose_normals(const Context& c, RecommendedResult& out);

}  // namespace focal::detail::recommended
