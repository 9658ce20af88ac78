#include "focal/curvature/recommended.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "curvature/corrected_step.h"
#include "curvature/normal_choice.h"
#include "curvature/robust_fit.h"
#include "curvature/spike_repair.h"
#include "curvature/triangle_fit.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/jets.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/prepared_access.h"
#include "normals/jet_normals_from.h"
#include "normals/vertex_normals_from.h"

namespace focal {
namespace {

void validate_options(const RecommendedOptions& o, const char* what) {
  const auto non_negative = [&](double x, const char* name) {
    if (!(x >= 0.0)) throw InvalidInput(std::string(what) + ": " + name + " must be >= 0");
  };
  non_negative(o.noise_for_two_rings, "noise_for_two_rings");
  non_negative(o.noise_for_three_rings, "noise_for_three_rings");
  non_negative(o.file_agreement, "file_agreement");
  non_negative(o.outlier_disagreement, "outlier_disagreement");
  non_negative(o.zero_tolerance, "zero_tolerance");
  non_negative(o.umbilic_tolerance, "umbilic_tolerance");
  non_negative(o.crease_angle, "crease_angle");
  if (o.threads < 0) throw InvalidInput(std::string(what) + ": threads must be >= 0");
}

/// Everything the steps share: the mesh (its incidence and edge length kept there), its 1-ring
/// (the mesh's if kept, else built here once and dropped before the per-triangle pass) and Max's
/// normals (the jets' starting frames, and a candidate field of their own).
struct Context {
  const PreparedMesh& mesh;
  const RecommendedOptions& options;
  int threads;
  double edge_length;
  mutable std::shared_ptr<const Neighbourhoods> one_ring;  ///< dropped and rebuilt on demand
  RowMatrixX3d max;                                        ///< freed once the normals are chosen
};

Context make_context(const PreparedMesh& mesh, const RecommendedOptions& options) {
  const int threads = detail::threads_for(mesh, options.threads);
  return {mesh,
          options,
          threads,
          mesh.mean_edge_length(),
          detail::one_ring(mesh),
          detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh),
                                      NormalWeighting::max, threads)};
}

/// The paper's estimator options with the recommended estimator's classes and threads.
CurvatureOptions paper_options(const Context& c) {
  CurvatureOptions o;
  o.zero_tolerance = c.options.zero_tolerance;
  o.umbilic_tolerance = c.options.umbilic_tolerance;
  o.threads = c.threads;
  return o;
}

/// The paper's per-vertex closed-form two-slit fit of the normals of `normals` (the mesh with
/// some normal field) over `rings` rings, on the context's 1-ring (estimate_curvature would build
/// the k-ring from scratch per call).
CurvatureResult two_slit_fit(const Context& c, const PreparedMesh& normals, int rings,
                             bool gaussian) {
  CurvatureOptions o = paper_options(c);
  o.rings = rings;
  o.weighting = gaussian && rings > 1 ? RayWeighting::gaussian : RayWeighting::uniform;
  const detail::UnitNormals& unit = detail::unit_normals(normals);
  const PositionsRef& V = c.mesh.V();
  if (rings == 1) return detail::fit_vertices({V, unit.N, unit.ok, *c.one_ring, c.edge_length}, o);
  const Neighbourhoods ring = k_ring(*c.one_ring, rings, c.threads);
  return detail::fit_vertices({V, unit.N, unit.ok, ring, c.edge_length}, o);
}

/// How rough a normal field is at each vertex: the RMS misfit (residual, slope units) of its
/// 1-ring two-slit fit, NaN (no usable fit) where the fit had to leave out a neighbour's ray —
/// a normal more than 90 degrees from the vertex's, as a flipped or wild normal makes it; the
/// residual of the few rays left says nothing then. Only the residual is computed and stored
/// (detail::fit_roughness): the bits of the full fit's, at a fraction of its time and memory.
Eigen::VectorXd roughness_of(const Context& c, NormalsRef normals) {
  const PreparedMesh with = c.mesh.with_normals(normals);
  const detail::UnitNormals& unit = detail::unit_normals(with);
  return detail::fit_roughness({c.mesh.V(), unit.N, unit.ok, *c.one_ring, c.edge_length},
                               paper_options(c));
}

/// roughness_of at the listed vertices only (entry k: vertex vertices[k]; the same bits).
Eigen::VectorXd roughness_at(const Context& c, NormalsRef normals,
                             const std::vector<int>& vertices) {
  const PreparedMesh with = c.mesh.with_normals(normals);
  const detail::UnitNormals& unit = detail::unit_normals(with);
  return detail::fit_roughness_at({c.mesh.V(), unit.N, unit.ok, *c.one_ring, c.edge_length},
                                  paper_options(c), vertices.data(),
                                  static_cast<Eigen::Index>(vertices.size()));
}

/// Median of the finite entries; NaN when there are none.
double finite_median(const Eigen::VectorXd& x) {
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(x.size()));
  for (double e : x) {
    if (std::isfinite(e)) v.push_back(e);
  }
  if (v.empty()) return NAN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

JetOptions jet_options(const Context& c, int rings, int degree) {
  JetOptions o;
  o.rings = rings;
  o.degree = degree;
  o.iterations = 1;
  o.threads = c.threads;
  return o;
}

/// Jets from Max's normals: unit or NaN rows by construction, so not checked again.
JetNormals local_jets(const Context& c, int rings, int degree) {
  return detail::jet_normals_from(c.mesh.V(), *c.one_ring, c.max, jet_options(c, rings, degree));
}

/// Vertices sampled for the noise measurement: at most about kNoiseSamples, evenly by index.
constexpr Eigen::Index kNoiseSamples = 4096;

