#include "estimator_flags.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

#include "focal/error.h"
#include "focal/mesh_io.h"
#include "focal/normals.h"
#include "focal/recommended.h"
#include "input_check.h"

namespace focal::cli {
namespace {

/// The estimator used when the file has no normals: Max's weights are exact for vertices on a
/// sphere and second-order accurate on smooth surfaces, also on irregular meshes.
constexpr NormalWeighting kDefaultWeighting = NormalWeighting::max;

/// Normals estimated from faces take their side from the faces' orientation.
void orient_faces_outward(Mesh& mesh, const Log& log) {
  const OrientationReport report = orientation_report(mesh.V, mesh.F);
  if (const int inward = report.inward_count(); inward > 0) {
    log.warning(std::to_string(inward) +
                " closed component(s) are oriented inward; their faces "
                "were reversed so that normals point outward");
    mesh.F = orient_outward(mesh.F, report);
  }
}

RowMatrixX3d estimated_normals(Mesh& mesh, NormalWeighting weighting, const Log& log) {
  orient_faces_outward(mesh, log);
  return vertex_normals(mesh.V, mesh.F, weighting);
}

/// Rows of the file's normals that are missing (NaN) or zero are filled from the faces.
void fill_missing_rows(Mesh& mesh, RowMatrixX3d& normals, const Log& log) {
  std::vector<Eigen::Index> missing;
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    const double len = normals.row(i).norm();
    if (!std::isfinite(len) || len == 0.0) missing.push_back(i);
  }
  if (missing.empty()) return;
  const RowMatrixX3d estimated = vertex_normals(mesh.V, mesh.F, kDefaultWeighting);
  for (Eigen::Index i : missing) normals.row(i) = estimated.row(i);
  log.warning(std::to_string(missing.size()) +
              " vertices have no usable normal in the file; estimated them from the faces");
}

void check_file_normals(const Mesh& mesh, RowMatrixX3d& normals, const Log& log) {
  int rescaled = 0;
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    const double len = normals.row(i).norm();
    if (std::isfinite(len) && len > 0.0 && std::abs(len - 1.0) > 1e-6) {
      normals.row(i) /= len;
      ++rescaled;
    }
  }
  if (rescaled > 0)
    log.warning(std::to_string(rescaled) + " normals were not of unit length; normalised");
  if (mesh.F.rows() > 0 && fraction_against_faces(mesh.V, mesh.F, normals) > 0.5) {
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

RowMatrixX3d prepare_normals(Mesh& mesh, const std::string& mesh_name, NormalsSource source,
                             const Log& log) {
  Stage stage(log, "normals");
  if (source == NormalsSource::file && !mesh.has_normals()) {
    throw InvalidInput("--normals file: " + mesh_name + " has no vertex normals");
  }
  if (source == NormalsSource::file || (source == NormalsSource::automatic && mesh.has_normals())) {
    RowMatrixX3d normals = mesh.N;
    fill_missing_rows(mesh, normals, log);
    check_file_normals(mesh, normals, log);
    return normals;
  }
  const NormalWeighting weighting = source == NormalsSource::automatic ? kDefaultWeighting
                                    : source == NormalsSource::area    ? NormalWeighting::area
                                    : source == NormalsSource::angle   ? NormalWeighting::angle
                                                                       : NormalWeighting::max;
  return estimated_normals(mesh, weighting, log);
}

namespace {

/// The recommended estimator (recommended.h) on the file's normals when it has them.
Estimate run_recommended(Mesh& mesh, const std::string& mesh_name, const EstimatorFlags& flags,
                         const Log& log) {
  RowMatrixX3d file_normals(0, 3);
  if (mesh.has_normals()) {
    file_normals = prepare_normals(mesh, mesh_name, NormalsSource::file, log);
  } else {
    Stage stage(log, "normals");
    orient_faces_outward(mesh, log);  // the jets' normals take their side from the faces
  }
  RecommendedResult r;
  {
    Stage stage(log, "curvature");
    r = estimate_curvature_recommended_full(mesh.V, mesh.F, file_normals, flags.options.threads);
  }
  if (mesh.has_normals() && !r.file_normals_used) {
    log.warning("the file's normals disagree with the positions (median angle " +
                std::to_string(r.file_disagreement) +
                " rad to jet normals): using normals estimated from the positions on the "
                "file normals' side");
  }
  std::ostringstream plan;
  plan << "  recommended estimator: "
       << (r.file_normals_used ? "file normals, jet normals at outliers"
                               : "jet or Max normals, whichever is smoother")
       << ", position noise " << r.plan.noise << " x edge length, " << r.plan.rings << "-ring "
       << (r.plan.gaussian ? "Gaussian-weighted " : "") << "fit";
  log.info(plan.str());
  print_summary(r.curvature, log);
  return {std::move(r.N), std::move(r.curvature)};
}

}  // namespace

Mesh read_input(const std::string& path, const EstimatorFlags& flags, const Log& log) {
  Mesh mesh;
  {
    Stage stage(log, "read");
    mesh = read_mesh(path);
    log.info("  " + std::to_string(mesh.V.rows()) + " vertices, " + std::to_string(mesh.F.rows()) +
             " triangles");
  }
  const RowMatrixX3d no_normals(0, 3);
  check_input(mesh, flags.uses_file_normals(mesh) ? mesh.N : no_normals, path, flags.strict, log);
  return mesh;
}

Estimate estimate(Mesh& mesh, const std::string& mesh_name, const EstimatorFlags& flags,
                  const Log& log) {
  if (flags.recommended()) return run_recommended(mesh, mesh_name, flags, log);
  RowMatrixX3d normals = prepare_normals(mesh, mesh_name, flags.normals, log);
  CurvatureResult fields = run_estimator(mesh, normals, flags, log);
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
