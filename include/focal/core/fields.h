#pragma once
/// \file fields.h
/// The results of focal: per-vertex curvature fields with their classes, and focal meshes.
/// Plain data, written by the estimators (curvature/), read by the writers (io/), the renderer
/// and the bindings.
///
/// Conventions: outward normals; curvature positive where the surface bends away from the normal
/// (sphere of radius r: k1 = k2 = +1/r); d1 belongs to k1; d1, d2 are unit 3D vectors tangent to
/// the vertex normal, and (d1, d2, N) is right-handed.

#include <Eigen/Core>
#include <cstdint>

#include "focal/core/mesh.h"
#include "focal/core/point_class.h"

namespace focal {

/// Per-vertex fields, #V rows each, row i for input vertex i. Vertices of class `undefined`
/// have NaN in every numeric field (never zeros).
struct CurvatureResult {
  Eigen::VectorXd k1;  ///< larger principal curvature
  Eigen::VectorXd k2;  ///< smaller principal curvature
  Eigen::VectorXd H;   ///< mean curvature (k1 + k2) / 2
  Eigen::VectorXd K;   ///< Gaussian curvature k1 k2
  RowMatrixX3d d1;     ///< unit principal direction of k1
  RowMatrixX3d d2;     ///< unit principal direction of k2
  /// Root-mean-square residual of the fit, sqrt(E / sum of weights), in units of slope
  /// (per-vertex method) or the spread of the incident faces' estimates (triangle method).
  Eigen::VectorXd residual;
  VectorXu8 point_class;        ///< PointClass codes
  Eigen::VectorXi rays_used;     ///< neighbour rays that entered the fit
  Eigen::VectorXi rays_excluded; ///< neighbours whose normal left the vertex normal's hemisphere

  [[nodiscard]] PointClass class_of(int i) const { return static_cast<PointClass>(point_class[i]); }
};

/// The focal meshes (curvature/focal_mesh.h builds them, paper section 3).
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

}  // namespace focal
