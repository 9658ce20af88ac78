// The recommended estimator's mesh-wide measurements and its plan (recommended.h): the position
// noise from the jets' residuals, the side and the agreement of the file's normals with the
// jets, the plan they give, and the reach of the estimate in rings.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "curvature/corrected_step.h"
#include "curvature/height_fit.h"
#include "curvature/recommended_steps.h"
#include "curvature/spike_repair.h"
#include "focal/core/error.h"
#include "mesh/position_spikes.h"
#include "mesh/prepared_access.h"
#include "normals/jet_normals_from.h"

namespace focal::detail::recommended {
namespace {

/// Vertices sampled for the noise measurement: at most about kNoiseSamples, evenly by index.
constexpr Eigen::Index kNoiseSamples = 4096;

/// Whether vertex i (of n) is in the sample the per-mesh choices are measured on: every
/// step-th vertex by index, about kNoiseSamples of them. Their medians over 4,096 vertices are
/// within about 2% (one standard error of a median over 4,096) of the whole mesh's.
bool in_mesh_wide_sample(Eigen::Index i, Eigen::Index n) {
  const Eigen::Index step = std::max<Eigen::Index>(1, n / kNoiseSamples);
  return i % step == 0;
}

/// The vertices of in_mesh_wide_sample, ascending.
std::vector<int> mesh_wide_sample(Eigen::Index n) {
  std::vector<int> out;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (in_mesh_wide_sample(i, n)) out.push_back(static_cast<int>(i));
  }
  return out;
}

/// The position noise of recommended_plan (recommended.h) at the listed vertices (entry k:
/// vertex sample[k], length units): the 2-ring cubic jets' residuals `r2` (entry k: vertex
/// sample[k]'s; finite) with
/// their truncation error taken out, by the 3-ring jets' residuals. A cubic's truncation error
/// grows as radius^4, and the 3-ring's radius is about 3/2 the 2-ring's: its squared residual
/// would grow (3/2)^8 = 25.6 times, the noise's not at all (the residuals are per degree of
/// freedom). The divisor below is (3/2)^4 - 1, not (3/2)^8 - 1: the plan's noise thresholds
/// (kNoiseForTwoRings, kNoiseForThreeRings) were measured with it, so it stays until they are
/// measured again with the other.
Eigen::VectorXd noise_at(const Context& c, const Eigen::VectorXd& r2,
                         const std::vector<int>& sample) {
  const Eigen::VectorXd r3 =
      detail::jet_residuals_at(c.mesh.V(), *c.one_ring, c.max, jet_options(3, 3), sample);
  constexpr double kGrowth = 5.0625 - 1.0;  // (3/2)^4 - 1
  Eigen::VectorXd noise(static_cast<Eigen::Index>(sample.size()));
  for (Eigen::Index k = 0; k < noise.size(); ++k) {
    const double a = r2[k], b = r3[k];
    const double truncation = std::max(0.0, b * b - a * a) / kGrowth;
    noise[k] = std::isfinite(b) ? std::sqrt(std::max(0.0, a * a - truncation)) : NAN;
  }
  return noise;
}

/// The entries of `sample` (vertices) whose 2-ring jet residual `r2` (entry k: sample[k]'s)
/// is finite, with those residuals: the position noise's sample.
std::pair<std::vector<int>, Eigen::VectorXd> with_finite_residual(const std::vector<int>& sample,
                                                                  const Eigen::VectorXd& r2) {
  std::vector<int> vertices;
  std::vector<double> residual;
  for (std::size_t k = 0; k < sample.size(); ++k) {
    const double r = r2[static_cast<Eigen::Index>(k)];
    if (!std::isfinite(r)) continue;
    vertices.push_back(sample[k]);
    residual.push_back(r);
  }
  return {vertices, Eigen::Map<const Eigen::VectorXd>(residual.data(), std::ssize(residual))};
}

/// The listed rows of N (row k: row rows[k]).
RowMatrixX3d rows_of(NormalsRef N, const std::vector<int>& rows) {
  RowMatrixX3d out(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.row(static_cast<Eigen::Index>(k)) = N.row(rows[k]);
  return out;
}

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

/// +1 when most usable rows of `file` point to the side of `estimated`, -1 when most point
/// against it (a file whose normals point inward while the faces turn outward).
double majority_side(NormalsRef file, NormalsRef estimated) {
  const auto [along, against] = sides(file, estimated);
  return side_of(along, against);
}

/// normal_angle of row i of A and side * row i of B.
double angle_between(NormalsRef A, NormalsRef B, double side, Eigen::Index i) {
  return normal_angle(A.row(i).transpose(), side * B.row(i).transpose());
}

/// angle_between at every row.
Eigen::VectorXd angles_between(NormalsRef A, NormalsRef B, double side, int threads) {
  Eigen::VectorXd angle(A.rows());
  detail::parallel_for(A.rows(), threads,
                       [&](std::int64_t i) { angle[i] = angle_between(A, B, side, i); });
  return angle;
}

/// The medians of the file's normals over the sample (radians; slope units) and their side.
struct FileMedians {
  double angle = NAN, roughness = NAN, side = 1.0;
};

/// The per-mesh choices from their medians over the whole mesh (length units) and the file's:
/// measured on one mesh (measure_mesh_wide) or over its parts (recommended_mesh_wide_from).
RecommendedMeshWide mesh_wide_of(double jet_residual, double sample_noise, const FileMedians& file,
                                 double height_share, double edge_length) {
  RecommendedMeshWide m;
  m.height_share = height_share;
  m.noise = jet_residual / edge_length;
  m.position_noise = sample_noise / edge_length;
  m.file_disagreement = file.angle;
  m.side = file.side;
  m.file_roughness = file.roughness;
  return m;
}

/// The height fit's truncation shares (curvature/height_fit.h) at the listed vertices, in the
/// frames of their jet normals (rows of `jet_normals`), its turn guard on Max's normals.
Eigen::VectorXd height_shares(const Context& c, const std::vector<int>& vertices,
                              const RowMatrixX3d& jet_normals) {
  std::vector<char> ok(static_cast<std::size_t>(c.max.rows()));
  for (Eigen::Index v = 0; v < c.max.rows(); ++v) {
    ok[static_cast<std::size_t>(v)] = c.max.row(v).allFinite() ? 1 : 0;
  }
  const auto incidence = detail::incidence(c.mesh);
  Eigen::VectorXd out(std::ssize(vertices));
  detail::parallel_for(out.size(), 0, [&](std::int64_t k) {
    const Eigen::Vector3d n = jet_normals.row(k).transpose();
    out[k] = n.allFinite() ? detail::height_truncation_share(c.mesh.V(), c.max, ok, *c.one_ring,
                                                             *incidence, vertices[k], n)
                           : NAN;
  });
  return out;
}

}  // namespace

RecommendedPlan plan_for(const RecommendedMeshWide& m, const RecommendedOptions& options) {
  RecommendedPlan plan = recommended_plan_for_noise(m.position_noise, options);
  plan.noise = m.noise;
  return plan;
}

bool file_normals_agree(double median_angle, double noise, double agreement) {
  if (!std::isfinite(median_angle)) return false;  // no normal of the file is usable
  if (!std::isfinite(noise)) return true;          // no jets to judge them by
  // Angles at rounding level agree whatever the noise (a plane has noise 0).
  return median_angle <= std::max(agreement * noise, 1e-12);
}

double normal_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const bool usable = a.allFinite() && b.allFinite() && a != Eigen::Vector3d::Zero() &&
                      b != Eigen::Vector3d::Zero();
  return usable ? std::atan2(a.cross(b).norm(), a.dot(b)) : NAN;
}

