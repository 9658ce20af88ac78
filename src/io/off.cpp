// OFF reading and writing (Geomview's Object File Format, ascii). The keyword's prefixes say
// what follows the coordinates of a vertex: ST (texture coordinates), C (a colour), N (a
// normal). Geomview writes them in the order [ST][C][N]OFF and a vertex as
// `x y z [nx ny nz] [colour] [s t]`; MeshLab (vcglib's exporter, so pymeshlab too) writes
// [N][C][ST]OFF and, with both N and C, the colour first: `NCOFF` is `x y z r g b a nx ny nz`.
// The keyword's order tells the two apart; the colour (0 to 4 numbers) and texture coordinates
// are skipped. Face lines are `n i0 .. in-1 [colour]`. `#` starts a comment.

#include <cmath>
#include <optional>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/number_text.h"
#include "io/text_scan.h"

namespace focal {
namespace {

using io_detail::fail;
using io_detail::fail_at_line;

/// What a vertex line holds after its coordinates, from the keyword's prefixes.
struct VertexLayout {
  bool normals = false;
  bool colour_before_normal = false;  ///< MeshLab's NCOFF
  bool texture = false;
};

/// The keyword's layout and the element counts.
struct OffHeader {
  VertexLayout layout;
  std::int64_t vertices = 0;
  std::int64_t faces = 0;
};

class OffReader {
 public:
  OffReader(const std::filesystem::path& path, std::string_view text)
      : path_(path), text_(text), cursor_(text) {}

  /// The keyword and counts; the body starts at offset().
  OffHeader read_header() {
    if (!next_line()) fail(path_, "empty file, expected an OFF header");
    const VertexLayout layout = parse_keyword(tokens_[0]);
    tokens_.erase(tokens_.begin());
    // Counts usually follow on the next line, but "OFF 8 6 12" on one line is common too.
    if (tokens_.empty() && !next_line()) fail(path_, "file ends before the element counts");
    const auto [vertex_count, face_count] = parse_counts();

    // Every vertex and face takes at least one non-blank line ("x\n"). The bound is loose on
    // purpose: it only has to stop a header claiming 1e12 vertices before allocation, while a
    // merely malformed file gets the precise message of the line where it goes wrong.
    const std::size_t rest = text_.size() - cursor_.offset();
    const std::string where = "line " + std::to_string(cursor_.line_number() + 1);
    io_detail::check_count_fits(path_, where, vertex_count, 2, rest, "vertices");
    io_detail::check_count_fits(path_, where, face_count, 2, rest, "faces");
    const std::uint64_t normal_bytes = layout.normals ? io_detail::kNormalBytes : 0;
    io_detail::require_memory_for(path_, vertex_count, io_detail::kVertexBytes + normal_bytes,
                                  "vertices");
    io_detail::require_memory_for(path_, face_count, io_detail::kTriangleBytes, "faces");
    return {layout, static_cast<std::int64_t>(vertex_count), static_cast<std::int64_t>(face_count)};
  }

  /// Offset just past the lines read so far.
  [[nodiscard]] std::size_t offset() const { return cursor_.offset(); }

  /// The vertices and faces that follow the header, in order.
  Mesh read_body(const OffHeader& h) {
    Mesh mesh;
    read_vertices(h, mesh);
    read_faces(h, mesh);
    // More element lines than the header declares: a wrong count, or two files in one; never
    // silently dropped.
    if (next_line()) {
      fail_at_line(path_, cursor_.line_number(),
                   "data after the last of the " + std::to_string(h.vertices) + " vertices and " +
                       std::to_string(h.faces) + " faces the header declares: '" +
                       std::string(tokens_[0]) + "'");
    }
    return mesh;
  }

  /// The elements of a run of body lines (read_off_runs) whose first element line is element
  /// `first` of the body (vertices, then faces; lines past the last face are not read): vertices
  /// into their rows of `mesh`, faces into `triangles`.
  void read_run(const OffHeader& h, std::int64_t first, Mesh& mesh,
                io_detail::TriangleCollector& triangles) {
    std::vector<std::int32_t> corners;
    for (std::int64_t e = first; e < h.vertices + h.faces && next_line(); ++e) {
      if (e < h.vertices) {
        read_vertex(static_cast<Eigen::Index>(e), h, mesh);
      } else {
        read_face(e - h.vertices, h, triangles, corners);
      }
    }
  }

