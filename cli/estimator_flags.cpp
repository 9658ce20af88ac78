#include "estimator_flags.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "focal/tiles/tiles.h"
#include "input_check.h"

namespace focal::cli {
namespace {

/// The warnings about what the normals stage fixed or suspects.
void report_normals(const NormalsReport& r, const std::string& mesh_name, const Log& log) {
  if (r.reoriented_component_count > 0) {
    log.warning(mesh_name + ": " + std::to_string(r.reoriented_component_count) +
                " closed component(s) are oriented inward; their faces "
                "were reversed so that normals point outward");
  }
  if (r.filled_normal_count > 0) {
    log.warning(mesh_name + ": " + std::to_string(r.filled_normal_count) +
                " vertices have no usable normal in the file; estimated them from the faces");
  }
  if (r.rescaled_normal_count > 0) {
    log.warning(mesh_name + ": " + std::to_string(r.rescaled_normal_count) +
                " normals were not of unit length; normalised");
  }
  if (r.normals_against_faces) {
    log.warning(mesh_name +
                ": most file normals point against the face orientation (inward?); curvature "
                "signs follow the normals");
  }
}

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
void report_recommended(const Input& input, const std::string& mesh_name, const Estimate& e,
                        const Log& log) {
  if (input.prepared->has_normals() && !e.file_normals_used) {
    log.warning(mesh_name + ": the file's normals disagree with the positions (median angle " +
                std::to_string(e.file_disagreement) +
                " rad to jet normals): using normals estimated from the positions on the "
                "file normals' side");
  }
  std::ostringstream plan;
  plan << "  recommended estimator: " << normals_used(e) << ", jet residual " << e.plan.noise
       << ", position noise " << e.plan.position_noise << " x edge length, " << e.plan.rings
       << "-ring " << (e.plan.gaussian ? "Gaussian-weighted " : "") << "fit";
  log.info(plan.str());
}

/// The widest neighbourhood, in rings, that the run gathered; 1 when it used 1-rings only
/// (never capped: kMaxNeighbourhoodSize).
int widest_rings(const EstimateOptions& o, const Estimate& e) {
  if (o.estimator == Estimator::paper) return o.paper.method == Method::vertex ? o.paper.rings : 1;
  // The recommended estimator's first jets take 2 rings (recommended.h).
  return e.plan.rings > 1 ? std::max(e.plan.rings, e.plan.jet_rings) : 2;
}

/// Whether some vertex may have more than kMaxNeighbourhoodSize vertices within `rings` rings: an
/// O(#F) bound from the largest valence D (at most twice a vertex's faces), D (D - 1)^(j - 1)
/// vertices at ring j, which keeps ordinary meshes from paying for a search of their rings.
bool may_be_crowded(const PreparedMesh& mesh, int rings) {
  if (mesh.vertex_count() == 0) return false;
  std::vector<int> faces(static_cast<std::size_t>(mesh.vertex_count()), 0);
  const FacesRef F = mesh.F();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) ++faces[static_cast<std::size_t>(F(f, c))];
  }
  const double valence = 2.0 * *std::max_element(faces.begin(), faces.end());
  double ring = valence, total = 0.0;
  for (int j = 1; j <= rings; ++j, ring *= valence - 1.0) total += ring;
  return total > kMaxNeighbourhoodSize;
}

