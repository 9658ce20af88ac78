#pragma once
/// \file mesh_io.h
/// Reading and writing meshes and per-vertex tables.
///
/// Readers: OBJ, PLY (ascii, binary little and big endian), OFF, STL (ascii and binary), and
/// point-cloud text (.xyz .xyzn .xyzrgb .pwn .pts .txt .csv: `x y z [nx ny nz]` per line, see
/// docs/IO.md), PCL's .pcd (ascii, binary, binary_compressed) and ASPRS LAS 1.0-1.4 (.las),
/// these two read only.
/// A file without faces is a point cloud: Mesh::F has 0 rows (Mesh::is_cloud).
/// Vertex order and count of indexed formats (OBJ, PLY, OFF) are preserved exactly; polygons are
/// fan-triangulated and Mesh::face_source maps each triangle to its input polygon. STL has no
/// shared vertices: corners at the same position are welded into one vertex (ReadOptions), the
/// vertices numbered in order of first appearance, and Mesh::corner_vertex maps each corner of
/// the file to its vertex.
/// Nothing is dropped or repaired: non-manifold and duplicate faces are kept as they are, a face
/// with fewer than 3 vertices or an index out of range is an IoError. NaN and infinite coordinates
/// are read as they are (later stages flag them). Counts declared in a header are checked against
/// the file size before anything is allocated. See docs/IO.md for the per-format details.
///
/// Writers go through a temporary file in the destination folder that is renamed at the end, so
/// a failed write never leaves a half-written file behind (and an existing file stays as it was).
/// Numbers are written in the shortest form that reads back exactly (doubles round-trip bit for
/// bit through PLY, OBJ and OFF), or, with Precision::float32, as floats.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "focal/core/mesh.h"

namespace focal {

enum class MeshFormat { obj, ply, off, stl, xyz, pcd, las };

/// The format named by the file extension (case-insensitive .obj .ply .off .stl; .xyz .xyzn
/// .xyzrgb .pwn .pts .txt and .csv are point-cloud text, MeshFormat::xyz; .pcd is PCL's format;
/// .las (and .laz, whose compressed points are an error naming a way out) is ASPRS LAS).
/// \throw IoError for any other extension.
[[nodiscard]] MeshFormat mesh_format_from_path(const std::filesystem::path& path);

struct ReadOptions {
  /// STL: weld facet corners into shared vertices (false: every corner is its own vertex, in file
  /// order, as the file stores them; no triangle then shares an edge).
  bool weld = true;
  /// STL: 0 welds corners whose coordinates are exactly equal (-0.0 == 0.0); > 0 welds a corner
  /// to the first earlier vertex within this Euclidean distance (grid hashing, deterministic).
  double weld_tolerance = 0.0;
};

/// Reads a mesh; the format is taken from the extension.
/// Vertex normals are read when the file has them (OBJ `vn` referenced by faces, PLY nx/ny/nz,
/// OFF `NOFF`); otherwise Mesh::N is empty. They are kept as written (not renormalised), except
/// for an OBJ vertex referenced with several different `vn`: it gets the normalised average of
/// them (NaN if they cancel). In an OBJ file whose faces reference normals, a vertex never
/// referenced with one gets a NaN row. STL facet normals are not vertex normals and are not read.
/// OBJ: negative (relative) and forward indices are accepted; texture coordinates, groups,
/// materials, lines (`l`, `p`) and free-form geometry are ignored.
/// \throw IoError naming the file and the line, byte offset or element index of the problem,
/// also for a missing file, a path that is not a regular file (a directory, FIFO, device or
/// socket) or an unreadable path; InvalidInput for a negative or non-finite weld_tolerance.
[[nodiscard]] Mesh read_mesh(const std::filesystem::path& path, const ReadOptions& options = {});

/// A binary PLY triangle mesh read a range or a set of records at a time, never whole: the input
/// of a tiled run on a mesh larger than memory (python/focal/stream.py). The values are those
/// read_mesh reads (x y z, and nx ny nz or PCL's normal_x normal_y normal_z, as doubles). Each
/// read opens the file, reads what it asks for in blocks of at most a megabyte and closes it: the
/// reader holds the header's layout only.
/// \pre A binary PLY file (either byte order) whose vertex and face records have a fixed size: the
/// vertex element has no list property, the face element one, its vertex_indices, of 3 items in
/// every face. Other elements before those two have a fixed size; a `tristrips` element is not
/// read, so it is refused.
class PlyTriangleReader {
 public:
  /// Reads and checks the header and the file's size.
  /// \throw IoError naming the file: missing or not a regular file, not PLY, ascii, no vertex or
  /// face element, records of varying size, more than 2^31 - 1 vertices or faces, or fewer bytes
  /// than the header's records need.
  explicit PlyTriangleReader(const std::filesystem::path& path);

  [[nodiscard]] const std::filesystem::path& path() const;
  [[nodiscard]] std::int64_t vertex_count() const;
  [[nodiscard]] std::int64_t face_count() const;
  /// Whether the vertex records hold normals (all three components).
  [[nodiscard]] bool has_normals() const;