/// Rings from a boundary within which a vertex's 2-ring is cut by it (distances 0 and 1), and
/// the rings of the jets there (recommended_reach).
constexpr int kBoundaryJetDistance = 1;
constexpr int kBoundaryJetRings = 3;

/// `jets` (the 2-ring cubic jets) with the rows of vertices whose 2-ring is cut by a boundary
/// (within kBoundaryJetDistance rings of it) replaced by cubic jets over kBoundaryJetRings
/// rings where those are the smoother field there (1-ring two-slit residual, roughness_of): a
/// one-sided 2-ring holds about half an interior 2-ring's points, about as many as a cubic's 10
/// coefficients, and its jet nearly interpolates them; the one-sided 3-ring holds about as many
/// points as an interior 2-ring (on a thin tube it reaches around it, and the 2-ring may stay
/// smoother). Rows where the wider jet fails stay.
RowMatrixX3d with_boundary_jets(const Context& c, const RowMatrixX3d& jets) {
  const std::vector<bool> boundary =
      boundary_vertices(static_cast<int>(c.mesh.vertex_count()), c.mesh.F(), c.threads);
  std::vector<int> near;
  const Eigen::VectorXi distance = rings_to_boundary(*c.one_ring, boundary, kBoundaryJetDistance);
  for (int i = 0; i < distance.size(); ++i) {
    if (distance[i] <= kBoundaryJetDistance) near.push_back(i);
  }
  RowMatrixX3d out = jets;
  if (near.empty()) return out;
  const JetNormals wide = detail::jet_normals_at(c.mesh.V(), *c.one_ring, c.max,
                                                 jet_options(c, kBoundaryJetRings, 3), near);
  for (std::size_t k = 0; k < near.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(k);
    if (wide.N.row(row).allFinite()) out.row(near[k]) = wide.N.row(row);
  }
  const Eigen::VectorXd r2 = roughness_at(c, jets, near), r3 = roughness_at(c, out, near);
  for (std::size_t k = 0; k < near.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(k);
    if (std::isfinite(r2[row]) && !(r3[row] <= r2[row])) out.row(near[k]) = jets.row(near[k]);
  }
  return out;
}

/// Whether vertex i (of n) is in the sample of position_noise: every step-th vertex by index,
/// about kNoiseSamples of them, where the 2-ring jet's residual `r2` is finite.
bool in_noise_sample(Eigen::Index i, Eigen::Index n, double r2) {
  const Eigen::Index step = std::max<Eigen::Index>(1, n / kNoiseSamples);
  return i % step == 0 && std::isfinite(r2);
}

/// The position noise of recommended_plan (recommended.h) at the listed vertices (entry k:
/// vertex sample[k], length units): the 2-ring cubic jets' residuals `r2` (of every vertex) with
/// their truncation error taken out, by the 3-ring jets' residuals. A cubic's truncation error
/// grows as radius^4, and the 3-ring's radius is about 3/2 the 2-ring's: its squared residual
/// grows (3/2)^8 = 25.6 times, the noise's not at all (the residuals are per degree of freedom).
Eigen::VectorXd noise_at(const Context& c, const Eigen::VectorXd& r2,
                         const std::vector<int>& sample) {
  const Eigen::VectorXd r3 =
      detail::jet_residuals_at(c.mesh.V(), *c.one_ring, c.max, jet_options(c, 3, 3), sample);
  constexpr double kGrowth = 5.0625 - 1.0;  // (3/2)^4 - 1
  Eigen::VectorXd noise(static_cast<Eigen::Index>(sample.size()));
  for (Eigen::Index k = 0; k < noise.size(); ++k) {
    const double a = r2[sample[static_cast<std::size_t>(k)]], b = r3[k];
    const double truncation = std::max(0.0, b * b - a * a) / kGrowth;
    noise[k] = std::isfinite(b) ? std::sqrt(std::max(0.0, a * a - truncation)) : NAN;
  }
  return noise;
}

/// The median of noise_at on the sample (in_noise_sample), length units.
double position_noise(const Context& c, const Eigen::VectorXd& r2) {
  std::vector<int> sample;
  for (Eigen::Index i = 0; i < r2.size(); ++i) {
    if (in_noise_sample(i, r2.size(), r2[i])) sample.push_back(static_cast<int>(i));
  }
  return finite_median(noise_at(c, r2, sample));
}

/// The plan for the mesh from its measured (or given) per-mesh choices: rings from the position
/// noise, `noise` the 2-ring cubic jets' plain residual (the file's normals are judged against
/// the jets' error, truncation included).
RecommendedPlan plan_for(const RecommendedMeshWide& m, const RecommendedOptions& options) {
  RecommendedPlan plan = recommended_plan_for_noise(m.position_noise, options);
  plan.noise = m.noise;
  return plan;
}

using detail::select_normal;

/// select_normal at every vertex.
RowMatrixX3d select_normals(NormalsRef primary, const Eigen::VectorXd& primary_roughness,
                            NormalsRef secondary, const Eigen::VectorXd& secondary_roughness,
                            int threads) {
  RowMatrixX3d out(primary.rows(), 3);
  detail::parallel_for(primary.rows(), threads, [&](std::int64_t i) {
    out.row(i) = select_normal(primary.row(i).transpose(), primary_roughness[i],
                               secondary.row(i).transpose(), secondary_roughness[i], true)
                     .first.transpose();
  });
  return out;
}

/// Where the chosen normal has none (the jets had too few points, a degenerate fit): Max's
/// normal if any; turned to the file's side (`side`, -1 or +1; the fit's residuals do not
/// change: the rays are the same lines).
Eigen::Vector3d with_max_fallback(const Context& c, Eigen::Vector3d n, Eigen::Index i,
                                  double side) {
  if (!n.allFinite()) n = c.max.row(i).transpose();
  return side < 0.0 ? Eigen::Vector3d(-n) : n;
}

