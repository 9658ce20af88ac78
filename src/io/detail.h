#pragma once
/// \file detail.h
/// Internal helpers shared by the mesh readers and writers: whole-file reading, error messages
/// that name the file and the place, text scanning with line numbers, fan triangulation and
/// number formatting. The writers write through io/atomic_file.h.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/io/mesh_io.h"

namespace focal::io_detail {

/// Throws IoError("<path>: <what>").
[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what);
/// Throws IoError("<path>: line <line>: <what>").
[[noreturn]] void fail_at_line(const std::filesystem::path& path, std::size_t line,
                               const std::string& what);
/// Throws IoError("<path>: byte offset <offset>: <what>").
[[noreturn]] void fail_at_offset(const std::filesystem::path& path, std::size_t offset,
                                 const std::string& what);

/// A file's bytes in memory. The buffer is not zero-filled before the read writes it (a
/// std::string was: a pass over the whole file of its own, ~80 MB for a 1M-vertex PLY).
class FileBytes {
 public:
  FileBytes(std::unique_ptr<char[]> data, std::size_t size) : data_(std::move(data)), size_(size) {}
  [[nodiscard]] std::string_view view() const { return {data_.get(), size_}; }
  operator std::string_view() const { return view(); }  // NOLINT: parsers take string_view

 private:
  std::unique_ptr<char[]> data_;
  std::size_t size_;
};

/// The whole file in memory (one read, so that parsers work on a contiguous buffer).
/// \throw IoError when the path is missing, a directory or unreadable.
[[nodiscard]] FileBytes read_whole_file(const std::filesystem::path& path);

/// Throws IoError unless `count` elements of at least `min_bytes` each fit in `available` bytes.
/// Called before anything is allocated for a count declared in a file header, so that a header
/// claiming 1e12 vertices is rejected instead of exhausting memory. `where` is the place the
/// elements start ("line 12", "byte offset 345"), for the message.
void check_count_fits(const std::filesystem::path& path, std::string_view where,
                      std::uint64_t count, std::uint64_t min_bytes, std::uint64_t available,
                      std::string_view what);

/// The same for binary records of exactly `record_bytes` each, which must all be there (a text
/// file's last element may lack its separator, a binary record may not lack its last byte).
void check_records_fit(const std::filesystem::path& path, std::string_view where,
                       std::uint64_t count, std::uint64_t record_bytes, std::uint64_t available,
                       std::string_view what);

/// `'text'`, for messages. (Also avoids "'" + std::string temporaries, on which GCC 12 gives a
/// false -Wrestrict warning.)
[[nodiscard]] std::string quoted(std::string_view text);

/// Lower-case ASCII copy.
[[nodiscard]] std::string to_lower(std::string_view s);

/// Splits a text buffer into lines ('\n', with a trailing '\r' removed) and counts them.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text, std::size_t first_line = 1)
      : text_(text), next_line_(first_line) {}
  /// Next line, false at the end of the text.
  bool next(std::string_view& line);
  /// 1-based number of the line last returned by next().
  [[nodiscard]] std::size_t line_number() const { return next_line_ - 1; }
  /// Offset just past the line last returned (its '\n' included).
  [[nodiscard]] std::size_t offset() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t next_line_;
};

/// Bytes per run of lines that the text readers parse in parallel: large enough that a run's
/// setup is noise, small enough that 1M-vertex files give dozens of runs to share out.
inline constexpr std::size_t kTextChunkBytes = std::size_t{1} << 20;

/// Offsets that cut `text` into runs of whole lines of about `chunk_bytes` each: 0, then
/// repeatedly the offset just past the first '\n' at least `chunk_bytes` past the previous cut,
/// then text.size() (increasing, no empty run). The cuts depend on the text only, never on a thread
/// count.
[[nodiscard]] std::vector<std::size_t> line_aligned_cuts(std::string_view text,
                                                         std::size_t chunk_bytes);

/// Splits `line` at blanks (space, tab, CR, VT, FF) into `tokens` (cleared first).
void split_tokens(std::string_view line, std::vector<std::string_view>& tokens);

/// split_tokens of `line` up to its comment: a '#' at the start of the line or after a blank. A
/// '#' inside a token is not a comment, so that old MSVC's "1.#QNAN" or "1.#INF" is an error,
/// not "1.".
void split_tokens_before_comment(std::string_view line, std::vector<std::string_view>& tokens);

/// Whether split_tokens(line) gives any token, without splitting: a cheap test for element lines.
[[nodiscard]] bool has_token(std::string_view line);
/// Whether split_tokens_before_comment(line) gives any token, without splitting.
[[nodiscard]] bool has_token_before_comment(std::string_view line);

