#include "estimator_flags.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "input_check.h"

namespace focal::cli {
namespace {

/// "[lo, hi]" of the finite values, or words when there are none.
std::string range_of(const Eigen::VectorXd& v) {
  double lo = INFINITY, hi = -INFINITY;
  for (double x : v) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  if (lo > hi) return "none (no finite value)";
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

/// Whether some row of N is a normal: finite and not zero.
bool any_usable_normal(const RowMatrixX3d& N) {
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double length = N.row(i).squaredNorm();
    if (std::isfinite(length) && length > 0.0) return true;
  }
  return false;
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
  command.add_option("--threads", threads, "worker threads (0 = FOCAL_NUM_THREADS or every CPU; more than " +
                         std::to_string(kMaxThreads) + " is clamped to it)")
      ->check(CLI::NonNegativeNumber);
  command.add_flag("--ignore-normals", ignore_normals,
                   "read the input as if it had no normals (meshes and clouds): they are "
                   "estimated, as for a file without normal columns");
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
                  "point clouds: neighbours per point, the k nearest (0 = chosen from the "
                  "cloud: " +
                      std::to_string(default_cloud_neighbours) + ", or " +
                      std::to_string(4 * default_cloud_neighbours) +
                      " on noisy positions; docs/POINTS.md)")
      ->check(CLI::Range(0, 1024));
  command
      .add_option("--radius", cloud.radius,
                  "point clouds: neighbours within this distance instead of the k nearest")
      ->check(CLI::PositiveNumber);
  command
      .add_option("--adaptive-radius", cloud.adaptive_radius,
                  "point clouds: neighbours within C x the local spacing (the median over each "
                  "point's k nearest of their distance to their k-th nearest; k = --k or 16) "
                  "instead of the k nearest")
      ->check(CLI::PositiveNumber);
  command
      .add_option("--outlier-ratio", cloud.outlier_ratio,
                  "point clouds: leave out points farther from their 16 nearest than this many "
                  "times their neighbours' median (0 = keep every point; docs/POINTS.md)")
      ->default_str(std::to_string(default_outlier_ratio).substr(0, 3));
  command
      .add_option("--off-surface-ratio", cloud.off_surface_ratio,
                  "point clouds: leave out points farther from the plane of their 16 nearest "
                  "than this many times those neighbours' RMS distance to it (0 = off; "
                  "docs/POINTS.md)")
      ->default_str(std::to_string(default_off_surface_ratio).substr(0, 4));
  command
      .add_option("--viewpoint", viewpoint,
                  "point clouds without normals: orient estimated normals towards X,Y,Z (the "
                  "scanner) instead of by a minimum spanning tree")
      ->delimiter(',')
      ->expected(3);
  const std::map<std::string, CloudOrientation> orientations = {
      {"mst", CloudOrientation::mst},
      {"global", CloudOrientation::global},
      {"viewpoint", CloudOrientation::viewpoint}};
  command
      .add_option("--orient", cloud.normals.orientation,
                  "point clouds without normals: how estimated normals get their side: mst (a "
                  "minimum spanning tree), global (the tree, then the winding number: closed "
                  "surfaces with thin or touching parts; docs/POINTS.md) or viewpoint (towards "
                  "--viewpoint)")
      ->transform(CLI::CheckedTransformer(orientations))
      ->default_str("mst");
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
  if (viewpoint.size() == 3)
    o.normals.viewpoint = Eigen::Vector3d(viewpoint[0], viewpoint[1], viewpoint[2]);
  if (o.normals.orientation == CloudOrientation::viewpoint && !o.normals.viewpoint)
    throw InvalidInput("--orient viewpoint needs --viewpoint X,Y,Z");
  if (o.normals.orientation == CloudOrientation::global && o.normals.viewpoint)
    throw InvalidInput("--orient global and --viewpoint conflict: give one");
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
  return o;
}

Input::Input(const std::string& path, const EstimatorFlags& flags, const Log& log) : path(path) {
  {
    Stage stage(log, "read");
    mesh = read_mesh(path, flags.read);
    // Every output has one row per vertex: an empty mesh would write an empty file and exit 0.
    if (mesh.V.rows() == 0) throw IoError(path + ": no vertices, nothing to compute");
    log.info("  " + std::to_string(mesh.V.rows()) + " vertices, " + std::to_string(mesh.F.rows()) +
             " triangles");
  }
  if (flags.ignore_normals) {
    mesh.N.resize(0, 3);
  } else if (mesh.has_normals() && !any_usable_normal(mesh.N)) {
    // Columns of zeros (CGAL's blobby.xyz: x y z 0 0 0) say nothing about the surface: as if
    // absent, rather than every vertex undefined.
    log.warning(path + ": every normal in the file is zero or not finite: read as a file without "
                "normals (they are estimated; --ignore-normals says so without this warning)");
    mesh.N.resize(0, 3);
  }
  cloud = mesh.is_cloud();
  if (cloud) {
    check_cloud(mesh, path, flags.strict, log);
    prepared.emplace(mesh.V, mesh.F, mesh.normals());
    return;
  }
  // No output of these commands maps triangles back to input polygons: 4 bytes per face less.
  mesh.face_source = Eigen::VectorXi();
  // The one validation of the arrays for the whole run.
  prepared.emplace(mesh.V, mesh.F, flags.uses_file_normals(mesh) ? mesh.normals() : std::nullopt);
  findings = check_input(*prepared, path, flags.strict, log);
}

Estimate run_estimate(const Input& input, const EstimatorFlags& flags, const Log& log, int tiles) {
  const PreparedMesh& mesh = *input.prepared;
  EstimateOptions options = flags.estimate_options();
  if (input.cloud) {
    options.cloud = flags.cloud_options();
  } else if (options.normals == NormalsSource::file && !mesh.has_normals()) {
    throw InvalidInput("--normals file: " + input.path + " has no vertex normals");
  }
  if (tiles > 0) {
    const std::int64_t n = mesh.vertex_count();
    options.tile_vertices = static_cast<int>(std::max<std::int64_t>(1, (n + tiles - 1) / tiles));
  }
  options.execution = execution_for(log, input.path);
  Estimate e = curvature(mesh, options);
  print_summary(e.curvature, log);
  return e;
}

PreparedMesh estimated_mesh(const Input& input, const Estimate& e) {
  const PreparedMesh& mesh = *input.prepared;
  // Reversed faces come with normals estimated from them.
  if (e.F) return PreparedMesh(mesh.V(), *e.F, *e.N);
  return e.N ? mesh.with_normals(*e.N) : mesh;
}

}  // namespace focal::cli