/// The positions' normal at vertex i on clean positions (the jets' or Max's, by select_normal
/// on their roughness `rj`, `rm` there), as choose_normals picks it, and its roughness.
std::pair<Eigen::Vector3d, double> positions_normal(const Context& c, const JetNormals& jets,
                                                    double rj, double rm, Eigen::Index i,
                                                    double side) {
  const auto [n, r] =
      select_normal(jets.N.row(i).transpose(), rj, c.max.row(i).transpose(), rm, true);
  return {with_max_fallback(c, n, i, side), r};
}

/// The file's normals, replaced by the positions' only at outliers: where a file normal is
/// unusable or gives no fit, or where it is more than `limit` radians from the jet normal and the
/// positions' normal (positions_normal) is clearly smoother. On a file whose normals agree with
/// the positions, such vertices are isolated bad normals; elsewhere the exact normals stay exact
/// (replacing them where two truncation-level residuals happen to differ by 2x cost up to 0.5%
/// of H error on clean irregular meshes). The positions' normals are rated only at those
/// vertices: elsewhere the file's normal is kept whatever they are.
RowMatrixX3d replace_outliers(const Context& c, NormalsRef file, const JetNormals& jets,
                              const Eigen::VectorXd& disagreement, double side, double limit) {
  const Eigen::VectorXd file_roughness = roughness_of(c, file);
  const auto may_replace = [&](Eigen::Index i) {
    return !(disagreement[i] <= limit) || !std::isfinite(file_roughness[i]);
  };
  RowMatrixX3d out(file.rows(), 3);
  std::vector<char> candidate(static_cast<std::size_t>(file.rows()));
  detail::parallel_for(file.rows(), c.threads, [&](std::int64_t i) {
    const Eigen::Vector3d a = file.row(i).transpose().normalized();
    out.row(i) = a.transpose();
    candidate[static_cast<std::size_t>(i)] = !a.allFinite() || may_replace(i);
  });
  std::vector<int> at;
  for (std::size_t i = 0; i < candidate.size(); ++i) {
    if (candidate[i]) at.push_back(static_cast<int>(i));
  }
  if (at.empty()) return out;
  const Eigen::VectorXd jets_roughness = roughness_at(c, jets.N, at);
  const Eigen::VectorXd max_roughness = roughness_at(c, c.max, at);
  detail::parallel_for(static_cast<std::int64_t>(at.size()), c.threads, [&](std::int64_t k) {
    const int i = at[static_cast<std::size_t>(k)];
    const auto [b, rb] = positions_normal(c, jets, jets_roughness[k], max_roughness[k], i, side);
    out.row(i) = select_normal(file.row(i).transpose(), file_roughness[i], b, rb, may_replace(i))
                     .first.transpose();
  });
  return out;
}

/// +1 when most usable rows of `file` point to the side of `estimated`, -1 when most point
/// against it (a file whose normals point inward while the faces turn outward).
/// The rows of `file` that point to the side of `estimated` (first) and against it (second).
std::pair<std::int64_t, std::int64_t> sides(NormalsRef file, NormalsRef estimated) {
  std::int64_t along = 0, against = 0;
  for (Eigen::Index i = 0; i < file.rows(); ++i) {
    const double d = file.row(i).dot(estimated.row(i));
    along += d > 0.0;
    against += d < 0.0;
  }
  return {along, against};
}

double side_of(std::int64_t along, std::int64_t against) { return against > along ? -1.0 : 1.0; }

double majority_side(NormalsRef file, NormalsRef estimated) {
  const auto [along, against] = sides(file, estimated);
  return side_of(along, against);
}

/// Angle (radians) between row i of A and side * row i of B: NaN where a row is zero or not
/// finite.
double angle_between(NormalsRef A, NormalsRef B, double side, Eigen::Index i) {
  const Eigen::Vector3d a = A.row(i).transpose(), b = side * B.row(i).transpose();
  const bool usable = a.allFinite() && b.allFinite() && a != Eigen::Vector3d::Zero() &&
                      b != Eigen::Vector3d::Zero();
  return usable ? std::atan2(a.cross(b).norm(), a.dot(b)) : NAN;
}

/// angle_between at every row.
Eigen::VectorXd angles_between(NormalsRef A, NormalsRef B, double side, int threads) {
  Eigen::VectorXd angle(A.rows());
  detail::parallel_for(A.rows(), threads,
                       [&](std::int64_t i) { angle[i] = angle_between(A, B, side, i); });
  return angle;
}

/// The file's normals agree with the positions when their median angle to the jet normals is
/// within `agreement` (RecommendedOptions::file_agreement, 2) times the position noise. The jets'
/// own normal error is about the noise (median angle / noise measured 0.8 to 1.05 with exact file
/// normals under 10% vertex noise, 0.09 to 0.95 on clean meshes), so a median angle beyond twice
/// it means file normals whose own error is larger than the jets' (measured 5.3 to 4600 under 5%
/// normal noise). Outliers among agreeing normals (replace_outliers) are those more than
/// RecommendedOptions::outlier_disagreement (10) times the noise from the jet normal: an order of
/// magnitude beyond the jets' own error. (The suite's results are the same for 4, 10 and no
/// replacement at all; the factor matters for files with isolated bad normals.)
bool file_normals_agree(double median_angle, double noise, double agreement) {
  if (!std::isfinite(median_angle)) return false;  // no normal of the file is usable
  if (!std::isfinite(noise)) return true;          // no jets to judge them by
  // Angles at rounding level agree whatever the noise (a plane has noise 0).
  return median_angle <= std::max(agreement * noise, 1e-12);
}