RecommendedMeshWide measure_mesh_wide(const Context& c, const JetNormals* all) {
  const std::vector<int> sample = mesh_wide_sample(c.mesh.vertex_count());
  JetNormals jets;
  if (all != nullptr) {
    jets.N = rows_of(all->N, sample);
    jets.residual.resize(std::ssize(sample));
    for (std::size_t k = 0; k < sample.size(); ++k) {
      jets.residual[static_cast<Eigen::Index>(k)] = all->residual[sample[k]];
    }
  } else {
    jets = detail::jet_normals_at(c.mesh.V(), *c.one_ring, c.max, jet_options(2, 3), sample);
  }
  FileMedians medians;
  if (const std::optional<NormalsRef> file = c.mesh.normals()) {
    // The file's normals decide the side (the sign of the curvature), as in estimate_curvature;
    // normals from the positions take the side of the faces until turned.
    const RowMatrixX3d file_rows = rows_of(*file, sample);
    medians.side = majority_side(file_rows, jets.N);
    medians.angle = finite_median(angles_between(file_rows, jets.N, medians.side, 0));
    medians.roughness = finite_median(roughness_at(c, *file, sample));
  }
  const auto [noise_sample, r2] = with_finite_residual(sample, jets.residual);
  const double jet_residual = finite_median(jets.residual);
  // The height fit runs only where the file's normals are not used.
  const bool file_used =
      c.mesh.normals().has_value() &&
      file_normals_agree(medians.angle, jet_residual / c.edge_length, c.options.file_agreement);
  const double share = file_used ? NAN : finite_median(height_shares(c, sample, jets.N));
  return mesh_wide_of(jet_residual, finite_median(noise_at(c, r2, noise_sample)), medians, share,
                      c.edge_length);
}

}  // namespace focal::detail::recommended

