#pragma once
/// \file focal_mesh.h
/// The two focal meshes of the paper, section 3 and Fig. 1: Gamma_j = S - N / k_j (eq. 2), with
/// the connectivity of the base mesh.

#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/mesh/prepared.h"

namespace focal {

struct FocalMeshOptions {
  /// Focal points farther than this from their base vertex are "at infinity": their distance is
  /// clamped to it. 0 = 10 x the bounding-box diagonal of the base mesh.
  double max_distance = 0.0;
  /// Leave out faces with a vertex at infinity (or undefined) instead of keeping them clamped.
  bool drop_faces_at_infinity = false;
};

/// Builds both focal meshes from the base mesh, its normals (made unit) and its curvature fields.
/// \throw InvalidInput when the mesh has no normals, the fields do not have #V rows or
/// max_distance < 0.
[[nodiscard]] FocalMeshes focal_meshes(const PreparedMesh& mesh, const CurvatureResult& curvature,
                                       const FocalMeshOptions& options = {});

/// focal_meshes of the arrays. \throw InvalidInput also when F indexes outside V or N does not
/// have #V rows.
[[nodiscard]] FocalMeshes focal_meshes(PositionsRef V, FacesRef F, NormalsRef N,
                                       const CurvatureResult& curvature,
                                       const FocalMeshOptions& options = {});

}  // namespace focal
