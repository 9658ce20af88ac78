#pragma once
/// \file focal_mesh.h
/// The two focal meshes of the paper, section 3 and Fig. 1: Gamma_j = S - N / k_j (eq. 2), with
/// the connectivity of the base mesh.

#include "focal/curvature/curvature.h"
#include "focal/core/mesh.h"

namespace focal {

struct FocalMeshOptions {
  /// Focal points farther than this from their base vertex are "at infinity": their distance is
  /// clamped to it. 0 = 10 x the bounding-box diagonal of the base mesh.
  double max_distance = 0.0;
  /// Leave out faces with a vertex at infinity (or undefined) instead of keeping them clamped.
  bool drop_faces_at_infinity = false;
};

/// Per-vertex focal-point flags, written with the meshes.
enum class FocalPointFlag : std::uint8_t {
  finite = 0,     ///< Gamma = S - N / k
  infinite = 1,   ///< |k| too small: clamped to max_distance along -sign(k) N (or +N if k = 0)
  undefined = 2,  ///< no curvature at the vertex: the point is the base vertex itself
};

struct FocalMesh {
  Mesh mesh;              ///< focal points (#V rows, input order) and the kept faces
  VectorXu8 flag;         ///< #V FocalPointFlag codes
  Eigen::VectorXi kept_faces;  ///< indices into the base F of the faces kept
};

struct FocalMeshes {
  FocalMesh gamma1;  ///< the focal mesh of k1 (its face normals approximate d1, paper Property 2)
  FocalMesh gamma2;  ///< the focal mesh of k2
};

/// Builds both focal meshes from the base mesh, its normals and its curvature fields.
/// \throw InvalidInput when the shapes of the arguments differ.
[[nodiscard]] FocalMeshes focal_meshes(PositionsRef V, FacesRef F, NormalsRef N,
                                       const CurvatureResult& curvature,
                                       const FocalMeshOptions& options = {});

}  // namespace focal
