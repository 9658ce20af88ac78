// The mesh functions of focal._focal_ext: curvature, focal meshes, checks, normals, files and
// the analytic surfaces (python/focal/__init__.py wraps them).

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/core/fields.h"
#include "focal/curvature.h"
#include "focal/curvature/estimate.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/io/fields_io.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/check.h"
#include "focal/mesh/prepared.h"
#include "focal/normals/vertex_normals.h"
#include "focal/surfaces/surfaces.h"

namespace focal_python {

nb::dict curvature_dict(focal::CurvatureResult&& r) {
  nb::dict d;
  d["k1"] = to_numpy(std::move(r.k1));
  d["k2"] = to_numpy(std::move(r.k2));
  d["H"] = to_numpy(std::move(r.H));
  d["K"] = to_numpy(std::move(r.K));
  d["d1"] = to_numpy(std::move(r.d1));
  d["d2"] = to_numpy(std::move(r.d2));
  d["residual"] = to_numpy(std::move(r.residual));
  d["point_class"] = to_numpy(std::move(r.point_class));
  d["rays_used"] = to_numpy(std::move(r.rays_used));
  d["rays_excluded"] = to_numpy(std::move(r.rays_excluded));
  return d;
}

/// The options of focal::estimate from the keywords of focal.curvature (python/focal/__init__.py
/// documents them and checks which estimator they belong to).
focal::EstimateOptions estimate_options(const nb::dict& o) {
  static const std::pair<const char*, focal::Estimator> estimators[] = {
      {"recommended", focal::Estimator::recommended},
      {"paper", focal::Estimator::paper},
      {"meyer_2003", focal::Estimator::meyer_2003},
      {"cohen_steiner_morvan_2003", focal::Estimator::cohen_steiner_morvan_2003},
      {"lachaud_2020", focal::Estimator::lachaud_2020},
      {"yang_2006", focal::Estimator::yang_2006},
      {"grinspun_2006", focal::Estimator::grinspun_2006}};
  static const std::pair<const char*, focal::Device> devices[] = {{"cpu", focal::Device::cpu},
                                                                  {"cuda", focal::Device::cuda}};
  static const std::pair<const char*, focal::NormalsSource> sources[] = {
      {"auto", focal::NormalsSource::automatic},
      {"file", focal::NormalsSource::file},
      {"area", focal::NormalsSource::area},
      {"angle", focal::NormalsSource::angle},
      {"max", focal::NormalsSource::max}};
  static const std::pair<const char*, focal::Method> methods[] = {
      {"vertex", focal::Method::vertex}, {"triangle", focal::Method::triangle}};
  static const std::pair<const char*, focal::Solver> solvers[] = {
      {"closed-form", focal::Solver::closed_form},
      {"levenberg-marquardt", focal::Solver::levenberg_marquardt}};
  static const std::pair<const char*, focal::RayWeighting> weights[] = {
      {"uniform", focal::RayWeighting::uniform}, {"gaussian", focal::RayWeighting::gaussian}};

  focal::EstimateOptions e;
  e.estimator = parse_enum(nb::cast<std::string>(o["estimator"]), "estimator", estimators);
  e.normals = parse_enum(nb::cast<std::string>(o["normals"]), "normals", sources);
  focal::CurvatureOptions& p = e.paper;
  p.method = parse_enum(nb::cast<std::string>(o["method"]), "method", methods);
  p.solver = parse_enum(nb::cast<std::string>(o["solver"]), "solver", solvers);
  p.rings = nb::cast<int>(o["rings"]);
  p.weighting = parse_enum(nb::cast<std::string>(o["ray_weighting"]), "ray_weighting", weights);
  p.gaussian_width = nb::cast<double>(o["gaussian_width"]);
  p.levenberg_marquardt.initial_angles = nb::cast<int>(o["lm_initial_angles"]);
  p.levenberg_marquardt.max_iterations = nb::cast<int>(o["lm_max_iterations"]);
  p.levenberg_marquardt.tolerance = nb::cast<double>(o["lm_tolerance"]);
  p.tolerances.zero = nb::cast<double>(o["zero_tolerance"]);
  p.tolerances.umbilic = nb::cast<double>(o["umbilic_tolerance"]);
  focal::RecommendedOptions& r = e.recommended;
  r.noise_for_two_rings = nb::cast<double>(o["noise_for_two_rings"]);
  r.noise_for_three_rings = nb::cast<double>(o["noise_for_three_rings"]);
  r.file_agreement = nb::cast<double>(o["file_agreement"]);
  r.outlier_disagreement = nb::cast<double>(o["outlier_disagreement"]);
  r.tolerances = p.tolerances;
  e.execution.threads = nb::cast<int>(o["threads"]);
  if (o.contains("device")) {
    e.device = parse_enum(nb::cast<std::string>(o["device"]), "device", devices);
  }
  if (o.contains("tile_vertices")) e.tile_vertices = nb::cast<int>(o["tile_vertices"]);
  if (o.contains("cloud")) {
    e.cloud = cloud_options_from(nb::cast<nb::dict>(o["cloud"]));
    e.cloud.tolerances = p.tolerances;
  }
  return e;
}

namespace {

using namespace nb::literals;

nb::dict mesh_dict(focal::Mesh&& mesh) {
  nb::dict d;
  d["V"] = to_numpy(std::move(mesh.V));
  d["F"] = to_numpy(std::move(mesh.F));
  d["N"] = mesh.N.rows() > 0 ? nb::cast(to_numpy(std::move(mesh.N))) : nb::none();
  return d;
}

focal::NormalWeighting parse_weighting(const std::string& s) {
  static const std::pair<const char*, focal::NormalWeighting> names[] = {
      {"area", focal::NormalWeighting::area},
      {"angle", focal::NormalWeighting::angle},
      {"max", focal::NormalWeighting::max}};
  return parse_enum(s, "weighting", names);
}

nb::dict default_options() {
  const focal::CurvatureOptions p;
  const focal::RecommendedOptions r;
  const focal::FocalMeshOptions f;
  nb::dict d;
  d["rings"] = p.rings;
  d["gaussian_width"] = p.gaussian_width;
  d["lm_initial_angles"] = p.levenberg_marquardt.initial_angles;
  d["lm_max_iterations"] = p.levenberg_marquardt.max_iterations;
  d["lm_tolerance"] = p.levenberg_marquardt.tolerance;
  d["zero_tolerance"] = p.tolerances.zero;
  d["umbilic_tolerance"] = p.tolerances.umbilic;
  d["recommended_zero_tolerance"] = r.tolerances.zero;
  d["recommended_umbilic_tolerance"] = r.tolerances.umbilic;
  d["noise_for_two_rings"] = r.noise_for_two_rings;
  d["noise_for_three_rings"] = r.noise_for_three_rings;
  d["file_agreement"] = r.file_agreement;
  d["outlier_disagreement"] = r.outlier_disagreement;
  d["max_distance"] = f.max_distance;
  d["drop_faces_at_infinity"] = f.drop_faces_at_infinity;
  return d;
}

/// The estimate of focal.curvature's timing helper: the mesh pipeline (focal::estimate on a
/// PreparedMesh of the arrays as given), with the options' execution.
focal::Estimate run_estimate(const DoubleRows& V, const IntRows& F,
                             const std::optional<DoubleRows>& N, const focal::EstimateOptions& o) {
  const focal::ExecutionScope scope(o.execution);
  const focal::PreparedMesh mesh(view(V), view(F), normals_ref(N));
  return focal::estimate(mesh, o);
}

nb::dict cloud_plan_dict(const focal::CloudPlan& c) {
  nb::dict d;
  d["normals_estimated"] = c.normals_estimated;
  d["spacing"] = c.spacing;
  d["noise"] = c.noise;
  d["k"] = c.k;
  d["corrected"] = c.corrected;
  d["outlier_count"] = std::count(c.outlier.begin(), c.outlier.end(), char{1});
  return d;
}

/// focal.curvature's progress= callable (python/focal/_progress.py) behind the execution's
/// progress and pass_progress: (stage, 0, 0.0) as a stage begins, (stage, 0, 1.0) as it ends,
/// (stage, k, f) as its k-th parallel pass advances. Called on the calling thread, the GIL taken
/// for each call. A Python exception it raises is kept and stops the call (Cancelled, from
/// which rethrow() raises the kept exception again).
class PythonProgress {
 public:
  explicit PythonProgress(nb::object callable) : callable_(std::move(callable)) {}