/// A 1-ring fit residual at or below this is rounding (corrected_step.h).
using detail::kExactFitResidual;

/// On clean positions, the per-triangle characteristic equation averaged to the vertices
/// (Method::triangle) is more accurate than the 1-ring fit on irregular meshes (measured 1.3 to
/// 1.8 times lower H error, docs/ESTIMATOR.md), but only second-order exact where the fit is
/// exact: `fit` keeps its rows where its residual says the rays fit exactly, or where the
/// triangles give no estimate, and takes the triangles' elsewhere, except where `replaced` (if
/// not empty) is set: the corrected step writes those rows, so the pass runs on the faces of the
/// other vertices only (a vertex's row reads its own faces, in the same order: the same bits).
void prefer_triangles(const Context& c, const PreparedMesh& fitted,
                      const std::vector<char>& replaced, CurvatureResult& fit) {
  CurvatureOptions o = paper_options(c);
  o.method = Method::triangle;
  const Eigen::Index n = fitted.vertex_count();
  std::vector<char> wanted(static_cast<std::size_t>(n));
  detail::parallel_for(n, c.threads, [&](std::int64_t i) {
    const auto v = static_cast<std::size_t>(i);
    wanted[v] = !(fit.residual[i] <= kExactFitResidual) && (replaced.empty() || !replaced[v]);
  });
  const FacesRef& F = fitted.F();
  std::vector<int> faces;
  if (!replaced.empty()) {
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (wanted[static_cast<std::size_t>(F(f, 0))] || wanted[static_cast<std::size_t>(F(f, 1))] ||
          wanted[static_cast<std::size_t>(F(f, 2))]) {
        faces.push_back(static_cast<int>(f));
      }
    }
  }
  if (replaced.empty() || faces.size() == static_cast<std::size_t>(F.rows())) {
    return detail::replace_with_triangles(fitted, o, wanted, fit);
  }
  if (faces.empty()) return;
  RowMatrixX3i part(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t k = 0; k < faces.size(); ++k) {
    part.row(static_cast<Eigen::Index>(k)) = F.row(faces[k]);
  }
  // The whole mesh's scale (the classes' tolerances), the fitted normals, the same threads.
  const PreparedMesh sub = detail::PreparedAccess::make(
      fitted.V(), part, fitted.normals(), {.threads = c.threads, .mean_edge_length = c.edge_length},
      "prefer_triangles");
  detail::replace_with_triangles(sub, o, wanted, fit);
}

/// The file's normals compared with the jet normals: the side they point to, and per vertex the
/// angle between the two (empty without file normals).
struct FileComparison {
  double side = 1.0;
  Eigen::VectorXd disagreement;
};

FileComparison compare_file_normals(const Context& c, const JetNormals& jets) {
  const std::optional<NormalsRef> file = c.mesh.normals();
  if (!file) return {};
  // The file's normals decide the side (the sign of the curvature), as in estimate_curvature;
  // normals from the positions take the side of the faces until turned. A tile takes the whole
  // mesh's side.
  const double side =
      c.options.mesh_wide ? c.options.mesh_wide->side : majority_side(*file, jets.N);
  return {side, angles_between(*file, jets.N, side, c.threads)};
}

/// The per-mesh choices from their medians over the whole mesh (length units; radians) and the
/// side: measured on one mesh (measure_mesh_wide) or over its parts (recommended_mesh_wide_from).
RecommendedMeshWide mesh_wide_of(double jet_residual, double sample_noise, double file_angle,
                                 double side, double edge_length) {
  RecommendedMeshWide m;
  m.noise = jet_residual / edge_length;
  m.position_noise = sample_noise / edge_length;
  m.file_disagreement = file_angle;
  m.side = side;
  return m;
}

/// The per-mesh choices measured on the context's mesh: medians over all its vertices.
RecommendedMeshWide measure_mesh_wide(const Context& c, const JetNormals& jets,
                                      const FileComparison& file) {
  return mesh_wide_of(finite_median(jets.residual), position_noise(c, jets.residual),
                      c.mesh.has_normals() ? finite_median(file.disagreement) : NAN, file.side,
                      c.edge_length);
}

/// The robust fit (curvature/robust_fit.h) of the listed vertices over `rings` rings, Gaussian
/// weighted when `gaussian`, into their rows of `fit` (with `only_rejecting`, only where it
/// rejected rays); no ray from a vertex flagged in `skip`.
void robust_refit(const Context& c, const PreparedMesh& fitted, int rings, bool gaussian,
                  const std::vector<char>& skip, const std::vector<int>& vertices,
                  bool only_rejecting, CurvatureResult& fit) {
  if (vertices.empty()) return;
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const detail::UnitNormals& unit = detail::unit_normals(fitted);
  const Neighbourhoods wider = rings > 1 ? k_ring(*c.one_ring, rings, c.threads) : Neighbourhoods{};
  const detail::VertexFitInput in{c.mesh.V(), unit.N, unit.ok, rings > 1 ? wider : *c.one_ring,
                                  c.edge_length};
  detail::robust_fit_vertices({in, skip, gaussian ? c.edge_length * rings : 0.0}, vertices,
                              detail::class_tolerances(paper_options(c), c.edge_length), c.threads,
                              only_rejecting, fit);
}

std::vector<int> all_vertices(const Context& c) {
  std::vector<int> out(static_cast<std::size_t>(c.mesh.vertex_count()));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<int>(i);
  return out;
}

