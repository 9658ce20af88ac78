#include "estimator_flags.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "input_check.h"

namespace focal::cli {
namespace {

/// The warnings about what the normals stage fixed or suspects.
void report_normals(const NormalsReport& r, const Log& log) {
  if (r.reoriented_component_count > 0) {
    log.warning(std::to_string(r.reoriented_component_count) +
                " closed component(s) are oriented inward; their faces "
                "were reversed so that normals point outward");
  }
  if (r.filled_normal_count > 0) {
    log.warning(std::to_string(r.filled_normal_count) +
                " vertices have no usable normal in the file; estimated them from the faces");
  }
  if (r.rescaled_normal_count > 0) {
    log.warning(std::to_string(r.rescaled_normal_count) +
                " normals were not of unit length; normalised");
  }
  if (r.normals_against_faces) {
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

/// Which normals the recommended estimator fitted (recommended.h, step 3).
std::string normals_used(const Estimate& e) {
  if (e.file_normals_used) return "file normals (jet normals at outliers)";
  if (e.plan.rings > 1) {
    return "normals of degree-" + std::to_string(e.plan.jet_degree) + " jets over " +
           std::to_string(e.plan.jet_rings) + " rings";
  }
  return "jet or Max normals, whichever is smoother";
}

/// The recommended estimator's decisions: a warning when it ignored the file's normals, and with
/// -v its plan.
void report_recommended(const Input& input, const Estimate& e, const Log& log) {
  if (input.prepared->has_normals() && !e.file_normals_used) {
    log.warning("the file's normals disagree with the positions (median angle " +
                std::to_string(e.file_disagreement) +
                " rad to jet normals): using normals estimated from the positions on the "
                "file normals' side");
  }
  std::ostringstream plan;
  plan << "  recommended estimator: " << normals_used(e) << ", position noise " << e.plan.noise
       << " x edge length, " << e.plan.rings << "-ring "
       << (e.plan.gaussian ? "Gaussian-weighted " : "") << "fit";
  log.info(plan.str());
}

}  // namespace

void add_read_flags(CLI::App& command, ReadOptions& read) {
  auto* tolerance =
      command
          .add_option("--weld-tolerance", read.weld_tolerance,
                      "STL: weld facet corners within this distance into one vertex (default 0: "
                      "exactly equal positions)")
          ->check(CLI::NonNegativeNumber);
  command
      .add_flag_callback(
          "--no-weld", [&read] { read.weld = false; },
          "STL: keep every facet corner a vertex of its own (no triangle shares an edge, so "
          "every vertex is undefined)")
      ->excludes(tolerance);
}

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
  command.add_option("--threads", threads, "worker threads (0 = FOCAL_NUM_THREADS or all)")
      ->check(CLI::NonNegativeNumber);
  add_read_flags(command, read);
  add_cloud_flags(command);
  command.add_flag("--strict", strict,
                   "fail (exit 2, nothing written) when the input has problems such as NaN "
                   "coordinates, degenerate or non-manifold faces or bad normals, instead of "
                   "warning and leaving the affected vertices undefined");
}

void EstimatorFlags::add_cloud_flags(CLI::App& command) {
  const std::map<std::string, CloudNormalMethod> methods = {{"pca", CloudNormalMethod::pca},
                                                            {"jet", CloudNormalMethod::jet}};
  command
      .add_option("--k", cloud.k,
                  "point clouds: neighbours per point, the k nearest (0 = " +
                      std::to_string(default_cloud_neighbours) + ", docs/POINTS.md)")
      ->check(CLI::Range(0, 1024));
  command
      .add_option("--radius", cloud.radius,
                  "point clouds: neighbours within this distance instead of the k nearest")
      ->check(CLI::PositiveNumber);
  command
      .add_option("--viewpoint", viewpoint,
                  "point clouds without normals: orient estimated normals towards X,Y,Z (the "
                  "scanner) instead of by a minimum spanning tree")
      ->delimiter(',')
      ->expected(3);
  command
      .add_option("--cloud-normals", cloud.normals.method,
                  "point clouds without normals: pca, or jet (PCA then a quadratic jet)")
      ->transform(CLI::CheckedTransformer(methods))
      ->default_str("jet");
}

CloudOptions EstimatorFlags::cloud_options() const {
  for (const CLI::Option* o : method_options) {
    if (o->count() > 0 && o->get_name() != "--solver") {
      throw InvalidInput(o->get_name() +
                         " applies to meshes; the input is a point cloud (use --k or --radius)");
    }
  }
  CloudOptions o = cloud;
  o.solver = options.solver;
  o.threads = threads;
  if (viewpoint.size() == 3)
    o.normals.viewpoint = Eigen::Vector3d(viewpoint[0], viewpoint[1], viewpoint[2]);
  return o;
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

EstimateOptions EstimatorFlags::estimate_options() const {
  EstimateOptions o;
  o.estimator = recommended() ? Estimator::recommended : Estimator::paper;
  o.normals = normals;
  o.paper = options;
  o.paper.threads = threads;
  o.recommended.threads = threads;
  return o;
}

Input::Input(const std::string& path, const EstimatorFlags& flags, const Log& log) {
  {
    Stage stage(log, "read");
    ReadOptions read = flags.read;
    read.threads = flags.threads;
    mesh = read_mesh(path, read);
    // Every output has one row per vertex: an empty mesh would write an empty file and exit 0.
    if (mesh.V.rows() == 0) throw IoError(path + ": no vertices, nothing to compute");
    log.info("  " + std::to_string(mesh.V.rows()) + " vertices, " + std::to_string(mesh.F.rows()) +
             " triangles");
  }
  cloud = mesh.is_cloud();
  if (cloud) {
    check_cloud(mesh, path, flags.strict, log);
    return;
  }
  // No output of these commands maps triangles back to input polygons: 4 bytes per face less.
  mesh.face_source = Eigen::VectorXi();
  // The one validation of the arrays for the whole run.
  prepared.emplace(mesh.V, mesh.F, flags.uses_file_normals(mesh) ? mesh.normals() : std::nullopt,
                   PrepareOptions{.threads = flags.threads});
  findings = check_input(*prepared, path, flags.strict, log);
}

Estimate run_estimate(const Input& input, const std::string& mesh_name, const EstimatorFlags& flags,
                      const Log& log) {
  if (input.cloud) {
    throw InvalidInput(mesh_name + ": is a point cloud (no faces); this command needs a mesh");
  }
  const EstimateOptions options = flags.estimate_options();
  const PreparedMesh& mesh = *input.prepared;
  PreparedNormals normals;
  {
    Stage stage(log, "normals");
    if (options.normals == NormalsSource::file && !mesh.has_normals()) {
      throw InvalidInput("--normals file: " + mesh_name + " has no vertex normals");
    }
    normals = prepare_normals(mesh, options);
    report_normals(normals.report, log);
  }
  Estimate e;
  {
    Stage stage(log, "curvature");
    e = estimate(mesh, std::move(normals), options);
  }
  if (options.estimator == Estimator::recommended) report_recommended(input, e, log);
  print_summary(e.curvature, log);
  return e;
}

CloudCurvature run_cloud_estimate(const Input& input, const EstimatorFlags& flags, const Log& log) {
  const CloudOptions options = flags.cloud_options();
  CloudCurvature c;
  {
    Stage stage(log, "cloud curvature");
    c = estimate_cloud_curvature(input.mesh.V, input.mesh.normals(), options);
  }
  log.info(std::string("  normals: ") +
           (c.normals_estimated ? "estimated from the positions" : "the file's") +
           "; mean spacing " + std::to_string(c.spacing));
  print_summary(c.curvature, log);
  return c;
}

PreparedMesh estimated_mesh(const Input& input, const Estimate& e) {
  const PreparedMesh& mesh = *input.prepared;
  // Reversed faces come with normals estimated from them.
  if (e.F) return PreparedMesh(mesh.V(), *e.F, *e.N, {.threads = mesh.threads()});
  return e.N ? mesh.with_normals(*e.N) : mesh;
}

}  // namespace focal::cli
