#include "input_check.h"

#include <cmath>

#include "focal/core/error.h"
#include "focal/mesh/check.h"

namespace focal::cli {

MeshFindings check_input(const PreparedMesh& mesh, const std::string& mesh_name, bool strict,
                         const Log& log) {
  Stage stage(log, "check");
  const MeshFindings findings = check_mesh(mesh);
  log.info("  " + std::to_string(findings.component_count) + " component(s), " +
           std::to_string(findings.boundary_edge_count) + " boundary edge(s)");
  if (!findings.has_problems()) return findings;
  if (strict) throw InvalidInput(mesh_name + ": --strict: " + findings.summary());
  log.warning(mesh_name + ": found " + findings.summary() + " (--strict rejects such input)");
  return findings;
}

void check_cloud(const Mesh& cloud, const std::string& cloud_name, bool strict, const Log& log) {
  int bad_points = 0, bad_normals = 0;
  for (Eigen::Index i = 0; i < cloud.V.rows(); ++i) {
    bad_points += cloud.V.row(i).allFinite() ? 0 : 1;
    if (cloud.has_normals()) {
      const double length = cloud.N.row(i).norm();
      bad_normals += std::isfinite(length) && length > 0.0 ? 0 : 1;
    }
  }
  log.info("  point cloud, " + std::string(cloud.has_normals() ? "with" : "without") + " normals");
  if (bad_points == 0 && bad_normals == 0) return;
  const std::string summary = std::to_string(bad_points) + " non-finite points, " +
                              std::to_string(bad_normals) + " zero or non-finite normals";
  if (strict) throw InvalidInput(cloud_name + ": --strict: " + summary);
  log.warning(cloud_name + ": found " + summary + " (--strict rejects such input)");
}

}  // namespace focal::cli
