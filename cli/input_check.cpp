#include "input_check.h"

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

}  // namespace focal::cli