/// Parses a whole token as a double (std::from_chars; a leading '+', "nan" and "inf" accepted).
/// A value below the smallest double (1e-400) underflows to a subnormal or zero, as in C; one
/// above the largest (1e400) is not a number.
[[nodiscard]] bool parse_double(std::string_view token, double& value);
/// Parses a whole token as a decimal integer (a leading '+' accepted).
[[nodiscard]] bool parse_int(std::string_view token, std::int64_t& value);

/// The fan triangles (v0, vk, vk+1) of one polygon of `count` corners: writes count - 2 of them
/// (none below 3 corners) to `triangles` (3 ints each) and `polygon` once per triangle to
/// `source`; returns how many.
std::size_t fan_triangulate(const std::int32_t* corners, std::size_t count, std::int32_t polygon,
                            std::int32_t* triangles, std::int32_t* source);

/// Triangles collected while reading: polygons are fan-triangulated (v0, vk, vk+1) and each
/// triangle remembers the index of its input polygon.
class TriangleCollector {
 public:
  void reserve(std::size_t polygons);
  void add_polygon(const std::int32_t* corners, std::size_t count, std::int32_t polygon);
  /// A triangle strip (PLY `tristrips`): -1 ends a strip and starts the next; triangle i of a
  /// strip is (c[i], c[i+1], c[i+2]) with every other one reversed, (c[i+1], c[i], c[i+2]), so
  /// that all keep the first one's orientation. Triangles with a repeated corner are left out:
  /// strips use them to join, they are not faces of the surface.
  void add_strip(const std::int32_t* corners, std::size_t count, std::int32_t polygon);
  /// Moves the collected triangles into mesh.F and mesh.face_source.
  void move_into(Mesh& mesh);

 private:
  std::vector<std::int32_t> corners_;
  std::vector<std::int32_t> source_;
};

/// For the runs of `body` cut at `cuts` (runs + 1 offsets), how many of its lines before each
/// run `counts` (prefix sums: runs + 1 entries, the last the whole body's), counted in parallel.
[[nodiscard]] std::vector<std::int64_t> lines_before_runs(std::string_view body,
                                                          std::span<const std::size_t> cuts,
                                                          int threads,
                                                          bool (*counts)(std::string_view));

/// Reads the runs in parallel, read_run(r, triangles) each, and joins their triangles into
/// mesh.F and mesh.face_source in run order. False, mesh's faces unset, when a run throws
/// IoError: the caller then reads serially, which gives the exact error (its line number).
[[nodiscard]] bool read_runs_joined(
    std::size_t runs, int threads, Mesh& mesh,
    const std::function<void(std::size_t, TriangleCollector&)>& read_run);

/// Appends the shortest text that reads back to exactly `value`; NaN as `nan`, infinities as
/// `inf` / `-inf`.
void append_number(std::string& out, double value);
void append_number(std::string& out, float value);
void append_number(std::string& out, std::int64_t value);

/// append_number of `value`, or of static_cast<float>(value) with Precision::float32: the one
/// place where the text writers convert to float32 outputs.
inline void append_real(std::string& out, double value, Precision precision) {
  if (precision == Precision::float32) {
    append_number(out, static_cast<float>(value));
  } else {
    append_number(out, value);
  }
}

/// "3 a b c\n": one triangle as OFF and ascii PLY write it.
inline void append_ascii_triangle(std::string& out, const Eigen::Ref<const RowMatrixX3i>& F,
                                  Eigen::Index f) {
  out += '3';
  for (int c = 0; c < 3; ++c) {
    out += ' ';
    append_number(out, static_cast<std::int64_t>(F(f, c)));
  }
  out += '\n';
}

/// "x y z[ nx ny nz]\n": vertex i as OFF and point-cloud text write it (normals when `normals`).
inline void append_vertex_line(std::string& out, const Mesh& mesh, Eigen::Index i, bool normals,
                               Precision precision) {
  for (int c = 0; c < 3; ++c) {
    if (c > 0) out += ' ';
    append_real(out, mesh.V(i, c), precision);
  }
  for (int c = 0; normals && c < 3; ++c) {
    out += ' ';
    append_real(out, mesh.N(i, c), precision);
  }
  out += '\n';
}