/// Never NaN where a fit is possible: vertices left undefined (too few rays in the hemisphere
/// of their normal, an ill-posed fit) are fitted again, robustly, in the frame of the mean of
/// their neighbours' normals (their own may be the wild one), over one and then two more rings
/// than the plan's: kMaxExtraRings bounds the estimator's reach (recommended_reach). `N` is the
/// normal field of the fit; the rows of the refitted vertices are replaced by that mean.
void fill_undefined(const Context& c, const RecommendedPlan& plan, const std::vector<char>& skip,
                    RowMatrixX3d& N, CurvatureResult& fit) {
  for (int extra = 1; extra <= kMaxExtraRings; ++extra) {
    std::vector<int> candidates, undefined;
    for (int i = 0; i < c.mesh.vertex_count(); ++i) {
      if (fit.class_of(i) == PointClass::undefined) candidates.push_back(i);
    }
    if (candidates.empty()) return;
    // The 1-ring, dropped for the per-triangle pass, is rebuilt only when a vertex needs it.
    if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
    for (const int i : candidates) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const int* j = c.one_ring->begin(i); j != c.one_ring->end(i); ++j) {
        if (N.row(*j).allFinite()) mean += N.row(*j).transpose();
      }
      if (!(mean.norm() > 0.0)) continue;  // no neighbour with a normal: no fit possible
      N.row(i) = mean.normalized().transpose();
      undefined.push_back(i);
    }
    if (undefined.empty()) return;
    robust_refit(c, c.mesh.with_normals(N), plan.rings + extra, true, skip, undefined, false, fit);
  }
}

/// `N` with each row that points against the sum of its 1-ring neighbours' turned round. Under
/// strong noise a few jets fit in a frame tilted past 90 degrees (their first frame, Max's
/// normal, comes from folded faces); such a normal leaves every neighbour's ray out of its fit.
RowMatrixX3d turned_with_neighbours(const Context& c, RowMatrixX3d N) {
  std::vector<char> turn(static_cast<std::size_t>(N.rows()), 0);
  detail::parallel_for(N.rows(), c.threads, [&](std::int64_t i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const int v = static_cast<int>(i);
    for (const int* j = c.one_ring->begin(v); j != c.one_ring->end(v); ++j) {
      if (N.row(*j).allFinite()) sum += N.row(*j).transpose();
    }
    turn[static_cast<std::size_t>(i)] = N.row(i).dot(sum) < 0.0 ? 1 : 0;
  });
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    if (turn[static_cast<std::size_t>(i)]) N.row(i) = -N.row(i);
  }
  return N;
}

/// Crease vertices (recommended.h, step 5): corners of an edge whose two faces' normals differ
/// by more than RecommendedOptions::crease_angle. Per vertex, over pairs of its faces that
/// share an edge at it.
std::vector<char> crease_vertices(const Context& c) {
  const PositionsRef& V = c.mesh.V();
  const FacesRef& F = c.mesh.F();
  const auto& incidence = *detail::incidence(c.mesh);
  const double cos_limit = std::cos(c.options.crease_angle);
  const auto normal_of = [&](int f) {
    const Eigen::Vector3d a = V.row(F(f, 0)).transpose(), b = V.row(F(f, 1)).transpose(),
                          d = V.row(F(f, 2)).transpose();
    return Eigen::Vector3d((b - a).cross(d - a).normalized());
  };
  // A face at v: its normal and its corners other than v (the one there is twice, or a value no
  // corner has where there is none): two faces share an edge at v exactly when those meet.
  struct FaceAtVertex {
    Eigen::Vector3d normal;
    int other[2];
  };
  const auto at_vertex = [&](int f, int v) {
    FaceAtVertex out{normal_of(f), {-1 - f, -1 - f}};
    int found = 0;
    for (int x = 0; x < 3 && found < 2; ++x) {
      if (F(f, x) != v) out.other[found++] = F(f, x);
    }
    if (found == 1) out.other[1] = out.other[0];
    return out;
  };
  const auto share_edge = [](const FaceAtVertex& a, const FaceAtVertex& b) {
    return a.other[0] == b.other[0] || a.other[0] == b.other[1] || a.other[1] == b.other[0] ||
           a.other[1] == b.other[1];
  };
  std::vector<char> crease(static_cast<std::size_t>(c.mesh.vertex_count()), 0);
  detail::parallel_for_blocks(
      c.mesh.vertex_count(), 1024, c.threads, [&](std::int64_t begin, std::int64_t end) {
        // Each face's normal and corners once per vertex (a face meets two others at v).
        std::vector<FaceAtVertex> faces;
        for (auto i = begin; i < end; ++i) {
          const int v = static_cast<int>(i);
          faces.clear();
          for (int a = incidence.begin(v); a < incidence.end(v); ++a)
            faces.push_back(at_vertex(incidence.faces[static_cast<std::size_t>(a)], v));
          for (std::size_t a = 0; a < faces.size() && !crease[static_cast<std::size_t>(i)]; ++a) {
            for (std::size_t b = a + 1; b < faces.size(); ++b) {
              if (share_edge(faces[a], faces[b]) &&
                  faces[a].normal.dot(faces[b].normal) < cos_limit) {
                crease[static_cast<std::size_t>(i)] = 1;
                break;
              }
            }
          }
        }
      });
  return crease;
}

/// Vertices within `rings` rings of a flagged one (not flagged themselves).
std::vector<int> near_flagged(const Context& c, const std::vector<char>& flagged, int rings) {
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const Eigen::VectorXi distance =
      rings_to_boundary(*c.one_ring, std::vector<bool>(flagged.begin(), flagged.end()), rings);
  std::vector<int> out;
  for (int i = 0; i < distance.size(); ++i) {
    if (distance[i] >= 1 && distance[i] <= rings) out.push_back(i);
  }
  return out;
}