  void attach(focal::Execution& e) {
    if (callable_.is_none()) return;
    e.progress = [this](const focal::Progress& p) {
      const bool begins = p.fraction == 0.0;
      if (begins) {
        stages_.emplace_back(p.stage);
        passes_.push_back(0);
      }
      call(std::string(p.stage), 0, p.fraction, begins);  // never throws as a stage ends
      if (!begins && !stages_.empty()) stages_.pop_back(), passes_.pop_back();
    };
    e.pass_progress = [this](const focal::PassProgress& p) {
      if (stages_.empty()) return;
      if (p.pass != last_pass_) last_pass_ = p.pass, ++passes_.back();
      call(stages_.back(), passes_.back(), p.fraction(), true);
    };
  }

  /// After the call stopped by an exception (the GIL held): the callable's, when it raised one.
  void rethrow() const {
    if (failed_) throw nb::python_error();
  }

 private:
  void call(const std::string& stage, int pass, double fraction, bool may_throw) {
    if (failed_) {
      if (may_throw) throw focal::Cancelled("cancelled: the progress callable raised");
      return;
    }
    const nb::gil_scoped_acquire gil;
    try {
      callable_(stage, pass, fraction);
    } catch (nb::python_error& error) {
      error.restore();  // raised again by rethrow()
      failed_ = true;
      if (may_throw) throw focal::Cancelled("cancelled: the progress callable raised");
    }
  }

