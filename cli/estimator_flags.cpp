#include "estimator_flags.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/normals.h"
#include "focal/curvature/recommended.h"
#include "input_check.h"

namespace focal::cli {
namespace {

/// The estimator used when the file has no normals: Max's weights are exact for vertices on a
/// sphere and second-order accurate on smooth surfaces, also on irregular meshes.
constexpr NormalWeighting kDefaultWeighting = NormalWeighting::max;

/// Normals estimated from faces take their side from the faces' orientation. The check stage
/// has counted the inward components of this very F; only when there are some is the report
/// (a pass over the whole topology) computed again, for the faces to reverse.
void orient_faces_outward(Mesh& mesh, const MeshFindings& findings, const Log& log) {
  if (findings.inward_component_count == 0) return;
  const OrientationReport report = orientation_report(mesh.V, mesh.F);
  if (const int inward = report.inward_count(); inward > 0) {
    log.warning(std::to_string(inward) +
                " closed component(s) are oriented inward; their faces "
                "were reversed so that normals point outward");
    mesh.F = orient_outward(mesh.F, report);
  }
}

RowMatrixX3d estimated_normals(Mesh& mesh, const MeshFindings& findings, NormalWeighting weighting,
                               const Log& log) {
  orient_faces_outward(mesh, findings, log);
  return vertex_normals(mesh.V, mesh.F, weighting);
}

/// Rows of the file's normals that are missing (NaN) or zero are filled from the faces.
void fill_missing_rows(Mesh& mesh, const Log& log) {
  std::vector<Eigen::Index> missing;
  for (Eigen::Index i = 0; i < mesh.N.rows(); ++i) {
    const double len = mesh.N.row(i).norm();
    if (!std::isfinite(len) || len == 0.0) missing.push_back(i);
  }
  if (missing.empty()) return;
  const RowMatrixX3d estimated = vertex_normals(mesh.V, mesh.F, kDefaultWeighting);
  for (Eigen::Index i : missing) mesh.N.row(i) = estimated.row(i);
  log.warning(std::to_string(missing.size()) +
              " vertices have no usable normal in the file; estimated them from the faces");
}

void normalise_rows(Mesh& mesh, const Log& log) {
  int rescaled = 0;
  for (Eigen::Index i = 0; i < mesh.N.rows(); ++i) {
    const double len = mesh.N.row(i).norm();
    if (std::isfinite(len) && len > 0.0 && std::abs(len - 1.0) > 1e-6) {
      mesh.N.row(i) /= len;
      ++rescaled;
    }
  }
  if (rescaled > 0)
    log.warning(std::to_string(rescaled) + " normals were not of unit length; normalised");
}

/// Makes the file's normals (mesh.N) usable in place, warning about what it fixed or suspects.
/// The findings (check_mesh of these normals) say whether any row needs fixing, so the usual
/// file of unit normals is not scanned again, and how many normals point against their faces:
/// that count covers the rows as given, so the filled rows (which follow the faces) are not in
/// it, and rescaling does not change a sign.
void prepare_file_normals(Mesh& mesh, const MeshFindings& findings, const Log& log) {
  if (findings.non_finite_normal_count + findings.zero_normal_count +
          findings.non_unit_normal_count >
      0) {
    fill_missing_rows(mesh, log);
    normalise_rows(mesh, log);
  }
  if (2 * findings.normals_against_faces_count > findings.normals_compared_count) {
    log.warning(
        "most file normals point against the face orientation (inward?); curvature signs "
        "follow the normals");
  }
}

std::string range_of(const Eigen::VectorXd& v) {
  double lo = INFINITY, hi = -INFINITY;
  for (double x : v) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  std::ostringstream s;
  s << "[" << lo << ", " << hi << "]";
  return s.str();
}

void print_summary(const CurvatureResult& r, const Log& log) {
  if (!log.verbose()) return;  // three passes over #V for lines nobody sees
  std::array<int, 6> counts{};
  for (auto c : r.point_class) ++counts[c];
  std::string line = "  classes:";
  for (int c = 0; c < 6; ++c) {
    line +=
        " " + std::string(class_name(static_cast<PointClass>(c))) + "=" + std::to_string(counts[c]);
  }
  log.info(line);
  log.info("  H range: " + range_of(r.H) + "   K range: " + range_of(r.K));
}

}  // namespace

void EstimatorFlags::add_to(CLI::App& command) {
  const std::map<std::string, Method> methods = {{"vertex", Method::vertex},
                                                 {"triangle", Method::triangle}};
  const std::map<std::string, Solver> solvers = {
      {"closed-form", Solver::closed_form}, {"levenberg-marquardt", Solver::levenberg_marquardt}};
  const std::map<std::string, RayWeighting> weights = {{"uniform", RayWeighting::uniform},
                                                       {"gaussian", RayWeighting::gaussian}};
  const std::map<std::string, NormalsSource> sources = {{"file", NormalsSource::file},
                                                        {"area", NormalsSource::area},
                                                        {"angle", NormalsSource::angle},
                                                        {"max", NormalsSource::max}};
  method_options.push_back(
      command
          .add_option("--method", options.method,
                      "per-vertex two-slit fit or per-triangle characteristic equation")
          ->transform(CLI::CheckedTransformer(methods))
          ->default_str("vertex"));
  method_options.push_back(command.add_option("--solver", options.solver, "two-slit solver")
                               ->transform(CLI::CheckedTransformer(solvers))
                               ->default_str("closed-form"));
  method_options.push_back(
      command.add_option("--rings", options.rings, "neighbourhood size in rings (1 = the paper's)")
          ->check(CLI::Range(1, 16))
          ->default_str("1"));
  method_options.push_back(command.add_option("--weights", options.weighting, "ray weights")
                               ->transform(CLI::CheckedTransformer(weights))
                               ->default_str("uniform"));
  method_options.push_back(
      command
          .add_option("--normals", normals,
                      "vertex normals: the file's, or estimated from faces by area, angle or Max "
                      "(1999) weights [paper's method default: the file's when present, else max]")
          ->transform(CLI::CheckedTransformer(sources)));
  command.add_flag("--paper", paper,
                   "the paper's method as written (1-ring closed-form two-slit fit of the "
                   "file's normals, else of Max normals) instead of the recommended estimator; "
                   "implied by any of --method --solver --rings --weights --normals");
  command.add_option("--threads", options.threads, "worker threads (0 = FOCAL_NUM_THREADS or all)")
      ->check(CLI::NonNegativeNumber);
  command.add_flag("--strict", strict,
                   "fail (exit 2, nothing written) when the input has problems such as NaN "
                   "coordinates, degenerate or non-manifold faces or bad normals, instead of "
                   "warning and leaving the affected vertices undefined");
}

bool EstimatorFlags::recommended() const {
  if (paper) return false;
  for (const CLI::Option* o : method_options) {
    if (o->count() > 0) return false;
  }
  return true;
}

bool EstimatorFlags::uses_file_normals(const Mesh& mesh) const {
  return mesh.has_normals() &&
         (normals == NormalsSource::file || normals == NormalsSource::automatic);
}

RowMatrixX3d prepare_normals(Mesh& mesh, const MeshFindings& findings, const std::string& mesh_name,
                             NormalsSource source, const Log& log) {
  Stage stage(log, "normals");
  if (source == NormalsSource::file && !mesh.has_normals()) {
    throw InvalidInput("--normals file: " + mesh_name + " has no vertex normals");
  }
  if (source == NormalsSource::file || (source == NormalsSource::automatic && mesh.has_normals())) {
    prepare_file_normals(mesh, findings, log);
    return std::move(mesh.N);  // the caller writes the normals it used, not a copy of them
  }
  const NormalWeighting weighting = source == NormalsSource::automatic ? kDefaultWeighting
                                    : source == NormalsSource::area    ? NormalWeighting::area
                                    : source == NormalsSource::angle   ? NormalWeighting::angle
                                                                       : NormalWeighting::max;
  return estimated_normals(mesh, findings, weighting, log);
}

namespace {

/// Which normals the recommended estimator fitted (recommended.h, step 3).
std::string normals_used(const RecommendedResult& r) {
  if (r.file_normals_used) return "file normals (jet normals at outliers)";
  if (r.plan.rings > 1) {
    return "normals of degree-" + std::to_string(r.plan.jet_degree) + " jets over " +
           std::to_string(r.plan.jet_rings) + " rings";
  }
  return "jet or Max normals, whichever is smoother";
}

/// The recommended estimator (recommended.h) on the file's normals when it has them, used in
/// place in mesh.N (the estimator returns the normals it chose).
Estimate run_recommended(Input& input, const EstimatorFlags& flags, const Log& log) {
  Mesh& mesh = input.mesh;
  const bool file_normals = mesh.has_normals();
  {
    Stage stage(log, "normals");
    if (file_normals) {
      prepare_file_normals(mesh, input.findings, log);
    } else {
      // The jets' normals take their side from the faces.
      orient_faces_outward(mesh, input.findings, log);
    }
  }
  RecommendedResult r;
  {
    Stage stage(log, "curvature");
    const RowMatrixX3d none(0, 3);
    // References, not `file_normals ? mesh.N : none`, whose value would be a copy.
    const NormalsRef normals = file_normals ? NormalsRef(mesh.N) : NormalsRef(none);
    r = estimate_curvature_recommended_full(mesh.V, mesh.F, normals, flags.options.threads);
  }
  if (file_normals && !r.file_normals_used) {
    log.warning("the file's normals disagree with the positions (median angle " +
                std::to_string(r.file_disagreement) +
                " rad to jet normals): using normals estimated from the positions on the "
                "file normals' side");
  }
  mesh.N.resize(0, 3);  // the file's normals are no longer needed: r.N replaces them
  std::ostringstream plan;
  plan << "  recommended estimator: " << normals_used(r) << ", position noise " << r.plan.noise
       << " x edge length, " << r.plan.rings << "-ring "
       << (r.plan.gaussian ? "Gaussian-weighted " : "") << "fit";
  log.info(plan.str());
  print_summary(r.curvature, log);
  return {std::move(r.N), std::move(r.curvature)};
}

/// --threads also pins the stages outside the estimator (see read_input).
void pin_threads(int threads) {
  if (threads > 0) setenv("FOCAL_NUM_THREADS", std::to_string(threads).c_str(), 1);
}

}  // namespace

Input read_input(const std::string& path, const EstimatorFlags& flags, const Log& log) {
  pin_threads(flags.options.threads);
  Input input;
  {
    Stage stage(log, "read");
    input.mesh = read_mesh(path);
    log.info("  " + std::to_string(input.mesh.V.rows()) + " vertices, " +
             std::to_string(input.mesh.F.rows()) + " triangles");
  }
  const RowMatrixX3d no_normals(0, 3);
  const Mesh& mesh = input.mesh;
  input.findings = check_input(mesh, flags.uses_file_normals(mesh) ? mesh.N : no_normals, path,
                               flags.strict, log);
  return input;
}

Estimate estimate(Input& input, const std::string& mesh_name, const EstimatorFlags& flags,
                  const Log& log) {
  if (flags.recommended()) return run_recommended(input, flags, log);
  RowMatrixX3d normals = prepare_normals(input.mesh, input.findings, mesh_name, flags.normals, log);
  CurvatureResult fields = run_estimator(input.mesh, normals, flags, log);
  return {std::move(normals), std::move(fields)};
}

CurvatureResult run_estimator(const Mesh& mesh, const RowMatrixX3d& normals,
                              const EstimatorFlags& flags, const Log& log) {
  CurvatureResult result;
  {
    Stage stage(log, "curvature");
    result = estimate_curvature(mesh.V, mesh.F, normals, flags.options);
  }
  print_summary(result, log);
  return result;
}

}  // namespace focal::cli