/// Vertices next to a crease vertex: the triangles there use the crease vertex's normal, which
/// belongs to neither piece; the 1-ring fit without crease vertices replaces them.
void refit_beside_creases(const Context& c, const PreparedMesh& fitted, const VectorXu8& crease,
                          CurvatureResult& fit) {
  if (crease.size() == 0 || crease.maxCoeff() == 0) return;
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const std::vector<char> skip(crease.begin(), crease.end());
  robust_refit(c, fitted, 1, false, skip, near_flagged(c, skip, 1), false, fit);
}

/// Trusted file normals on clean positions: the corrected curvature measures
/// (curvature/corrected_step.h) where the fit is not exact, except within 2 rings of a crease
/// (their balls would reach across it; refit_beside_creases and the per-triangle pass stay).
/// `asymmetry`: detail::stencil_asymmetry of the fitted normals.
detail::CorrectedRows corrected(const Context& c, const PreparedMesh& fitted,
                                const VectorXu8& crease, Eigen::VectorXd asymmetry,
                                const CurvatureResult& fit) {
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  std::vector<char> keep(crease.begin(), crease.end());  // empty: crease handling is off
  if (!keep.empty()) {
    for (const int v : near_flagged(c, keep, 2)) keep[static_cast<std::size_t>(v)] = 1;
  }
  // A vertex of one face keeps that face's operator (its spread, the residual, is 0: the
  // per-triangle pass's row counts as exact, as it did when the pass ran first).
  keep.resize(static_cast<std::size_t>(c.mesh.vertex_count()), 0);
  const auto incidence = detail::incidence(c.mesh);
  for (int v = 0; v < c.mesh.vertex_count(); ++v) {
    if (incidence->size(v) < 2) keep[static_cast<std::size_t>(v)] = 1;
  }
  return detail::corrected_rows(fitted, *c.one_ring, paper_options(c), keep, kExactFitResidual, fit,
                                std::move(asymmetry));
}

/// Steps 1 to 3 of recommended.h: the plan (from the jets' residuals), whether the file's
/// normals (the mesh's, if any) are used, and the normals to fit, into `out`. Returns the
/// mesh-wide choices it used (given or measured).
RecommendedMeshWide choose_normals(const Context& c, RecommendedResult& out) {
  const std::optional<NormalsRef> file = c.mesh.normals();
  const bool has_normals = file.has_value();
  const JetNormals jets = local_jets(c, 2, 3);
  const FileComparison compared = compare_file_normals(c, jets);
  const RecommendedMeshWide mesh_wide =
      c.options.mesh_wide ? *c.options.mesh_wide : measure_mesh_wide(c, jets, compared);
  out.plan = plan_for(mesh_wide, c.options);
  const double side = compared.side;
  const Eigen::VectorXd& disagreement = compared.disagreement;
  out.file_disagreement = mesh_wide.file_disagreement;
  out.file_normals_used = has_normals && file_normals_agree(out.file_disagreement, out.plan.noise,
                                                            c.options.file_agreement);
  if (out.file_normals_used) {
    // The file's normals, except outliers where the positions' choice is clearly smoother.
    out.N = replace_outliers(c, *file, jets, disagreement, side,
                             c.options.outlier_disagreement * out.plan.noise);
  } else {
    if (out.plan.rings > 1) {
      // Noisy positions: normals from wider, lower-degree jets that average the noise.
      JetOptions o = jet_options(c, out.plan.jet_rings, out.plan.jet_degree);
      o.iterations = out.plan.jet_iterations;
      out.N =
          turned_with_neighbours(c, detail::jet_normals_from(c.mesh.V(), *c.one_ring, c.max, o).N);
    } else {
      // The jets where Max's normals are not clearly smoother: Max's are exact on spheres, but
      // first-order (rough) on irregular meshes.
      const RowMatrixX3d J = with_boundary_jets(c, jets.N);
      out.N = select_normals(J, roughness_of(c, J), c.max, roughness_of(c, c.max), c.threads);
    }
    for (Eigen::Index i = 0; i < out.N.rows(); ++i) {
      if (side > 0.0 && out.N.row(i).allFinite()) continue;  // nothing to change
      out.N.row(i) = with_max_fallback(c, out.N.row(i).transpose(), i, side).transpose();
    }
  }
  if (out.plan.rings == 1 && c.options.crease_angle > 0.0) {
    // Creases on clean positions: jets over the 2-ring mix the pieces' normals; each face lies
    // on one piece, so Max's normals (of the faces) stay on their piece.
    const std::vector<char> crease = crease_vertices(c);
    out.crease = Eigen::Map<const Eigen::Matrix<char, Eigen::Dynamic, 1>>(
                     crease.data(), static_cast<Eigen::Index>(crease.size()))
                     .cast<std::uint8_t>();
    // Used file normals are kept there where they agree with Max's normal within half the
    // crease angle (the jets they were judged against mix the pieces); others take Max's.
    const double agree = std::cos(0.5 * c.options.crease_angle);
    for (const int v : near_flagged(c, crease, 2)) {
      const Eigen::RowVector3d max = side * c.max.row(v);
      const bool keep_file = out.file_normals_used && file->row(v).normalized().dot(max) > agree;
      out.N.row(v) = keep_file ? Eigen::RowVector3d(file->row(v).normalized()) : max;
    }
  }
  return mesh_wide;
}

/// Spikes on trusted file normals (spike_repair.h): the positions with each spike moved back
/// onto the surface its neighbours and the normals describe, or nothing when there is none.
std::optional<RowMatrixX3d> spike_repaired(const Context& c) {
  // Unit rows of its own, not the mesh's kept ones: nothing after this step reads them, and kept
  // they would stay alive through the fit and the per-triangle pass (24 B a vertex).
  std::vector<char> ok;
  const RowMatrixX3d N = detail::unit_rows(*c.mesh.normals(), ok, c.threads);
  const Eigen::VectorXd offset = detail::normal_offsets(c.mesh.V(), N, *c.one_ring, c.threads);
  const std::vector<int> spikes = detail::find_spikes(c.mesh.V(), N, *c.one_ring, offset);
  if (spikes.empty()) return std::nullopt;
  return detail::repaired_positions(c.mesh.V(), N, *c.one_ring, offset, spikes);
}

}  // namespace