  /// Positions of vertices begin .. end - 1, (end - begin) x 3.
  /// \throw InvalidInput unless 0 <= begin <= end <= vertex_count(); IoError when the file
  /// cannot be read (it changed since the header was read).
  [[nodiscard]] RowMatrixX3d positions(std::int64_t begin, std::int64_t end) const;
  /// Positions of vertices `ids` (#ids x 3), in any order; runs of ascending, close ids are read
  /// together. \throw InvalidInput for an id outside [0, vertex_count()); IoError as above.
  [[nodiscard]] RowMatrixX3d positions(std::span<const int> ids) const;
  /// The normals of the same rows. \throw InvalidInput also when the file has none.
  [[nodiscard]] RowMatrixX3d normals(std::int64_t begin, std::int64_t end) const;
  [[nodiscard]] RowMatrixX3d normals(std::span<const int> ids) const;

  /// Corners of faces begin .. end - 1, (end - begin) x 3.
  /// \throw InvalidInput unless 0 <= begin <= end <= face_count(); IoError naming the first face
  /// that is not a triangle or has a corner outside [0, vertex_count()).
  [[nodiscard]] RowMatrixX3i faces(std::int64_t begin, std::int64_t end) const;

  struct Layout;  ///< where the records' fields are (io/ply_records.cpp)

 private:
  std::shared_ptr<const Layout> layout_;
};

/// Precision of the real numbers a writer puts in a file.
enum class Precision {
  /// double: every value reads back bit for bit (binary PLY `double`; text in the shortest form
  /// that reads back to the same double). The default.
  float64,
  /// float: each value v is written as static_cast<float>(v) (binary PLY `float`, 4 bytes; text
  /// in the shortest form that reads back to the same float), for smaller files. Rounds to
  /// float's 24-bit significand; values beyond float's range become +-inf; NaN stays NaN.
  float32,
};

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
  /// float32: positions, normals and `float64` properties written as `float` (the converted
  /// values, see Precision); other property types are unchanged.
  Precision precision = Precision::float64;
};

/// Options of the text writers (CSV, OBJ, OFF, point-cloud text) and of write_mesh.
struct WriteOptions {
  /// float32: every real number (coordinates, normals, CSV numbers) written as the float nearest
  /// to it (Precision); PLY as `float` properties.
  Precision precision = Precision::float64;
};

/// Writes V, F, the normals when present and any extra per-vertex properties as PLY:
/// x y z (and nx ny nz) as `double` so that positions round-trip exactly (`float` with
/// Precision::float32), each property with its PropertyType (float64 ones as `float` with
/// Precision::float32), faces as `list uchar int vertex_indices`.
/// \throw InvalidInput when F indexes outside V, N has neither 0 nor #V rows, a property has not
/// one value per vertex, a property name is empty, has blanks or repeats another, a uint8/int32
/// property value is not an integer in range, or a comment holds a line break;
/// IoError naming the path on write failure.
void write_ply(const std::filesystem::path& path, const Mesh& mesh,
               std::span<const VertexProperty> properties = {},
               const PlyWriteOptions& options = {});

/// Writes V, F (and `vn` normals when present, faces as `v//vn`) as OBJ.
/// \throw InvalidInput for invalid arrays (see write_ply); IoError naming the path on failure.
void write_obj(const std::filesystem::path& path, const Mesh& mesh,
               const WriteOptions& options = {});

/// Writes V, F as OFF (NOFF when normals are present).
/// \throw InvalidInput for invalid arrays (see write_ply); IoError naming the path on failure.
void write_off(const std::filesystem::path& path, const Mesh& mesh,
               const WriteOptions& options = {});

/// Writes V (and N when present) as point-cloud text: one `x y z [nx ny nz]` line per point,
/// faces left out. \throw InvalidInput for invalid arrays; IoError naming the path on failure,
/// and for a .xyzrgb path (Open3D's x y z r g b: read back, the normals would be colours).
void write_xyz(const std::filesystem::path& path, const Mesh& mesh,
               const WriteOptions& options = {});

/// Writes a mesh in the format named by the extension (.ply binary, .obj, .off; .xyz and the
/// other point-cloud text extensions: write_xyz), with the options' precision.
/// \throw IoError for .stl (it cannot keep shared vertices), .pcd, .las and unknown extensions.
void write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                const WriteOptions& options = {});

/// One column of a CSV table: numbers (shortest round-trip form; NaN written as `nan`, infinities
/// as `inf` / `-inf`) or words (written as they are; quoted only when they hold a comma, a quote
/// or a line break, as RFC 4180 requires).
struct CsvColumn {
  std::string name;
  std::variant<Eigen::VectorXd, std::vector<std::string>> values;
};

/// Writes a header line with the column names, then one row per element, the rows formatted in
/// parallel (the bytes are the same for any thread count).
/// \throw InvalidInput when the columns differ in length; IoError on write failure.
void write_csv(const std::filesystem::path& path, std::span<const CsvColumn> columns);
/// write_csv with the numbers in the options' precision (Precision::float32: the shortest text of
/// the float nearest to each number; `nan`, `inf`, `-inf` as above).
void write_csv(const std::filesystem::path& path, std::span<const CsvColumn> columns,
               const WriteOptions& options);

/// Writes a text file (a report, a Markdown table) through the same temporary-file-and-rename
/// path as the other writers. \throw IoError on write failure.
void write_text_file(const std::filesystem::path& path, std::string_view text);

}  // namespace focal