  nb::object callable_;
  std::vector<std::string> stages_;  ///< begun, innermost last
  std::vector<int> passes_;          ///< passes seen of each
  std::uint64_t last_pass_ = 0;
  bool failed_ = false;
};

/// focal.curvature: the front door (focal::curvature) on the arrays, a cloud when F has no rows;
/// its warnings collected for Python's warnings module.
nb::dict curvature(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                   const nb::dict& options) {
  focal::EstimateOptions o = estimate_options(options);
  std::vector<std::string> warnings;
  o.execution.warning = [&warnings](const std::string& w) { warnings.push_back(w); };
  PythonProgress progress(options.contains("progress") ? nb::object(options["progress"])
                                                       : nb::none());
  progress.attach(o.execution);
  focal::Estimate e;
  try {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope(o.execution);
    const focal::PreparedMesh mesh(view(V), view(F), normals_ref(N));
    e = focal::curvature(mesh, o);
  } catch (...) {
    progress.rethrow();
    throw;
  }
  nb::dict d = curvature_dict(std::move(e.curvature));
  d["warnings"] = warnings;
  d["crowded_count"] = e.crowded_count;
  d["cloud"] = e.cloud ? nb::object(cloud_plan_dict(*e.cloud)) : nb::none();
  d["N"] = optional_to_numpy(std::move(e.N));
  d["F"] = optional_to_numpy(std::move(e.F));
  nb::dict report;
  report["reoriented_component_count"] = e.normals_report.reoriented_component_count;
  report["filled_normal_count"] = e.normals_report.filled_normal_count;
  report["rescaled_normal_count"] = e.normals_report.rescaled_normal_count;
  report["normals_against_faces"] = e.normals_report.normals_against_faces;
  d["normals_report"] = report;
  nb::dict plan;
  plan["noise"] = e.plan.noise;
  plan["position_noise"] = e.plan.position_noise;
  plan["rings"] = e.plan.rings;
  plan["gaussian"] = e.plan.gaussian;
  plan["jet_rings"] = e.plan.jet_rings;
  plan["jet_degree"] = e.plan.jet_degree;
  plan["jet_iterations"] = e.plan.jet_iterations;
  d["plan"] = plan;
  d["file_disagreement"] = e.file_disagreement;
  d["file_normals_used"] = e.file_normals_used;
  d["crease"] = crease_or_none(std::move(e.crease));
  return d;
}

/// Seconds of each of `repeats` runs of the C++ call under focal.curvature, timed in C++: the
/// Python call's overhead is measured against it (bench/python/bench.py).
std::vector<double> estimate_seconds(const DoubleRows& V, const IntRows& F,
                                     const std::optional<DoubleRows>& N, const nb::dict& options,
                                     int repeats) {
  const focal::EstimateOptions o = estimate_options(options);
  std::vector<double> seconds;
  nb::gil_scoped_release release;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const focal::Estimate e = run_estimate(V, F, N, o);
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return seconds;
}

nb::dict focal_mesh_dict(focal::FocalMesh&& m) {
  nb::dict d = mesh_dict(std::move(m.mesh));
  d["flag"] = to_numpy(std::move(m.flag));
  d["kept_faces"] = to_numpy(std::move(m.kept_faces));
  return d;
}

/// focal.focal_meshes: the estimate, then the focal meshes on the normals and faces it used (as
/// `focal focal-mesh` does).
nb::dict focal_meshes(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                      const nb::dict& options, double max_distance, bool drop_faces_at_infinity) {
  const focal::EstimateOptions o = estimate_options(options);
  focal::FocalMeshes meshes;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope(o.execution);
    const focal::PreparedMesh mesh(view(V), view(F), normals_ref(N));
    const focal::Estimate e = focal::estimate(mesh, o);
    const focal::FocalMeshOptions fo{.max_distance = max_distance,
                                     .drop_faces_at_infinity = drop_faces_at_infinity};
    if (e.F) {
      meshes = focal::focal_meshes(focal::PreparedMesh(mesh.V(), *e.F, *e.N), e.curvature, fo);
    } else {
      meshes = focal::focal_meshes(e.N ? mesh.with_normals(*e.N) : mesh, e.curvature, fo);
    }
  }
  nb::dict d;
  d["gamma1"] = focal_mesh_dict(std::move(meshes.gamma1));
  d["gamma2"] = focal_mesh_dict(std::move(meshes.gamma2));
  return d;
}

nb::dict check_mesh(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                    int threads) {
  focal::MeshFindings f;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    f = focal::check_mesh(view(V), view(F), normals_ref(N));
  }
  nb::dict d;
#define FOCAL_FIELD(name) d[#name] = f.name
  FOCAL_FIELD(non_finite_vertex_count);
  FOCAL_FIELD(repeated_index_face_count);
  FOCAL_FIELD(degenerate_face_count);
  FOCAL_FIELD(duplicate_face_count);
  FOCAL_FIELD(unreferenced_vertex_count);
  FOCAL_FIELD(non_manifold_edge_count);
  FOCAL_FIELD(non_manifold_vertex_count);
  FOCAL_FIELD(inconsistent_component_count);
  FOCAL_FIELD(inward_component_count);
  FOCAL_FIELD(non_finite_normal_count);
  FOCAL_FIELD(zero_normal_count);
  FOCAL_FIELD(non_unit_normal_count);
  FOCAL_FIELD(normals_against_faces_count);
  FOCAL_FIELD(normals_compared_count);
  FOCAL_FIELD(inward_normal_component_count);
  FOCAL_FIELD(boundary_edge_count);
  FOCAL_FIELD(component_count);
#undef FOCAL_FIELD
  d["has_problems"] = f.has_problems();
  d["summary"] = f.summary();
  return d;
}