RecommendedPlan recommended_plan_for_noise(double noise, const RecommendedOptions& options) {
  RecommendedPlan plan;
  plan.noise = plan.position_noise = noise;
  // Also NaN: no estimate, keep the 1-ring.
  if (!(noise > options.noise_for_two_rings)) return plan;
  plan.rings = noise > options.noise_for_three_rings ? 3 : 2;
  // Strong noise tilts the faces, so Max's normals (the jets' first frame) are far off: a second
  // fit in the frame of the first.
  plan.jet_iterations = noise > kNoiseForRefittedJets ? 2 : 1;
  plan.gaussian = true;
  plan.jet_rings = plan.rings + 1;
  plan.jet_degree = 2;
  return plan;
}

RecommendedPlan recommended_plan(const PreparedMesh& mesh, const RecommendedOptions& options) {
  validate_options(options, "recommended_plan");
  if (options.mesh_wide) return plan_for(*options.mesh_wide, options);
  const Context c = make_context(mesh, options);
  const JetNormals jets = local_jets(c, 2, 3);
  return plan_for(measure_mesh_wide(c, jets, compare_file_normals(c, jets)), options);
}

RecommendedMeshWide recommended_mesh_wide(const PreparedMesh& mesh,
                                          const RecommendedOptions& options) {
  validate_options(options, "recommended_mesh_wide");
  RecommendedOptions measured = options;
  measured.mesh_wide.reset();
  const Context c = make_context(mesh, measured);
  const JetNormals jets = local_jets(c, 2, 3);
  return measure_mesh_wide(c, jets, compare_file_normals(c, jets));
}

RecommendedStatistics recommended_statistics(const PreparedMesh& part, const std::vector<int>& rows,
                                             const std::vector<int>& ids,
                                             Eigen::Index whole_vertex_count,
                                             const RecommendedOptions& options) {
  validate_options(options, "recommended_statistics");
  const auto n = part.vertex_count();
  if (ids.size() != static_cast<std::size_t>(n)) {
    throw InvalidInput("recommended_statistics: ids must name every vertex of the part (" +
                       std::to_string(n) + "), got " + std::to_string(ids.size()));
  }
  for (const int r : rows) {
    if (r < 0 || r >= n) {
      throw InvalidInput("recommended_statistics: row " + std::to_string(r) +
                         " is out of range [0, " + std::to_string(n) + ")");
    }
  }
  RecommendedOptions measured = options;
  measured.mesh_wide.reset();
  const Context c = make_context(part, measured);
  // The jets of the listed vertices (detail::jet_normals_at: the bits of local_jets' rows).
  const JetNormals jets =
      detail::jet_normals_at(part.V(), *c.one_ring, c.max, jet_options(c, 2, 3), rows);
  RecommendedStatistics out;
  out.jet_residual = jets.residual;
  // position_noise's sample, by whole-mesh index; noise_at reads r2 by part row.
  Eigen::VectorXd r2 = Eigen::VectorXd::Constant(n, NAN);
  std::vector<int> sample;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int r = rows[k];
    r2[r] = jets.residual[static_cast<Eigen::Index>(k)];
    if (in_noise_sample(ids[static_cast<std::size_t>(r)], whole_vertex_count, r2[r])) {
      sample.push_back(r);
      out.sample.push_back(ids[static_cast<std::size_t>(r)]);
    }
  }
  out.sample_noise = noise_at(c, r2, sample);
  if (const std::optional<NormalsRef> file = part.normals()) {
    const auto m = static_cast<Eigen::Index>(rows.size());
    RowMatrixX3d file_rows(m, 3);
    for (Eigen::Index k = 0; k < m; ++k) file_rows.row(k) = file->row(rows[std::size_t(k)]);
    std::tie(out.along, out.against) = sides(file_rows, jets.N);
    out.angle_along.resize(m);
    out.angle_against.resize(m);
    detail::parallel_for(m, c.threads, [&](std::int64_t k) {
      out.angle_along[k] = angle_between(file_rows, jets.N, 1.0, k);
      out.angle_against[k] = angle_between(file_rows, jets.N, -1.0, k);
    });
  }
  return out;
}

RecommendedMeshWide recommended_mesh_wide_from(const RecommendedMedians& whole,
                                               double mean_edge_length) {
  const double side = side_of(whole.along, whole.against);
  const double file_angle =
      whole.has_normals ? (side < 0.0 ? whole.angle_against : whole.angle_along) : NAN;
  return mesh_wide_of(whole.jet_residual, finite_median(whole.sample_noise), file_angle,
                      whole.has_normals ? side : 1.0, mean_edge_length);
}

