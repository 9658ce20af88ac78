#pragma once
/// \file mesh.h
/// The mesh model of focal: an indexed triangle mesh as plain row-major arrays.
/// Conventions used throughout the library:
///  - `V` is `#V x 3` vertex positions, `F` is `#F x 3` vertex indices (0-based) of triangles,
///    `N` is `#V x 3` unit vertex normals.
///  - Normals point outward; triangles are counter-clockwise seen from outside.
///  - Curvature is positive where the surface bends away from the normal: a sphere of radius r
///    with outward normals has k1 = k2 = +1/r.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace focal {

/// `n x 3` row-major doubles (positions, normals, directions); numpy's default layout.
using RowMatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// `m x 3` row-major 32-bit indices (triangles).
using RowMatrixX3i = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// Per-element small codes (classes, flags).
using VectorXu8 = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 1>;

/// Read-only views accepted by the API, so that numpy arrays and mapped buffers pass without
/// copies.
using PositionsRef = Eigen::Ref<const RowMatrixX3d>;
using FacesRef = Eigen::Ref<const RowMatrixX3i>;
using NormalsRef = Eigen::Ref<const RowMatrixX3d>;

/// An indexed triangle mesh. Vertex order and count are exactly those of the file it was read
/// from: row i of any per-vertex result belongs to input vertex i.
struct Mesh {
  RowMatrixX3d V;  ///< #V x 3 positions.
  RowMatrixX3i F;  ///< #F x 3 triangles (polygons of the input are fan-triangulated).
  RowMatrixX3d N;  ///< #V x 3 vertex normals as read, or 0 rows when the input had none.
  /// #F: index of the input polygon each triangle came from (identity for triangle input).
  Eigen::VectorXi face_source;
  /// STL only (read_mesh welds its unshared facet corners, ReadOptions): for every corner in file
  /// order (facet 0's corners, then facet 1's, ...), the row of V it became. Empty for indexed
  /// formats, whose vertices are the file's.
  Eigen::VectorXi corner_vertex;

  /// A point cloud: vertices without faces (the cloud functions of points/, normals/ and
  /// curvature/cloud_curvature.h take it).
  [[nodiscard]] bool is_cloud() const { return F.rows() == 0 && V.rows() > 0; }
  [[nodiscard]] bool has_normals() const { return N.rows() == V.rows() && V.rows() > 0; }
  /// N as the functions taking optional normals want it: std::nullopt when N has 0 rows.
  [[nodiscard]] std::optional<NormalsRef> normals() const {
    if (N.rows() == 0) return std::nullopt;
    return NormalsRef(N);
  }
};

/// Throws InvalidInput unless F indexes V (every index in [0, #V)) and, when N is non-empty,
/// N has #V rows. `what` names the caller in the message. Checked in parallel.
void validate_mesh_arrays(PositionsRef V, FacesRef F, NormalsRef N, const char* what);

/// Mean length of the triangle edges (each undirected edge once per incident face). Edges with a
/// NaN or infinite length are left out; 0 when no edge is left. Summed in parallel, with the same
/// result for any thread count.
[[nodiscard]] double mean_edge_length(PositionsRef V, FacesRef F);

/// Length of the diagonal of the axis-aligned bounding box of the rows of V whose coordinates are
/// all finite; 0 when there are none.
[[nodiscard]] double bounding_box_diagonal(PositionsRef V);

}  // namespace focal