 private:
  /// Next line with tokens (comments and blank lines skipped); false at the end of the file.
  bool next_line() {
    std::string_view line;
    while (cursor_.next(line)) {
      io_detail::split_tokens_before_comment(line, tokens_);
      if (!tokens_.empty()) return true;
    }
    return false;
  }

  /// Removes `prefix` from the front of k if it is there.
  static bool take(std::string_view& k, std::string_view prefix) {
    const bool found = k.starts_with(prefix);
    if (found) k.remove_prefix(prefix.size());
    return found;
  }

  /// Prefixes in Geomview's order [ST][C][N]: a normal follows the coordinates.
  static bool parse_geomview(std::string_view k, VertexLayout& layout) {
    layout.texture = take(k, "ST");
    take(k, "C");
    layout.normals = take(k, "N");
    return k.empty();
  }

  /// Prefixes in MeshLab's order [N][C][ST]: with a colour, the colour comes before the normal.
  static bool parse_meshlab(std::string_view k, VertexLayout& layout) {
    layout.normals = take(k, "N");
    layout.colour_before_normal = take(k, "C") && layout.normals;
    layout.texture = take(k, "ST");
    return k.empty();
  }

  VertexLayout parse_keyword(std::string_view keyword) const {
    std::string_view k = keyword;
    if (k.size() < 3 || k.substr(k.size() - 3) != "OFF") {
      fail_at_line(path_, cursor_.line_number(),
                   "not an OFF file (expected a keyword such as OFF or NOFF, got '" +
                       std::string(keyword) + "')");
    }
    k.remove_suffix(3);
    VertexLayout layout;
    if (!parse_geomview(k, layout) && !parse_meshlab(k, layout)) {
      fail_at_line(path_, cursor_.line_number(),
                   "unsupported OFF variant '" + std::string(keyword) +
                       "' (expected [ST][C][N]OFF or MeshLab's [N][C][ST]OFF; 4OFF and nOFF are "
                       "not 3-d meshes)");
    }
    if (tokens_.size() > 1 && tokens_[1] == "BINARY") {
      fail_at_line(path_, cursor_.line_number(), "binary OFF is not supported");
    }
    return layout;
  }

  std::pair<std::uint64_t, std::uint64_t> parse_counts() const {
    std::int64_t counts[3] = {0, 0, 0};
    const bool ok = (tokens_.size() == 2 || tokens_.size() == 3) &&
                    io_detail::parse_int(tokens_[0], counts[0]) &&
                    io_detail::parse_int(tokens_[1], counts[1]) &&
                    (tokens_.size() == 2 || io_detail::parse_int(tokens_[2], counts[2]));
    if (!ok || counts[0] < 0 || counts[1] < 0) {
      fail_at_line(path_, cursor_.line_number(),
                   "expected the counts '<vertices> <faces> [<edges>]' (non-negative integers)");
    }
    return {static_cast<std::uint64_t>(counts[0]), static_cast<std::uint64_t>(counts[1])};
  }

  double number(std::size_t t) const {
    double value = 0.0;
    if (!io_detail::parse_double(tokens_[t], value)) {
      fail_at_line(path_, cursor_.line_number(),
                   io_detail::quoted(tokens_[t]) + " is not a number");
    }
    return value;
  }

  void read_vertices(const OffHeader& h, Mesh& mesh) {
    mesh.V.resize(h.vertices, 3);
    if (h.layout.normals) mesh.N.resize(h.vertices, 3);
    for (Eigen::Index i = 0; i < h.vertices; ++i) {
      if (!next_line()) {
        fail_at_line(
            path_, cursor_.line_number(),
            "file ends inside vertex " + std::to_string(i) + " of " + std::to_string(h.vertices));
      }
      read_vertex(i, h, mesh);
    }
  }