int recommended_reach(const RecommendedPlan& plan) {
  // What the estimate at a vertex v reads, in rings from v (a vertex's Max normal reads its
  // incident faces, whose corners are one ring further; jets read their k-ring's positions and
  // Max's normal at their centre only):
  //  - a fitted normal at u, on clean positions, is chosen between candidates (jets over 2
  //    rings, Max's, the file's) by their 1-ring fits' residuals at u, and the crease steps read
  //    the faces of vertices within 2 rings of u: 1 + 2 + 1 = 4 rings from u, one more where
  //    u is within kBoundaryJetDistance of a boundary (its jets over kBoundaryJetRings rings;
  //    whether it is reads 2 rings); on noisy
  //    positions it is the jet of u over plan.jet_rings rings from Max's normals, turned with
  //    its 1-ring's normals: jet_rings + 2 (with a margin of one);
  //  - the fit of v reads the fitted normals within plan.rings, the per-triangle pass those at
  //    the corners of v's faces (1 ring), and where v stays undefined the refits over up to
  //    kMaxExtraRings more rings; those read the normals that the previous refit replaced by
  //    their neighbours' mean, one ring further;
  //  - on clean positions with trusted normals, the corrected step (corrected_step.h) reads the
  //    fitted normals at the corners of the faces of its ball's vertices (at most
  //    kCorrectedBallRings + 1 rings) and the stencil asymmetry of v's 1-ring (2 rings);
  //  - on clean positions with trusted normals, each position read is the spike repair's
  //    (spike_repair.h): a spike's offset reads its 1-ring, whether it is isolated the offsets
  //    of that 1-ring, 2 rings in all.
  const int normal_reach = std::max(kBoundaryJetRings + 2, plan.rings > 1 ? plan.jet_rings + 2 : 0);
  const int fit_reach = std::max(std::max(plan.rings, 1) + kMaxExtraRings + 1,
                                 plan.rings > 1 ? 0 : detail::kCorrectedBallRings + 1);
  const int position_reach = plan.rings > 1 ? 0 : detail::kSpikeRepairRings;
  return fit_reach + normal_reach + position_reach;
}

RecommendedPlan recommended_plan(PositionsRef V, FacesRef F, const RecommendedOptions& options) {
  validate_options(options, "recommended_plan");
  return recommended_plan(detail::PreparedAccess::make(
                              V, F, std::nullopt, {.threads = options.threads}, "recommended_plan"),
                          options);
}

namespace {

/// estimate_curvature_recommended; `repair_spikes`: step 4 may start again on repaired positions.
RecommendedResult estimate(const PreparedMesh& mesh, const RecommendedOptions& options,
                           bool repair_spikes) {
  Context c = make_context(mesh, options);
  RecommendedResult out;
  const RecommendedMeshWide mesh_wide = choose_normals(c, out);
  if (repair_spikes && out.file_normals_used && out.plan.rings == 1) {
    // Spikes (step 4): the whole estimate again on the repaired positions, with this mesh's
    // mesh-wide choices and scale (away from the spikes the positions, and so the estimate, are
    // the same).
    if (const std::optional<RowMatrixX3d> V = spike_repaired(c)) {
      RecommendedOptions o = options;
      o.mesh_wide = mesh_wide;
      o.threads = c.threads;
      const PreparedMesh repaired = detail::PreparedAccess::make(
          *V, mesh.F(), mesh.normals(), {.threads = c.threads, .mean_edge_length = c.edge_length},
          "estimate_curvature_recommended");
      return estimate(repaired, o, false);
    }
  }
  // Max's normals served the choice of normals only: their memory is the later steps'.
  c.max.resize(0, 3);
  // The mesh with the chosen normals: the fit and the per-triangle pass share their unit rows.
  const PreparedMesh fitted = mesh.with_normals(out.N);
  const std::vector<char> no_skip;
  if (out.plan.rings == 1) {
    // The corrected step's stencil asymmetry before the fit: its two arrays are then not alive
    // beside the fit's result (the peak of a run at 1M).
    Eigen::VectorXd asymmetry;
    if (out.file_normals_used) {
      asymmetry = detail::stencil_asymmetry(fitted.V(), detail::unit_normals(fitted).N, *c.one_ring,
                                            c.threads);
    }
    out.curvature = two_slit_fit(c, fitted, out.plan.rings, out.plan.gaussian);
    // The corrected step first: the per-triangle pass then skips the rows it replaces. Both
    // judge the fit's residual (whether it is exact) of rows the other does not write, so the
    // measures are written (and their whole-mesh result freed) before the pass runs.
    std::vector<char> replaced;
    if (out.file_normals_used) {
      detail::CorrectedRows measures =
          corrected(c, fitted, out.crease, std::move(asymmetry), out.curvature);
      detail::apply_corrected_rows(measures, c.threads, out.curvature);
      replaced = std::move(measures.replace);
    }
    // The 1-ring's memory is the per-triangle pass's (later steps rebuild it if they need it).
    c.one_ring.reset();
    prefer_triangles(c, fitted, replaced, out.curvature);
    replaced = {};
    refit_beside_creases(c, fitted, out.crease, out.curvature);
  } else {
    // Noisy positions: where rays lie far off the fit (wild normals), it is repeated without.
    out.curvature = two_slit_fit(c, fitted, out.plan.rings, out.plan.gaussian);
    robust_refit(c, fitted, out.plan.rings, out.plan.gaussian, no_skip, all_vertices(c), true,
                 out.curvature);
  }
  fill_undefined(c, out.plan, no_skip, out.N, out.curvature);
  if (!out.file_normals_used) detail::undefine_isolated_triangles(mesh.F(), out.curvature);
  return out;
}

}  // namespace

RecommendedResult estimate_curvature_recommended(const PreparedMesh& mesh,
                                                 const RecommendedOptions& options) {
  validate_options(options, "estimate_curvature_recommended");
  return estimate(mesh, options, true);
}

RecommendedResult estimate_curvature_recommended(PositionsRef V, FacesRef F,
                                                 std::optional<NormalsRef> N,
                                                 const RecommendedOptions& options) {
  validate_options(options, "estimate_curvature_recommended");
  return estimate_curvature_recommended(
      detail::PreparedAccess::make(V, F, std::move(N), {.threads = options.threads},
                                   "estimate_curvature_recommended"),
      options);
}

}  // namespace focal