/// STL welding (ReadOptions): `mesh` as the STL parsers return it, one vertex per corner in file
/// order; replaces V by the welded vertices (first-appearance order), remaps F and fills
/// Mesh::corner_vertex. tolerance 0: exactly equal coordinates (-0 == 0; non-finite corners stay
/// apart); > 0: a corner joins the first vertex within that distance. weld false: identity.
/// The exact weld runs on `threads` threads (0: the default); the result does not depend on it.
/// \throw InvalidInput for a negative or non-finite tolerance.
void weld_corners(Mesh& mesh, double tolerance, bool weld, int threads);
/// The exact weld's matching: for every corner of V, the first corner with exactly its position
/// (-0 == 0; itself for a first and for a non-finite corner). `hashes_first`: corners are matched
/// by 64-bit hashes alone and the matches then checked, positions compared throughout only if a
/// check fails (what weld_corners does); false: positions compared throughout. The same answer
/// either way and for any `threads`; the choice is exposed for tests.
[[nodiscard]] std::vector<std::int32_t> first_equal_corners(const RowMatrixX3d& V, int threads,
                                                            bool hashes_first);

// The per-format readers, dispatched by read_mesh().
/// `threads` as ReadOptions::threads (the mesh does not depend on it).
[[nodiscard]] Mesh read_obj(const std::filesystem::path& path, int threads);
[[nodiscard]] Mesh read_ply(const std::filesystem::path& path, int threads);
[[nodiscard]] Mesh read_off(const std::filesystem::path& path, int threads);
/// Point-cloud text (xyz.cpp); Mesh::F has 0 rows.
[[nodiscard]] Mesh read_xyz(const std::filesystem::path& path);
/// PCL's .pcd (pcd.cpp): ascii, binary or binary_compressed; Mesh::F has 0 rows.
[[nodiscard]] Mesh read_pcd(const std::filesystem::path& path);
/// ASPRS LAS (las.cpp): the positions of every point record; Mesh::F has 0 rows, no normals.
[[nodiscard]] Mesh read_las(const std::filesystem::path& path);
[[nodiscard]] Mesh read_stl(const std::filesystem::path& path, int threads);

// The same readers on the contents of a file already in memory (read_X(path) is
// parse_X(path, read_whole_file(path))); `path` only names the file in messages. The fuzz targets
// in fuzz/ call these directly. \throw IoError as the readers.
[[nodiscard]] Mesh parse_obj(const std::filesystem::path& path, std::string_view data);
/// parse_obj reading runs of `chunk_bytes` (line_aligned_cuts) on `threads` threads (0: the
/// default); the Mesh, or the error, is the serial reader's for any thread count and run size.
[[nodiscard]] Mesh parse_obj(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// The parallel read of that parse_obj alone: nothing where parse_obj falls back to the serial
/// read (one run or one thread; a run holding an error, a control byte or a relative index).
/// Lets tests see that the parallel read ran.
[[nodiscard]] std::optional<Mesh> parse_obj_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);
[[nodiscard]] Mesh parse_ply(const std::filesystem::path& path, std::string_view data);
/// Point-cloud text; the extension of `path` says what six columns hold (xyz.cpp).
[[nodiscard]] Mesh parse_xyz(const std::filesystem::path& path, std::string_view data);
[[nodiscard]] Mesh parse_pcd(const std::filesystem::path& path, std::string_view data);
[[nodiscard]] Mesh parse_las(const std::filesystem::path& path, std::string_view data);
/// parse_ply with its parallel passes on `threads` threads (0: the default).
[[nodiscard]] Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads);
/// That parse_ply with an ascii body read as parse_obj reads a file: runs of `chunk_bytes`, the
/// serial reader's Mesh or error whatever the thread count.
[[nodiscard]] Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// Its parallel ascii read alone: nothing where it falls back to the serial read (and for binary
/// files). For tests.
[[nodiscard]] std::optional<Mesh> parse_ply_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);
[[nodiscard]] Mesh parse_off(const std::filesystem::path& path, std::string_view data);
/// parse_off reading the body (the vertex and face lines) as parse_obj reads a file: runs of
/// `chunk_bytes` on `threads` threads, the serial reader's Mesh or error whatever the count.
[[nodiscard]] Mesh parse_off(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// Its parallel read alone: nothing where it falls back to the serial read. For tests.
[[nodiscard]] std::optional<Mesh> parse_off_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);
[[nodiscard]] Mesh parse_stl(const std::filesystem::path& path, std::string_view data);
/// parse_stl with binary facets read on `threads` threads and an ascii text read in runs of about
/// `chunk_bytes` cut where facets open: the serial reader's Mesh or error for any thread count
/// and run size.
[[nodiscard]] Mesh parse_stl(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// Its parallel ascii read alone: nothing where it falls back to the serial read (and for binary
/// files). For tests.
[[nodiscard]] std::optional<Mesh> parse_stl_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);

}  // namespace focal::io_detail
