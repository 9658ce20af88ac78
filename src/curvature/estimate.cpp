#include "focal/curvature/estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/mesh/check.h"
#include "focal/mesh/orientation.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/prepared_access.h"

namespace focal {
namespace {

/// Normals from the faces when the mesh's are not used: Max's weights are exact for vertices on
/// a sphere and second-order accurate on smooth surfaces, also on irregular meshes.
constexpr NormalWeighting kDefaultWeighting = NormalWeighting::max;

/// |n| - 1 beyond which a mesh normal is normalised (check_mesh counts the same rows).
constexpr double kUnitTolerance = 1e-6;

bool uses_mesh_normals(const PreparedMesh& mesh, NormalsSource source) {
  return source == NormalsSource::file ||
         (source == NormalsSource::automatic && mesh.has_normals());
}

/// The mesh's normals with zero or non-finite rows filled from the faces and the others made
/// unit, into `out`; a copy only when some row needs it (the findings say whether).
void fix_mesh_normals(const PreparedMesh& mesh, const MeshFindings& findings,
                      PreparedNormals& out) {
  if (findings.non_finite_normal_count + findings.zero_normal_count +
          findings.non_unit_normal_count ==
      0) {
    return;
  }
  RowMatrixX3d N = mesh.N();
  std::vector<Eigen::Index> missing;
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double len = N.row(i).norm();
    if (!std::isfinite(len) || len == 0.0) missing.push_back(i);
  }
  if (!missing.empty()) {
    const RowMatrixX3d estimated = vertex_normals(mesh, kDefaultWeighting);
    for (const Eigen::Index i : missing) N.row(i) = estimated.row(i);
    out.report.filled_normal_count = static_cast<int>(missing.size());
  }
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double len = N.row(i).norm();
    if (std::isfinite(len) && len > 0.0 && std::abs(len - 1.0) > kUnitTolerance) {
      N.row(i) /= len;
      ++out.report.rescaled_normal_count;
    }
  }
  out.N = std::move(N);
}

/// F with the faces of inward closed components reversed, into `out` when there are some. The
/// findings, when the mesh has them, say whether there are any without another topology pass.
void orient_faces_outward(const PreparedMesh& mesh, PreparedNormals& out) {
  if (detail::PreparedAccess::has_findings(mesh) && check_mesh(mesh).inward_component_count == 0) {
    return;
  }
  const OrientationReport report = orientation_report(mesh);
  out.report.reoriented_component_count = report.inward_count();
  if (out.report.reoriented_component_count > 0) out.F = orient_outward(mesh.F(), report);
}

NormalWeighting weighting_of(NormalsSource source) {
  switch (source) {
    case NormalsSource::area:
      return NormalWeighting::area;
    case NormalsSource::angle:
      return NormalWeighting::angle;
    default:
      return kDefaultWeighting;
  }
}

/// The mesh the estimator runs on: the prepared faces and normals, sharing what `mesh` has built
/// when the faces are its own.
PreparedMesh mesh_to_fit(const PreparedMesh& mesh, const PreparedNormals& normals) {
  const std::optional<NormalsRef> N =
      normals.N ? std::optional<NormalsRef>(*normals.N) : mesh.normals();
  if (!normals.F) return normals.N ? mesh.with_normals(N) : mesh;
  // Reversed faces have the same corners: F was valid, so are they.
  return detail::PreparedAccess::make(mesh.V(), *normals.F, N, {}, "estimate");
}

/// The paper's estimator. The per-vertex fit gets the 1-ring, then the incidence is freed: the
/// fit is the peak of a run and needs only the 1-ring (estimate_curvature would keep both).
CurvatureResult run_paper(const PreparedMesh& mesh, const CurvatureOptions& options) {
  if (options.method == Method::triangle) return estimate_curvature(mesh, options);
  detail::validate_curvature_options(options);
  const std::shared_ptr<const Neighbourhoods> one_ring = detail::one_ring(mesh);
  detail::PreparedAccess::release_incidence(mesh);
  return detail::vertex_curvature_from_rays(mesh, *one_ring, options);
}

}  // namespace