  /// Vertex i from the current line, into row i of mesh.V (and mesh.N).
  void read_vertex(Eigen::Index i, const OffHeader& h, Mesh& mesh) const {
    const VertexLayout layout = h.layout;
    const bool normals = layout.normals;
    const std::size_t needed = normals ? 6 : 3;
    if (tokens_.size() < needed) {
      fail_at_line(path_, cursor_.line_number(),
                   "vertex " + std::to_string(i) + ": expected " + std::to_string(needed) +
                       (normals ? " coordinates and normal components" : " coordinates") +
                       ", got " + std::to_string(tokens_.size()));
    }
    for (int c = 0; c < 3; ++c) mesh.V(i, c) = number(static_cast<std::size_t>(c));
    if (!normals) return;
    const std::size_t first = layout.colour_before_normal ? normal_after_colour(i, layout) : 3;
    for (int c = 0; c < 3; ++c) mesh.N(i, c) = number(first + static_cast<std::size_t>(c));
  }

  /// Token of the normal's first component on a MeshLab NCOFF vertex line: after the colour,
  /// whose 0 to 4 numbers are what the line holds beyond coordinates, normal and [s t].
  std::size_t normal_after_colour(Eigen::Index i, VertexLayout layout) const {
    const std::size_t fixed = 6 + (layout.texture ? 2 : 0);
    if (tokens_.size() < fixed || tokens_.size() > fixed + 4) {
      fail_at_line(path_, cursor_.line_number(),
                   "vertex " + std::to_string(i) + ": expected " + std::to_string(fixed) + " to " +
                       std::to_string(fixed + 4) +
                       " numbers (coordinates, a colour of 0 to 4, a normal" +
                       (layout.texture ? ", texture coordinates" : "") + "), got " +
                       std::to_string(tokens_.size()));
    }
    return tokens_.size() - 3 - (layout.texture ? 2 : 0);
  }

  void read_faces(const OffHeader& h, Mesh& mesh) {
    io_detail::TriangleCollector triangles;
    triangles.reserve(static_cast<std::size_t>(h.faces));
    std::vector<std::int32_t> corners;
    for (std::int64_t f = 0; f < h.faces; ++f) {
      if (!next_line()) {
        fail_at_line(
            path_, cursor_.line_number(),
            "file ends inside face " + std::to_string(f) + " of " + std::to_string(h.faces));
      }
      read_face(f, h, triangles, corners);
    }
    triangles.move_into(mesh);
  }

  /// Face f from the current line, fanned into `triangles` (`corners`: scratch).
  void read_face(std::int64_t f, const OffHeader& h, io_detail::TriangleCollector& triangles,
                 std::vector<std::int32_t>& corners) const {
    const std::string face = "face " + std::to_string(f);
    std::int64_t n = 0;
    if (!io_detail::parse_int(tokens_[0], n) || n < 0) {
      fail_at_line(path_, cursor_.line_number(),
                   face + ": '" + std::string(tokens_[0]) + "' is not a vertex count");
    }
    if (n < 3) {
      fail_at_line(path_, cursor_.line_number(),
                   face + " has " + std::to_string(n) + " vertices; a face needs at least 3");
    }
    // Tokens after the indices are a colour.
    if (tokens_.size() < static_cast<std::size_t>(n) + 1) {
      fail_at_line(path_, cursor_.line_number(),
                   face + ": expected " + std::to_string(n) + " vertex indices, got " +
                       std::to_string(tokens_.size() - 1));
    }
    corners.resize(static_cast<std::size_t>(n));
    for (std::size_t c = 0; c < corners.size(); ++c) {
      corners[c] = vertex_index(tokens_[c + 1], face, h.vertices);
    }
    triangles.add_polygon(corners.data(), corners.size(), static_cast<std::int32_t>(f));
  }