nb::ndarray<nb::numpy, double> vertex_normals(const DoubleRows& V, const IntRows& F,
                                              const std::string& weighting, int threads) {
  const focal::NormalWeighting w = parse_weighting(weighting);
  focal::RowMatrixX3d N;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    N = focal::vertex_normals(view(V), view(F), w);
  }
  return to_numpy(std::move(N));
}

nb::dict read_mesh(const nb::bytes& path_bytes, int threads) {
  const std::string path = path_of(path_bytes);
  focal::Mesh mesh;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    mesh = focal::read_mesh(path);
  }
  return mesh_dict(std::move(mesh));
}

focal::Precision precision_of(bool float32) {
  return float32 ? focal::Precision::float32 : focal::Precision::float64;
}

void write_mesh(const nb::bytes& path_bytes, const DoubleRows& V, const IntRows& F,
                const std::optional<DoubleRows>& N, bool float32) {
  const std::string path = path_of(path_bytes);
  nb::gil_scoped_release release;
  // The writers take a Mesh, which owns its arrays: one copy, made here.
  focal::Mesh mesh;
  mesh.V = view(V);
  mesh.F = view(F);
  if (N) mesh.N = view(*N);
  focal::write_mesh(path, mesh, {.precision = precision_of(float32)});
}

template <class Vector, class Scalar>
Vector vector_of(const nb::handle& a) {
  const auto arr =
      nb::cast<nb::ndarray<const Scalar, nb::ndim<1>, nb::c_contig, nb::device::cpu>>(a);
  return Eigen::Map<const Vector>(arr.data(), static_cast<Eigen::Index>(arr.shape(0)));
}