PreparedNormals prepare_normals(const PreparedMesh& mesh, const EstimateOptions& options) {
  const NormalsSource source = options.normals;
  if (source == NormalsSource::file && !mesh.has_normals()) {
    throw InvalidInput("prepare_normals: NormalsSource::file, but the mesh has no normals");
  }
  const bool recommended = options.estimator == Estimator::recommended;
  if (recommended && source != NormalsSource::automatic && source != NormalsSource::file) {
    throw InvalidInput(
        "prepare_normals: the recommended estimator takes the mesh's normals or none "
        "(NormalsSource::automatic or file); it estimates its own from the positions");
  }
  PreparedNormals out;
  if (uses_mesh_normals(mesh, source)) {
    const MeshFindings& findings = check_mesh(mesh);
    fix_mesh_normals(mesh, findings, out);
    // The count covers the rows as given: the filled rows follow the faces, and rescaling does
    // not change a sign.
    out.report.normals_against_faces =
        2 * findings.normals_against_faces_count > findings.normals_compared_count;
    return out;
  }
  // Normals from the faces (or, for the recommended estimator, from the positions later) take
  // their side from the faces.
  if (options.orient_faces) orient_faces_outward(mesh, out);
  if (!recommended) {
    const PreparedMesh faces = mesh_to_fit(mesh.with_normals(std::nullopt), out);
    out.N = vertex_normals(faces, weighting_of(source));
  }
  return out;
}

Estimate estimate(const PreparedMesh& mesh, PreparedNormals normals,
                  const EstimateOptions& options) {
  Estimate out;
  out.normals_report = normals.report;
  {
    // Recommended without mesh normals: none here either, whatever the mesh's (prepare_normals
    // would have used them).
    const PreparedMesh fit = mesh_to_fit(mesh, normals);
    if (options.estimator == Estimator::recommended) {
      RecommendedResult r = estimate_curvature_recommended(fit, options.recommended);
      out.curvature = std::move(r.curvature);
      out.N = std::move(r.N);
      out.plan = r.plan;
      out.file_disagreement = r.file_disagreement;
      out.file_normals_used = r.file_normals_used;
      out.crease = r.crease.size() == fit.vertex_count()
                       ? std::move(r.crease)
                       : VectorXu8(VectorXu8::Zero(fit.vertex_count()));
    } else {
      out.curvature = run_paper(fit, options.paper);
    }
    // (The recommended estimator does this itself.)
    if (options.estimator == Estimator::paper && !uses_mesh_normals(mesh, options.normals)) {
      detail::undefine_isolated_triangles(fit.F(), out.curvature);
    }
  }
  if (options.estimator == Estimator::paper && normals.N) out.N = std::move(normals.N);
  out.F = std::move(normals.F);
  return out;
}

Estimate estimate(const PreparedMesh& mesh, const EstimateOptions& options) {
  return estimate(mesh, prepare_normals(mesh, options), options);
}

int estimate_reach(const EstimateOptions& options) {
  if (options.estimator == Estimator::recommended) {
    // Without the mesh's choices, the bound of every plan's reach.
    if (!options.recommended.mesh_wide) return kRecommendedMaxReach;
    return recommended_reach(recommended_plan_for_noise(
        options.recommended.mesh_wide->position_noise, options.recommended));
  }
  // The corners of a vertex's faces, whose normals read their own faces.
  if (options.paper.method == Method::triangle) return 2;
  return options.paper.rings + 1;
}

MeshWideChoices mesh_wide_choices(const PreparedMesh& mesh, const EstimateOptions& options) {
  // The normals the whole estimate would fit are needed only where they decide something
  // mesh-wide: the file's (filled, made unit) for the recommended estimator's comparison. Each
  // tile prepares its own from its rows (the fixes are per row).
  PreparedNormals prepared;
  if (uses_mesh_normals(mesh, options.normals)) {
    if (options.estimator == Estimator::recommended) prepared = prepare_normals(mesh, options);
  } else if (options.orient_faces) {
    orient_faces_outward(mesh, prepared);
  }
  MeshWideChoices out;
  {
    const PreparedMesh fit = mesh_to_fit(mesh, prepared);
    out.mean_edge_length = fit.mean_edge_length();
    if (options.estimator == Estimator::recommended) {
      out.recommended = recommended_mesh_wide(fit, options.recommended);
    }
  }
  out.F = std::move(prepared.F);
  return out;
}

EstimateOptions options_for_part(const EstimateOptions& options, const MeshWideChoices& choices) {
  EstimateOptions out = options;
  out.orient_faces = false;
  out.recommended.mesh_wide = choices.recommended;
  return out;
}

}  // namespace focal
