#pragma once
/// \file fields_io.h
/// Files of curvature fields and focal meshes, in the layouts the `focal` command writes.

#include <filesystem>

#include "focal/core/fields.h"
#include "focal/io/mesh_io.h"

namespace focal {

/// Column names of the per-vertex fields, in file order:
/// k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,residual,class.
[[nodiscard]] const std::vector<std::string>& curvature_field_names();

/// One CSV row per vertex, in input order; class as a word, NaN as `nan`. With `crease` (#V
/// flags, Estimate::crease) a last column `crease` of 0 and 1; empty: no such column. The rows
/// are formatted in parallel, the same bytes for any thread count.
/// \throw InvalidInput when `crease` is neither empty nor of the fields' length.
void write_curvature_csv(const std::filesystem::path& path, const CurvatureResult& fields,
                         const VectorXu8& crease = {});
/// write_curvature_csv with the options' precision (Precision::float32: each number
/// as the shortest text of the float nearest to it; `nan` stays `nan`, class words and crease
/// flags are unchanged).
void write_curvature_csv(const std::filesystem::path& path, const CurvatureResult& fields,
                         const VectorXu8& crease, const WriteOptions& options);

/// The mesh with the fields as per-vertex PLY properties (floats; class as a uchar whose codes
/// are listed in a header comment), so MeshLab and ParaView can colour by them; with `crease`
/// (as above) a last uchar property `crease`. Positions and normals are doubles, or floats with
/// PlyWriteOptions::precision = Precision::float32.
void write_curvature_ply(const std::filesystem::path& path, const Mesh& mesh,
                         const CurvatureResult& fields, const PlyWriteOptions& options = {},
                         const VectorXu8& crease = {});

/// A focal mesh with its per-vertex `focal_flag` (uchar; codes listed in a header comment); the
/// focal points as doubles, or floats with Precision::float32 (the flags are the same).
void write_focal_mesh_ply(const std::filesystem::path& path, const FocalMesh& focal,
                          const PlyWriteOptions& options = {});

/// Both focal meshes (write_focal_mesh_ply) as `path1` (Gamma_1) and `path2` (Gamma_2), all or
/// nothing: either both new files are in place or both paths are as they were (an existing file
/// keeps its contents, a missing one stays missing).
/// \throw IoError naming the path that failed.
void write_focal_meshes_ply(const std::filesystem::path& path1, const std::filesystem::path& path2,
                            const FocalMeshes& meshes, const PlyWriteOptions& options = {});

}  // namespace focal