/// The fields of a focal.Curvature (its arrays, checked by the package) as the library's result.
focal::CurvatureResult curvature_result(const nb::dict& c) {
  focal::CurvatureResult r;
  r.k1 = vector_of<Eigen::VectorXd, double>(c["k1"]);
  r.k2 = vector_of<Eigen::VectorXd, double>(c["k2"]);
  r.H = vector_of<Eigen::VectorXd, double>(c["H"]);
  r.K = vector_of<Eigen::VectorXd, double>(c["K"]);
  r.residual = vector_of<Eigen::VectorXd, double>(c["residual"]);
  r.point_class = vector_of<focal::VectorXu8, std::uint8_t>(c["point_class"]);
  r.rays_used = vector_of<Eigen::VectorXi, std::int32_t>(c["rays_used"]);
  r.rays_excluded = vector_of<Eigen::VectorXi, std::int32_t>(c["rays_excluded"]);
  r.d1 = view(nb::cast<DoubleRows>(c["d1"]));
  r.d2 = view(nb::cast<DoubleRows>(c["d2"]));
  return r;
}

/// focal.write_fields: the files of `focal curvature -o` (.csv, or .ply with the mesh). The
/// writers take owning structs: the arrays are copied once, here.
void write_fields(const nb::bytes& path_bytes, const nb::dict& fields,
                  const std::optional<DoubleRows>& V, const std::optional<IntRows>& F,
                  const std::optional<DoubleRows>& N, bool binary, int threads, bool float32) {
  const std::string path = path_of(path_bytes);
  const focal::CurvatureResult r = curvature_result(fields);
  const focal::VectorXu8 crease = fields.contains("crease")
                                      ? vector_of<focal::VectorXu8, std::uint8_t>(fields["crease"])
                                      : focal::VectorXu8();
  nb::gil_scoped_release release;
  const focal::ExecutionScope scope({.threads = threads});
  if (!V) {
    focal::write_curvature_csv(path, r, crease, {.precision = precision_of(float32)});
    return;
  }
  focal::Mesh mesh;
  mesh.V = view(*V);
  mesh.F = view(*F);
  if (N) mesh.N = view(*N);
  focal::write_curvature_ply(path, mesh, r,
                             {.binary = binary, .comments = {}, .precision = precision_of(float32)},
                             crease);
}

nb::dict generate_surface(const std::string& kind, const std::string& triangulation,
                          int target_vertices, std::uint64_t seed, double a, double b, double c) {
  static const std::pair<const char*, focal::Triangulation> triangulations[] = {
      {"regular", focal::Triangulation::regular}, {"irregular", focal::Triangulation::irregular}};
  focal::SurfaceOptions o;
  o.kind = focal::surface_from_name(kind);
  o.triangulation = parse_enum(triangulation, "triangulation", triangulations);
  o.target_vertices = target_vertices;
  o.seed = seed;
  o.a = a;
  o.b = b;
  o.c = c;
  focal::AnalyticSurface s;
  {
    nb::gil_scoped_release release;
    s = focal::make_surface(o);
  }
  nb::dict d = mesh_dict(std::move(s.mesh));
  d["k1"] = to_numpy(std::move(s.k1));
  d["k2"] = to_numpy(std::move(s.k2));
  d["d1"] = to_numpy(std::move(s.d1));
  d["d2"] = to_numpy(std::move(s.d2));
  d["uv"] = to_numpy(std::move(s.uv));
  return d;
}

}  // namespace

void bind_meshes(nb::module_& m) {
  m.def("default_options", &default_options);
  m.def("curvature", &curvature, "V"_a.noconvert(), "F"_a.noconvert(), "N"_a.none().noconvert(),
        "options"_a);
  m.def("_estimate_seconds", &estimate_seconds, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.none().noconvert(), "options"_a, "repeats"_a);
  m.def("focal_meshes", &focal_meshes, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.none().noconvert(), "options"_a, "max_distance"_a, "drop_faces_at_infinity"_a);
  m.def("check_mesh", &check_mesh, "V"_a.noconvert(), "F"_a.noconvert(), "N"_a.none().noconvert(),
        "threads"_a);
  m.def("vertex_normals", &vertex_normals, "V"_a.noconvert(), "F"_a.noconvert(), "weighting"_a,
        "threads"_a);
  m.def("read_mesh", &read_mesh, "path"_a, "threads"_a);
  m.def("write_mesh", &write_mesh, "path"_a, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.none().noconvert(), "float32"_a);
  m.def("write_fields", &write_fields, "path"_a, "fields"_a, "V"_a.none().noconvert(),
        "F"_a.none().noconvert(), "N"_a.none().noconvert(), "binary"_a, "threads"_a, "float32"_a);
  m.def("generate_surface", &generate_surface, "kind"_a, "triangulation"_a, "target_vertices"_a,
        "seed"_a, "a"_a, "b"_a, "c"_a);
}

}  // namespace focal_python