/// Warnings about vertices without an estimate: those whose neighbourhood was over the cap, and
/// a mesh where no vertex has one.
void report_undefined(const PreparedMesh& mesh, const std::string& mesh_name,
                      const EstimateOptions& o, const Estimate& e, const Log& log) {
  const auto& classes = e.curvature.point_class;
  const auto undefined =
      std::count(classes.begin(), classes.end(), static_cast<std::uint8_t>(PointClass::undefined));
  const int rings = widest_rings(o, e);
  // Crowded vertices lose their jets: without a 2-ring fit they are undefined (or, on the
  // recommended estimator's 1-ring path, fitted on Max's normals), so a run without undefined
  // vertices has none to report.
  const bool lost_jets = o.estimator == Estimator::recommended && e.plan.rings == 1;
  std::size_t crowded = 0;
  if (rings > 1 && (undefined > 0 || lost_jets) && may_be_crowded(mesh, rings)) {
    crowded = crowded_vertices(
                  vertex_adjacency(static_cast<int>(mesh.vertex_count()), mesh.F(), mesh.threads()),
                  rings, mesh.threads())
                  .size();
  }
  if (crowded > 0) {
    log.warning(mesh_name + ": " + std::to_string(crowded) + " vertices have more than " +
                std::to_string(kMaxNeighbourhoodSize) + " vertices within " +
                std::to_string(rings) +
                " rings (a polygon of thousands of corners, or an edge of thousands of faces?): " +
                (lost_jets ? "their fit uses their 1-ring and Max's normals only, no jets"
                           : "left undefined"));
  }
  if (undefined > 0 && undefined == classes.size()) {
    log.warning(mesh_name + ": every vertex is undefined (" + std::to_string(undefined) + ")" +
                (crowded > 0 ? ""
                             : ": no vertex has two neighbour rays to fit (a mesh this coarse, "
                               "with neighbouring normals 90 degrees or more apart, has none)"));
  }
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
                  "than this many times those neighbours' median distance to it (0 = off; "
                  "docs/POINTS.md)")
      ->default_str(std::to_string(default_off_surface_ratio).substr(0, 4));
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

Input::Input(const std::string& path, const EstimatorFlags& flags, const Log& log) : path(path) {
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
    report_normals(normals.report, mesh_name, log);
  }
  Estimate e;
  {
    Stage stage(log, "curvature");
    e = estimate(mesh, std::move(normals), options);
  }
  if (options.estimator == Estimator::recommended) report_recommended(input, mesh_name, e, log);
  report_undefined(mesh, mesh_name, options, e, log);
  print_summary(e.curvature, log);
  return e;
}

TileEstimate run_tiled_estimate(const Input& input, const std::string& mesh_name,
                                const EstimatorFlags& flags, int tiles, const Log& log) {
  if (input.cloud) {
    const CloudOptions options = flags.cloud_options();
    const std::int64_t n = input.mesh.V.rows();
    const auto per_tile = static_cast<int>(std::max<std::int64_t>(1, (n + tiles - 1) / tiles));
    TileEstimate c;
    {
      Stage stage(log, "cloud curvature in tiles of " + std::to_string(per_tile) + " points");
      c = estimate_cloud_tiled(input.mesh.V, input.mesh.normals(), options,
                               {.tile_vertices = per_tile, .threads = flags.threads});
    }
    print_summary(c.curvature, log);
    return c;
  }
  const PreparedMesh& mesh = *input.prepared;
  const EstimateOptions options = flags.estimate_options();
  if (options.normals == NormalsSource::file && !mesh.has_normals()) {
    throw InvalidInput("--normals file: " + mesh_name + " has no vertex normals");
  }
  const std::int64_t n = mesh.vertex_count();
  const auto per_tile = static_cast<int>(std::max<std::int64_t>(1, (n + tiles - 1) / tiles));
  TileEstimate c;
  {
    Stage stage(log, "curvature in tiles of " + std::to_string(per_tile) + " vertices");
    c = estimate_tiled(mesh, options, {.tile_vertices = per_tile, .threads = flags.threads});
  }
  print_summary(c.curvature, log);
  return c;
}

CloudCurvature run_cloud_estimate(const Input& input, const EstimatorFlags& flags, const Log& log) {
  CloudOptions options = flags.cloud_options();
  // No command writes the lists (64 bytes a point at k = 16): not taken back, not held while
  // the outputs are written.
  options.keep_neighbours = false;
  CloudCurvature c;
  {
    Stage stage(log, "cloud curvature");
    c = estimate_cloud_curvature(input.mesh.V, input.mesh.normals(), options);
  }
  log.info(std::string("  normals: ") +
           (c.normals_estimated ? "estimated from the positions" : "the file's") +
           "; mean spacing " + std::to_string(c.spacing));
  const auto& classes = c.curvature.point_class;
  if (classes.size() > 0 && std::all_of(classes.begin(), classes.end(), [](std::uint8_t k) {
        return k == static_cast<std::uint8_t>(PointClass::undefined);
      })) {
    log.warning(input.path + ": every point is undefined (" + std::to_string(classes.size()) +
                "): no point has two neighbours apart from it with normals to fit (fewer than 3 "
                "distinct points, or points along a line, span no surface)");
  }
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