namespace focal {

using namespace detail::recommended;

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
  return plan_for(measure_mesh_wide(c), options);
}

RecommendedMeshWide recommended_mesh_wide(const PreparedMesh& mesh,
                                          const RecommendedOptions& options) {
  validate_options(options, "recommended_mesh_wide");
  RecommendedOptions measured = options;
  measured.mesh_wide.reset();
  return measure_mesh_wide(make_context(mesh, measured));
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
  // The listed rows in the whole mesh's sample (by whole-mesh index), and where they are listed.
  std::vector<int> sampled;
  std::vector<Eigen::Index> listed;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (in_mesh_wide_sample(ids[static_cast<std::size_t>(rows[k])], whole_vertex_count)) {
      sampled.push_back(rows[k]);
      listed.push_back(static_cast<Eigen::Index>(k));
    }
  }
  // Their jets (detail::jet_normals_at: the bits of the whole mesh's).
  const JetNormals jets =
      detail::jet_normals_at(part.V(), *c.one_ring, c.max, jet_options(2, 3), sampled);
  const auto m = static_cast<Eigen::Index>(rows.size());
  RecommendedStatistics out;
  out.jet_residual = Eigen::VectorXd::Constant(m, NAN);
  for (std::size_t s = 0; s < sampled.size(); ++s) {
    out.jet_residual[listed[s]] = jets.residual[static_cast<Eigen::Index>(s)];
  }
  const auto [noise_sample, r2] = with_finite_residual(sampled, jets.residual);
  for (const int r : noise_sample) out.sample.push_back(ids[static_cast<std::size_t>(r)]);
  out.sample_noise = noise_at(c, r2, noise_sample);
  const Eigen::VectorXd shares = height_shares(c, sampled, jets.N);
  out.height_share = Eigen::VectorXd::Constant(m, NAN);
  for (std::size_t s = 0; s < sampled.size(); ++s) {
    out.height_share[listed[s]] = shares[static_cast<Eigen::Index>(s)];
  }
  if (const std::optional<NormalsRef> file = part.normals()) {
    const RowMatrixX3d file_rows = rows_of(*file, sampled);
    std::tie(out.along, out.against) = sides(file_rows, jets.N);
    const Eigen::VectorXd roughness = roughness_at(c, *file, sampled);
    out.angle_along = out.angle_against = out.file_roughness = Eigen::VectorXd::Constant(m, NAN);
    for (std::size_t s = 0; s < sampled.size(); ++s) {
      const auto k = static_cast<Eigen::Index>(s);
      out.angle_along[listed[s]] = angle_between(file_rows, jets.N, 1.0, k);
      out.angle_against[listed[s]] = angle_between(file_rows, jets.N, -1.0, k);
      out.file_roughness[listed[s]] = roughness[k];
    }
  }
  return out;
}

RecommendedMeshWide recommended_mesh_wide_from(const RecommendedMedians& whole,
                                               double mean_edge_length) {
  FileMedians file;
  if (whole.has_normals) {
    file.side = side_of(whole.along, whole.against);
    file.angle = file.side < 0.0 ? whole.angle_against : whole.angle_along;
    file.roughness = whole.file_roughness;
  }
  return mesh_wide_of(whole.jet_residual, finite_median(whole.sample_noise), file,
                      whole.height_share, mean_edge_length);
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
  //    kCorrectedBallRings + 1 rings) and the stencil asymmetry of v's 1-ring (2 rings), the
  //    Hermite fit (hermite_fit.h) the positions and fitted normals of v's 2-ring at most;
  //  - on clean positions each position read may be a repaired spike's: with trusted normals
  //    (spike_repair.h) a spike's offset reads its 1-ring, whether it is isolated the offsets
  //    of that 1-ring, 2 rings in all; without them (mesh/position_spikes.h)
  //    kPositionSpikeRings.
  const int normal_reach = std::max(kBoundaryJetRings + 2, plan.rings > 1 ? plan.jet_rings + 2 : 0);
  const int fit_reach = std::max(std::max(plan.rings, 1) + kMaxExtraRings + 1,
                                 plan.rings > 1 ? 0 : detail::kCorrectedBallRings + 1);
  const int position_reach =
      plan.rings > 1 ? 0 : std::max(detail::kSpikeRepairRings, detail::kPositionSpikeRings);
  return fit_reach + normal_reach + position_reach;
}

RecommendedPlan recommended_plan(PositionsRef V, FacesRef F, const RecommendedOptions& options) {
  validate_options(options, "recommended_plan");
  return recommended_plan(detail::PreparedAccess::make(V, F, std::nullopt, {}, "recommended_plan"),
                          options);
}

}  // namespace focal
