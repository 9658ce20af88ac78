#include "focal/curvature.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/cuda/curvature.h"
#include "focal/curvature/baselines.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/tiles/tiles.h"

namespace focal {
namespace {

/// One stage of the call, reported through Execution::progress as it begins and as it ends (on
/// the way out of an exception too, so that a caller's timer always stops).
class StageReport {
 public:
  StageReport(const Execution& execution, std::string name)
      : execution_(execution), name_(std::move(name)) {
    if (execution_.cancel != nullptr && execution_.cancel->load()) {
      throw Cancelled("cancelled before " + name_);
    }
    if (execution_.progress) execution_.progress({name_, 0.0});
  }
  ~StageReport() {
    if (execution_.progress) execution_.progress({name_, 1.0});
  }
  StageReport(const StageReport&) = delete;
  StageReport& operator=(const StageReport&) = delete;

 private:
  const Execution& execution_;
  std::string name_;
};

void warn(const Execution& execution, const std::string& message) {
  if (execution.warning) execution.warning(message);
}

void inform(const Execution& execution, const std::string& message) {
  if (execution.info) execution.info(message);
}

bool is_baseline(Estimator e) { return e != Estimator::recommended && e != Estimator::paper; }

/// The warnings about what the normals stage fixed or suspects.
void report_normals(const NormalsReport& r, const Execution& execution) {
  if (r.reoriented_component_count > 0) {
    warn(execution, std::to_string(r.reoriented_component_count) +
                        " closed component(s) are oriented inward; their faces "
                        "were reversed so that normals point outward");
  }
  if (r.filled_normal_count > 0) {
    warn(execution, std::to_string(r.filled_normal_count) +
                        " vertices have no usable normal in the file; estimated them from the "
                        "faces");
  }
  if (r.rescaled_normal_count > 0) {
    warn(execution,
         std::to_string(r.rescaled_normal_count) + " normals were not of unit length; normalised");
  }
  if (r.normals_against_faces) {
    warn(execution,
         "most file normals point against the face orientation (inward?); curvature signs "
         "follow the normals");
  }
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

/// The recommended estimator's decisions: a warning when it ignored the file's normals, and its
/// plan as information.
void report_recommended(bool has_normals, const Estimate& e, const Execution& execution) {
  if (has_normals && !e.file_normals_used) {
    warn(execution, "the file's normals disagree with the positions (median angle " +
                        std::to_string(e.file_disagreement) +
                        " rad to jet normals): using normals estimated from the positions on "
                        "the file normals' side");
  }
  std::ostringstream plan;
  plan << "  recommended estimator: " << normals_used(e);
  if (std::isnan(e.plan.noise) && std::isnan(e.plan.position_noise)) {
    // No vertex had a jet (every one over the neighbourhood cap, or too few neighbours).
    plan << ", no jet fitted (noise unknown: the 1-ring plan)";
  } else {
    plan << ", jet residual " << e.plan.noise << ", position noise " << e.plan.position_noise
         << " x edge length";
  }
  plan << ", " << e.plan.rings
       << "-ring " << (e.plan.gaussian ? "Gaussian-weighted " : "") << "fit";
  inform(execution, plan.str());
}

std::int64_t undefined_count(const CurvatureResult& r) {
  return std::count(r.point_class.begin(), r.point_class.end(),
                    static_cast<std::uint8_t>(PointClass::undefined));
}

/// The widest neighbourhood, in rings, that the estimate gathered; 1 when it used 1-rings only.
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

/// Whether every vertex is a corner of at most one triangle (a soup of unwelded triangles, as
/// an OBJ or PLY exporter writes without shared vertices): no vertex has a neighbour's ray.
bool shares_no_vertex(const PreparedMesh& mesh) {
  std::vector<char> used(static_cast<std::size_t>(mesh.vertex_count()), 0);
  const auto F = mesh.F();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      char& u = used[static_cast<std::size_t>(F(f, c))];
      if (u != 0 && F(f, c) != F(f, (c + 2) % 3) && F(f, c) != F(f, (c + 1) % 3)) return false;
      u = 1;
    }
  }
  return F.rows() > 1;  // one triangle alone is no soup
}

/// Counts the vertices without an estimate and, where that can explain them, those over the
/// neighbourhood cap, and warns about both.
void count_undefined(const PreparedMesh& mesh, const EstimateOptions& o, Estimate& e) {
  e.undefined_count = undefined_count(e.curvature);
  const int rings = widest_rings(o, e);
  // Crowded vertices lose their jets: without a 2-ring fit they are undefined (or, on the
  // recommended estimator's 1-ring path, fitted on Max's normals), so a run without undefined
  // vertices has none to report.
  const bool lost_jets = o.estimator == Estimator::recommended && e.plan.rings == 1;
  if (rings > 1 && (e.undefined_count > 0 || lost_jets) && may_be_crowded(mesh, rings)) {
    e.crowded_count = static_cast<std::int64_t>(
        crowded_vertices(vertex_adjacency(static_cast<int>(mesh.vertex_count()), mesh.F()), rings)
            .size());
    e.crowded_rings = rings;
  }
  const Execution& execution = current_execution();
  if (e.crowded_count > 0) {
    warn(execution, std::to_string(e.crowded_count) + " vertices have more than " +
                        std::to_string(kMaxNeighbourhoodSize) + " vertices within " +
                        std::to_string(rings) +
                        " rings (a polygon of thousands of corners, or an edge of thousands of "
                        "faces?): " +
                        (lost_jets ? "their fit uses their 1-ring and Max's normals only, no jets"
                                   : "left undefined"));
  }
  const auto n = static_cast<std::int64_t>(e.curvature.point_class.size());
  if (e.undefined_count > 0 && e.undefined_count == n) {
    warn(execution, "every vertex is undefined (" + std::to_string(e.undefined_count) + ")" +
                        (e.crowded_count > 0 ? ""
                         : shares_no_vertex(mesh)
                             ? ": no two triangles share a vertex (a triangle soup: each "
                               "triangle has corners of its own; weld equal positions into one "
                               "vertex, e.g. write it as STL and read it back)"
                             : ": no vertex has two neighbour rays to fit (a mesh this coarse, "
                               "with neighbouring normals 90 degrees or more apart, has none)"));
  }
}

CurvatureResult run_baseline(const PreparedMesh& mesh, const EstimateOptions& o) {
  switch (o.estimator) {
    case Estimator::meyer_2003:
      return baselines::meyer_2003(mesh.V(), mesh.F(), o.paper);
    case Estimator::cohen_steiner_morvan_2003:
      return baselines::cohen_steiner_morvan_2003(mesh.V(), mesh.F(), o.paper);
    case Estimator::lachaud_2020:
      return baselines::lachaud_2020(mesh.V(), mesh.F(), mesh.normals(), {}, o.paper);
    case Estimator::yang_2006:
      return baselines::yang_2006(mesh.V(), mesh.F(), {}, o.paper);
    case Estimator::grinspun_2006:
      return baselines::grinspun_2006(mesh.V(), mesh.F(), o.paper);
    default:
      throw InvalidInput("curvature: not a baseline estimator");
  }
}

void require_cpu_only(const EstimateOptions& o, const char* what) {
  if (o.device != Device::cpu) {
    throw InvalidInput(std::string("curvature: Device::cuda does not run ") + what);
  }
}

/// The paper's estimator on the device: its per-vertex fit of the prepared normals.
Estimate device_estimate(const PreparedMesh& mesh, PreparedNormals normals,
                         const EstimateOptions& o) {
  if (o.estimator != Estimator::paper || o.paper.method != Method::vertex) {
    throw InvalidInput(
        "curvature: Device::cuda runs the paper's per-vertex fit (Estimator::paper, "
        "Method::vertex)");
  }
  Estimate e;
  e.normals_report = normals.report;
  const FacesRef F = normals.F ? FacesRef(*normals.F) : mesh.F();
  if (normals.N) {
    e.curvature = estimate_curvature_cuda(mesh.V(), F, *normals.N, o.paper);
  } else {
    e.curvature = estimate_curvature_cuda(mesh.V(), F, mesh.N(), o.paper);
  }
  e.N = std::move(normals.N);
  e.F = std::move(normals.F);
  return e;
}

Estimate mesh_curvature(const PreparedMesh& mesh, const EstimateOptions& o) {
  const Execution& execution = current_execution();
  if (is_baseline(o.estimator)) {
    require_cpu_only(o, "the baselines");
    if (o.tile_vertices > 0) throw InvalidInput("curvature: the baselines do not run in tiles");
    Estimate e;
    {
      StageReport stage(execution, "curvature");
      e.curvature = run_baseline(mesh, o);
    }
    e.undefined_count = undefined_count(e.curvature);
    return e;
  }
  if (o.normals == NormalsSource::file && !mesh.has_normals()) {
    throw InvalidInput("curvature: NormalsSource::file, but the mesh has no vertex normals");
  }
  if (o.tile_vertices > 0) {
    require_cpu_only(o, "in tiles");
    Estimate e;
    {
      StageReport stage(execution,
                        "curvature in tiles of " + std::to_string(o.tile_vertices) + " vertices");
      TileEstimate t = estimate_tiled(mesh, o, {.tile_vertices = o.tile_vertices});
      e.curvature = std::move(t.curvature);
      e.crease = std::move(t.crease);
    }
    e.undefined_count = undefined_count(e.curvature);
    return e;
  }
  PreparedNormals normals;
  {
    StageReport stage(execution, "normals");
    normals = prepare_normals(mesh, o);
    report_normals(normals.report, execution);
  }
  Estimate e;
  {
    StageReport stage(execution, "curvature");
    e = o.device == Device::cuda ? device_estimate(mesh, std::move(normals), o)
                                 : estimate(mesh, std::move(normals), o);
  }
  if (o.estimator == Estimator::recommended) report_recommended(mesh.has_normals(), e, execution);
  count_undefined(mesh, o, e);
  return e;
}

void require_cloud_options(const EstimateOptions& o) {
  if (is_baseline(o.estimator)) {
    throw InvalidInput("curvature: the baselines need faces; the input is a point cloud");
  }
  require_cpu_only(o, "point clouds");
  if (o.normals != NormalsSource::automatic && o.normals != NormalsSource::file) {
    throw InvalidInput(
        "curvature: normals from the faces were asked for; the input is a point cloud");
  }
  if (o.normals == NormalsSource::file) {
    throw InvalidInput(
        "curvature: NormalsSource::file applies to meshes; a point cloud's own "
        "normals are used whenever it has them");
  }
}

Estimate cloud_curvature(const PreparedMesh& cloud, const EstimateOptions& o) {
  require_cloud_options(o);
  const Execution& execution = current_execution();
  Estimate e;
  if (o.tile_vertices > 0) {
    {
      StageReport stage(
          execution, "cloud curvature in tiles of " + std::to_string(o.tile_vertices) + " points");
      TileEstimate t = estimate_cloud_tiled(cloud.V(), cloud.normals(), o.cloud,
                                            {.tile_vertices = o.tile_vertices});
      e.curvature = std::move(t.curvature);
    }
    e.undefined_count = undefined_count(e.curvature);
    return e;
  }
  CloudOptions options = o.cloud;
  // The front door returns no neighbour lists: not taken back, not held after the fit.
  options.keep_neighbours = false;
  CloudCurvature c;
  {
    StageReport stage(execution, "cloud curvature");
    c = estimate_cloud_curvature(cloud.V(), cloud.normals(), options);
  }
  inform(execution, std::string("  normals: ") +
                        (c.normals_estimated ? "estimated from the positions" : "the file's") +
                        "; mean spacing " + std::to_string(c.spacing));
  e.curvature = std::move(c.curvature);
  e.undefined_count = undefined_count(e.curvature);
  const auto n = static_cast<std::int64_t>(e.curvature.point_class.size());
  if (n > 0 && e.undefined_count == n) {
    warn(execution, "every point is undefined (" + std::to_string(n) +
                        "): no point has two neighbours apart from it with normals to fit "
                        "(fewer than 3 distinct points, or points along a line, span no "
                        "surface)");
  }
  e.N = std::move(c.N);
  e.file_normals_used = c.file_normals_used;
  e.cloud = CloudPlan{.normals_estimated = c.normals_estimated,
                      .spacing = c.spacing,
                      .noise = c.noise,
                      .k = c.k,
                      .corrected = c.corrected,
                      .outlier = std::move(c.outlier)};
  return e;
}

}  // namespace

Estimate curvature(const PreparedMesh& input, const EstimateOptions& options) {
  // Every step below, and every loop they start, runs with the options' execution.
  const ExecutionScope scope(options.execution);
  if (options.tile_vertices < 0) throw InvalidInput("curvature: tile_vertices must be >= 0");
  if (input.face_count() == 0) return cloud_curvature(input, options);
  return mesh_curvature(input, options);
}

Estimate curvature(const Mesh& input, const EstimateOptions& options) {
  const ExecutionScope scope(options.execution);
  const PreparedMesh prepared(input.V, input.F, input.normals());
  return curvature(prepared, options);
}

}  // namespace focal