  std::int32_t vertex_index(std::string_view token, const std::string& face,
                            std::int64_t vertex_count) const {
    std::int64_t v = 0;
    if (!io_detail::parse_int(token, v)) {
      fail_at_line(path_, cursor_.line_number(),
                   face + ": '" + std::string(token) + "' is not a vertex index");
    }
    if (v < 0 || v >= vertex_count) {
      fail_at_line(path_, cursor_.line_number(),
                   face + " refers to vertex " + std::to_string(v) + " but there are " +
                       std::to_string(vertex_count) + " vertices");
    }
    return static_cast<std::int32_t>(v);
  }

  const std::filesystem::path& path_;
  std::string_view text_;
  io_detail::LineCursor cursor_;
  std::vector<std::string_view> tokens_;
};

/// The body read as runs of lines in parallel (each run by the serial reader's code, its first
/// element's index known from the element lines before it), or nothing when the body is too
/// small to split, ends before its last face, or a run meets an error: the serial read then
/// gives the exact error (whose message needs its line number) or result.
std::optional<Mesh> read_off_runs(const std::filesystem::path& path, std::string_view body,
                                  const OffHeader& header, int threads, std::size_t run_bytes) {
  const std::vector<std::size_t> cuts = io_detail::line_aligned_cuts(body, run_bytes);
  const std::size_t runs = cuts.size() - 1;
  if (runs < 2 || detail::thread_count(threads) < 2) return std::nullopt;
  const auto run = [&](std::size_t r) { return body.substr(cuts[r], cuts[r + 1] - cuts[r]); };
  const std::vector<std::int64_t> first =  // element lines before each run
      io_detail::lines_before_runs(body, cuts, threads, io_detail::has_token_before_comment);
  const std::int64_t elements = header.vertices + header.faces;
  // Fewer element lines than declared, or more: the serial read reports where.
  if (first.back() != elements) return std::nullopt;

  Mesh mesh;
  mesh.V.resize(header.vertices, 3);
  if (header.layout.normals) mesh.N.resize(header.vertices, 3);
  const bool read = io_detail::read_runs_joined(
      runs, threads, mesh, [&](std::size_t r, io_detail::TriangleCollector& triangles) {
        if (first[r] < elements)
          OffReader(path, run(r)).read_run(header, first[r], mesh, triangles);
      });
  if (!read) return std::nullopt;
  return mesh;
}

}  // namespace

namespace io_detail {

Mesh parse_off(const std::filesystem::path& path, std::string_view data) {
  return parse_off(path, data, 0, kTextChunkBytes);
}

std::optional<Mesh> parse_off_in_chunks(const std::filesystem::path& path, std::string_view data,
                                        int threads, std::size_t chunk_bytes) {
  OffReader reader(path, data);
  const OffHeader header = reader.read_header();
  return read_off_runs(path, data.substr(reader.offset()), header, threads, chunk_bytes);
}

Mesh parse_off(const std::filesystem::path& path, std::string_view data, int threads,
               std::size_t chunk_bytes) {
  OffReader reader(path, data);
  const OffHeader header = reader.read_header();
  std::optional<Mesh> mesh =
      read_off_runs(path, data.substr(reader.offset()), header, threads, chunk_bytes);
  return mesh ? std::move(*mesh) : reader.read_body(header);
}

Mesh read_off(const std::filesystem::path& path, int threads) {
  return parse_off(path, read_whole_file(path), threads, kTextChunkBytes);
}

}  // namespace io_detail

void write_off(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options) {
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, ("write_off: " + path.string()).c_str());
  const bool normals = mesh.has_normals();
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    std::string& header = sink.buffer();
    header += normals ? "NOFF\n" : "OFF\n";
    header += std::to_string(mesh.V.rows()) + " " + std::to_string(mesh.F.rows()) + " 0\n";
    io_detail::write_lines(sink, mesh.V.rows(), 0, [&](std::string& line, std::int64_t i) {
      io_detail::append_vertex_line(line, mesh, i, normals, options.precision);
    });
    io_detail::write_lines(sink, mesh.F.rows(), 0, [&](std::string& line, std::int64_t f) {
      io_detail::append_ascii_triangle(line, mesh.F, f);
    });
  });
}

}  // namespace focal
