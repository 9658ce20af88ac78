#pragma once
/// \file triangle_curvature.h
/// The normal-ray characteristic equation per triangle (paper sections 4.2-4.3, eqs. 5-9, and
/// the per-triangle estimate of section 5.1).
///
/// The three vertex rays r, r + r_x, r + r_y of a triangle, in a frame of the triangle's mean
/// normal, focus where A l^2 + B l + C = 0 with
///     A = s_x t_y - s_y t_x,  B = s_x v_y - s_y v_x - t_x u_y + t_y u_x,  C = u_x v_y - u_y v_x,
/// K = A / C and 2H = B / C. Equivalently, with X = [u_x u_y; v_x v_y] and G = [s_x s_y; t_x t_y],
/// M = G X^-1 is a discrete shape operator whose eigenvalues are the principal curvatures.
/// The roots l_j = -1 / k_j are the focal depths; the slit at depth l_j runs along
/// (u_x + l_j s_x, v_x + l_j t_x) (Appendix B, eq. 18).

#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"

namespace focal {

/// Per-face results, #F rows each, in the frame-free form (3D directions).
struct TriangleCurvatureResult {
  Eigen::VectorXd A, B, C;  ///< characteristic-equation coefficients (eq. 7), frame of the face
  Eigen::VectorXd K;        ///< Gaussian curvature A / C
  Eigen::VectorXd H;        ///< mean curvature B / (2 C)
  Eigen::VectorXd k1, k2;   ///< principal curvatures (eigenvalues of the symmetrised M), k1 >= k2
  Eigen::VectorXd lambda1;  ///< focal depth -1 / k1 along the face normal (inf where k1 = 0)
  Eigen::VectorXd lambda2;  ///< focal depth -1 / k2
  RowMatrixX3d d1, d2;      ///< unit principal directions (d1 of k1), tangent to the face normal
  RowMatrixX3d slit1,
      slit2;  ///< unit slit directions at depths lambda1 and lambda2 (slit1 is along d2)
  RowMatrixX3d face_normal;  ///< the unit mean of the three vertex normals (the frame's z axis)
  /// 2x2 shape operator M = G X^-1 in the face frame, row-major (m00, m01, m10, m11) per face.
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> shape_operator;
  VectorXu8 point_class;  ///< PointClass codes from A, B and the discriminant
};

/// Which fields of TriangleCurvatureResult triangle_curvature fills. A field not asked for is
/// left with 0 rows and its computation is skipped where no asked field needs it (the slits are
/// the costliest); point_class is always filled. Every field is asked for by default.
struct TriangleFields {
  bool coefficients = true;    ///< A, B, C
  bool curvatures = true;      ///< K, H, k1, k2
  bool focal_depths = true;    ///< lambda1, lambda2
  bool directions = true;      ///< d1, d2
  bool slits = true;           ///< slit1, slit2
  bool face_normal = true;     ///< face_normal
  bool shape_operator = true;  ///< shape_operator
};

/// Solves the characteristic equation on every face of a mesh with normals, filling `fields`
/// (the same values in the fields it fills). Faces with zero area in the ray frame (C = 0), a
/// vertex normal outside the face normal's hemisphere or non-finite input are `undefined` with
/// NaN values. Each face's row is written once, by the thread that computes it. Reads
/// options.tolerances.
/// \throw InvalidInput when the mesh has no normals.
[[nodiscard]] TriangleCurvatureResult triangle_curvature(const PreparedMesh& mesh,
                                                         const CurvatureOptions& options = {},
                                                         const TriangleFields& fields = {});

/// triangle_curvature of the arrays, every field.
/// \throw InvalidInput when shapes differ or F indexes outside V.
[[nodiscard]] TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                                         const CurvatureOptions& options = {});

/// triangle_curvature of the arrays filling only `fields`.
[[nodiscard]] TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                                         const CurvatureOptions& options,
                                                         const TriangleFields& fields);

}  // namespace focal
