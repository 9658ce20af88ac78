#pragma once
/// \file mesh_io.h
/// Reading and writing meshes and per-vertex tables.
///
/// Readers: OBJ, PLY (ascii, binary little and big endian), OFF, STL (ascii and binary).
/// Vertex order and count of indexed formats (OBJ, PLY, OFF) are preserved exactly; polygons are
/// fan-triangulated and Mesh::face_source maps each triangle to its input polygon. STL has no
/// shared vertices: each facet's corners are three new vertices, in file order (nothing is merged).
/// Writers go through a temporary file in the destination folder that is renamed at the end, so
/// a failed write never leaves a half-written file behind.

#include <filesystem>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "focal/mesh.h"

namespace focal {

enum class MeshFormat { obj, ply, off, stl };

/// The format named by the file extension (case-insensitive .obj .ply .off .stl).
/// \throw IoError for any other extension.
[[nodiscard]] MeshFormat mesh_format_from_path(const std::filesystem::path& path);

/// Reads a mesh; the format is taken from the extension.
/// Vertex normals are read when the file has them (OBJ `vn` referenced by faces, PLY nx/ny/nz,
/// OFF `NOFF`); otherwise Mesh::N is empty.
/// \throw IoError naming the file and the line, byte offset or element index of the problem.
[[nodiscard]] Mesh read_mesh(const std::filesystem::path& path);

/// Scalar type a per-vertex property is stored as in PLY.
enum class PropertyType { float32, float64, uint8, int32 };

/// A named per-vertex scalar property (one value per vertex) for PLY output.
struct VertexProperty {
  std::string name;
  Eigen::VectorXd values;
  PropertyType type = PropertyType::float32;
};

struct PlyWriteOptions {
  bool binary = true;                 ///< binary little endian (default) or ascii
  std::vector<std::string> comments;  ///< `comment` lines in the header
};

/// Writes V, F, the normals when present and any extra per-vertex properties as PLY.
/// \throw InvalidInput when a property has not one value per vertex; IoError on write failure.
void write_ply(const std::filesystem::path& path, const Mesh& mesh,
               std::span<const VertexProperty> properties = {}, const PlyWriteOptions& options = {});

/// Writes V, F (and `vn` normals when present) as OBJ.
void write_obj(const std::filesystem::path& path, const Mesh& mesh);

/// Writes V, F as OFF (NOFF when normals are present).
void write_off(const std::filesystem::path& path, const Mesh& mesh);

/// Writes a mesh in the format named by the extension (.ply binary, .obj, .off).
void write_mesh(const std::filesystem::path& path, const Mesh& mesh);

/// One column of a CSV table: numbers (NaN written as `nan`, shortest round-trip form) or words.
struct CsvColumn {
  std::string name;
  std::variant<Eigen::VectorXd, std::vector<std::string>> values;
};

/// Writes a header line with the column names, then one row per element.
/// \throw InvalidInput when the columns differ in length; IoError on write failure.
void write_csv(const std::filesystem::path& path, std::span<const CsvColumn> columns);

}  // namespace focal
