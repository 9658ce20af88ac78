#pragma once
// The findings summary of `focal curvature` and `focal focal-mesh`: one `Warning:` line that
// counts what is wrong with the input mesh, or with --strict an error before any work.

#include <string>

#include "focal/core/mesh.h"
#include "focal/mesh/check.h"
#include "focal/mesh/prepared.h"
#include "log.h"

namespace focal::cli {

/// Checks the mesh (with the normals the run will use, when it has them: not when they are
/// estimated from the faces) and prints "Warning: <file>: <counts>" when anything was found.
/// Returns the findings, which the mesh keeps for the normals stage (orientation, the normals'
/// direction).
/// \throw InvalidInput naming the file and the counts when `strict` and anything was found.
MeshFindings check_input(const PreparedMesh& mesh, const std::string& mesh_name, bool strict,
                         const Log& log);

/// The same for a point cloud: counts points with a NaN or infinite coordinate and normals that
/// are zero or not finite (those points get no curvature). \throw as check_input.
void check_cloud(const Mesh& cloud, const std::string& cloud_name, bool strict, const Log& log);

}  // namespace focal::cli
