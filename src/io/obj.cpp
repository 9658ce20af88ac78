// Wavefront OBJ reading and writing (geometry only: v, vn and f; materials, texture coordinates,
// groups, lines and free-form geometry are not part of a triangle mesh and are ignored).

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/number_text.h"
#include "io/text_scan.h"

namespace focal {
namespace {

using io_detail::fail_at_line;

/// Offset of the first control byte other than blanks and line breaks, or npos.
std::size_t find_control_byte(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if ((byte < 0x20 && byte != '\t' && byte != '\n' && byte != '\r' && byte != '\v' &&
         byte != '\f') ||
        byte == 0x7F) {
      return i;
    }
  }
  return std::string_view::npos;
}

/// One face corner as written: vertex and normal indices, already resolved to 0-based
/// (relative indices applied), not yet range-checked. normal is -1 when the corner has none.
struct Corner {
  std::int64_t vertex;
  std::int64_t normal;
};

/// The statements of an OBJ text, or of a run of its lines, in file order.
struct ObjData {
  std::vector<double> positions;          // 3 per vertex
  std::vector<double> normals;            // 3 per vn
  std::size_t texture_count = 0;          // vt lines, for relative texture indices
  std::vector<Corner> corners;            // all face corners, polygon after polygon
  std::vector<std::size_t> polygon_end;   // one past each polygon's last corner
  std::vector<std::size_t> polygon_line;  // each polygon's line
  std::size_t lines = 0;                  // lines of the text read
};

/// What an ObjReader reads: a whole file, or a run of lines from inside one (read_obj_chunks).
enum class ObjText { whole_file, run_of_lines };

/// Thrown by a reader of a run of lines that meets a relative index: it refers to the elements
/// before the run, which only a reader of the whole file knows.
struct NeedsWholeFile {};

class ObjReader {
 public:
  ObjReader(const std::filesystem::path& path, ObjText scope) : path_(path), scope_(scope) {}

  ObjData read(std::string_view text) {
    io_detail::LineCursor cursor(text);
    std::string_view line;
    std::vector<std::string_view> tokens;
    while (cursor.next(line)) {
      line_ = cursor.line_number();
      io_detail::split_tokens_before_comment(line, tokens);
      if (tokens.empty()) continue;
      if (tokens[0] == "v") {
        read_triple(tokens, "coordinates", d_.positions);
      } else if (tokens[0] == "vn") {
        read_triple(tokens, "normal components", d_.normals);
      } else if (tokens[0] == "vt") {
        ++d_.texture_count;
      } else if (tokens[0] == "f") {
        read_face(tokens);
      }
    }
    d_.lines = cursor.line_number();
    return std::move(d_);
  }

 private:
  /// `v x y z [w] [r g b]` and `vn x y z`: the first three numbers are kept.
  void read_triple(const std::vector<std::string_view>& tokens, const char* what,
                   std::vector<double>& out) const {
    if (tokens.size() < 4) {
      fail_at_line(
          path_, line_,
          "expected 3 " + std::string(what) + ", got " + std::to_string(tokens.size() - 1));
    }
    for (std::size_t i = 1; i < tokens.size(); ++i) {
      double value = 0.0;
      if (!io_detail::parse_double(tokens[i], value)) {
        fail_at_line(path_, line_, io_detail::quoted(tokens[i]) + " is not a number");
      }
      if (i <= 3) out.push_back(value);
    }
  }

  /// 1-based or negative (relative to the `count` elements read so far) to 0-based.
  std::int64_t resolve(std::string_view token, std::size_t count, const char* what) const {
    std::int64_t index = 0;
    if (!io_detail::parse_int(token, index) || index == 0) {
      fail_at_line(path_, line_, io_detail::quoted(token) + " is not a valid " + what + " index");
    }
    if (index > 0) return index - 1;
    if (scope_ == ObjText::run_of_lines) throw NeedsWholeFile{};
    const std::int64_t resolved = static_cast<std::int64_t>(count) + index;
    if (resolved < 0) {
      fail_at_line(path_, line_,
                   "face " + std::to_string(d_.polygon_end.size()) + ": relative " + what +
                       " index " + std::to_string(index) + " reaches before the first " + what);
    }
    return resolved;
  }

  /// A corner is v, v/vt, v//vn or v/vt/vn.
  Corner parse_corner(std::string_view token) const {
    const std::size_t slash1 = token.find('/');
    Corner c{resolve(token.substr(0, slash1), d_.positions.size() / 3, "vertex"), -1};
    if (slash1 == std::string_view::npos) return c;
    const std::size_t slash2 = token.find('/', slash1 + 1);
    // Texture coordinates are not used, but a malformed one is still an error.
    const std::string_view texture = token.substr(slash1 + 1, slash2 - slash1 - 1);
    if (!texture.empty()) (void)resolve(texture, d_.texture_count, "texture coordinate");
    if (slash2 == std::string_view::npos) return c;
    const std::string_view normal = token.substr(slash2 + 1);
    if (!normal.empty()) c.normal = resolve(normal, d_.normals.size() / 3, "normal");
    return c;
  }

  void read_face(const std::vector<std::string_view>& tokens) {
    if (tokens.size() < 4) {
      fail_at_line(path_, line_,
                   "face " + std::to_string(d_.polygon_end.size()) + " has " +
                       std::to_string(tokens.size() - 1) + " vertices; a face needs at least 3");
    }
    for (std::size_t i = 1; i < tokens.size(); ++i) d_.corners.push_back(parse_corner(tokens[i]));
    d_.polygon_end.push_back(d_.corners.size());
    d_.polygon_line.push_back(line_);
  }

  const std::filesystem::path& path_;
  ObjText scope_;
  std::size_t line_ = 0;
  ObjData d_;
};

/// Where each run's elements start in the whole file's numbering.
struct RunStart {
  std::size_t vertex = 0;
  std::size_t normal = 0;
  std::size_t polygon = 0;
  std::size_t triangle = 0;
  std::size_t line = 0;  // lines before the run
};

/// Builds the mesh from the statements of a whole file, read as one run or as consecutive runs
/// of its lines: the runs' elements follow each other, the indices in their corners are the
/// file's (runs hold no relative index), their lines and polygons count from the run's start.
class ObjMeshBuilder {
 public:
  ObjMeshBuilder(const std::filesystem::path& path, std::span<const ObjData> runs, int threads)
      : path_(path), runs_(runs), threads_(threads), start_(runs.size() + 1) {
    for (std::size_t r = 0; r < runs.size(); ++r) {
      const ObjData& d = runs[r];
      const RunStart& s = start_[r];
      // Every polygon has at least 3 corners, so it fans into corners - 2 triangles.
      start_[r + 1] = {s.vertex + d.positions.size() / 3, s.normal + d.normals.size() / 3,
                       s.polygon + d.polygon_end.size(),
                       s.triangle + d.corners.size() - 2 * d.polygon_end.size(), s.line + d.lines};
    }
  }

  Mesh build() const {
    check_ranges();
    const RunStart& total = start_.back();
    if (total.vertex > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
      io_detail::fail(path_, "more vertices than 32-bit indices can address");
    }
    Mesh mesh;
    const auto vertex_count = static_cast<Eigen::Index>(total.vertex);
    mesh.V.resize(vertex_count, 3);
    for_each_run([&](std::size_t r) {
      std::copy(runs_[r].positions.begin(), runs_[r].positions.end(),
                mesh.V.data() + 3 * start_[r].vertex);
    });
    const bool any_normal = std::any_of(runs_.begin(), runs_.end(), [](const ObjData& d) {
      return std::any_of(d.corners.begin(), d.corners.end(),
                         [](const Corner& c) { return c.normal >= 0; });
    });
    if (any_normal) {
      mesh.N = vertex_normals(vertex_count);
    } else if (total.polygon == 0 && vertex_count > 0 && total.normal == total.vertex) {
      // A point cloud (no faces) with one `vn` per `v`, as write_obj writes one: paired in order.
      const std::vector<double> normals = joined_normals();
      mesh.N = Eigen::Map<const RowMatrixX3d>(normals.data(), vertex_count, 3);
    }
    triangulate(mesh);
    return mesh;
  }

 private:
  template <class Body>
  void for_each_run(Body&& body) const {
    detail::parallel_chunks(static_cast<std::int64_t>(runs_.size()), threads_,
                            [&](std::int64_t r) { body(static_cast<std::size_t>(r)); });
  }

  /// Fans every polygon, each run into its own rows of F.
  void triangulate(Mesh& mesh) const {
    const auto triangles = static_cast<Eigen::Index>(start_.back().triangle);
    mesh.F.resize(triangles, 3);
    mesh.face_source.resize(triangles);
    for_each_run([&](std::size_t r) {
      const ObjData& d = runs_[r];
      std::int32_t* corners_out = mesh.F.data() + 3 * start_[r].triangle;
      std::int32_t* source_out = mesh.face_source.data() + start_[r].triangle;
      std::vector<std::int32_t> polygon;
      std::size_t begin = 0;
      for (std::size_t p = 0; p < d.polygon_end.size(); ++p) {
        polygon.clear();
        for (std::size_t k = begin; k < d.polygon_end[p]; ++k) {
          polygon.push_back(static_cast<std::int32_t>(d.corners[k].vertex));
        }
        const auto source = static_cast<std::int32_t>(start_[r].polygon + p);
        const std::size_t written = io_detail::fan_triangulate(polygon.data(), polygon.size(),
                                                               source, corners_out, source_out);
        corners_out += 3 * written;
        source_out += written;
        begin = d.polygon_end[p];
      }
    });
  }

  /// Indices may refer forward, so the range check waits until every v and vn is known. The
  /// runs are checked in parallel; the file's first polygon out of range is reported.
  void check_ranges() const {
    std::vector<std::size_t> first_bad(runs_.size(), kNone);
    for_each_run([&](std::size_t r) {
      const ObjData& d = runs_[r];
      std::size_t begin = 0;
      for (std::size_t p = 0; p < d.polygon_end.size() && first_bad[r] == kNone; ++p) {
        for (std::size_t k = begin; k < d.polygon_end[p]; ++k) {
          if (out_of_range(d.corners[k])) first_bad[r] = p;
        }
        begin = d.polygon_end[p];
      }
    });
    for (std::size_t r = 0; r < runs_.size(); ++r) {
      if (first_bad[r] != kNone) fail_out_of_range(r, first_bad[r]);
    }
  }

  [[nodiscard]] bool out_of_range(const Corner& c) const {
    return c.vertex >= static_cast<std::int64_t>(start_.back().vertex) ||
           c.normal >= static_cast<std::int64_t>(start_.back().normal);
  }

  /// Throws for the first corner out of range of polygon p of run r.
  [[noreturn]] void fail_out_of_range(std::size_t r, std::size_t p) const {
    const ObjData& d = runs_[r];
    const std::size_t line = start_[r].line + d.polygon_line[p];
    const std::string face = "face " + std::to_string(start_[r].polygon + p);
    const auto vertices = static_cast<std::int64_t>(start_.back().vertex);
    const auto normals = static_cast<std::int64_t>(start_.back().normal);
    for (std::size_t k = p == 0 ? 0 : d.polygon_end[p - 1]; k < d.polygon_end[p]; ++k) {
      const Corner& c = d.corners[k];
      if (c.vertex >= vertices) {
        fail_at_line(path_, line,
                     face + " refers to vertex " + std::to_string(c.vertex + 1) +
                         " but there are " + std::to_string(vertices) + " vertices");
      }
      if (c.normal >= normals) {
        fail_at_line(path_, line,
                     face + " refers to normal " + std::to_string(c.normal + 1) +
                         " but there are " + std::to_string(normals) + " normals");
      }
    }
    io_detail::fail(path_, "internal error: polygon reported out of range is not");
  }

  /// Every run's `vn` components, in file order.
  [[nodiscard]] std::vector<double> joined_normals() const {
    std::vector<double> all;
    all.reserve(3 * start_.back().normal);
    for (const ObjData& d : runs_) all.insert(all.end(), d.normals.begin(), d.normals.end());
    return all;
  }

  /// Per vertex: the referenced normal, or the normalised average of the distinct normals
  /// (by vn index) referenced for it; NaN where a vertex is never referenced with a normal.
  RowMatrixX3d vertex_normals(Eigen::Index vertex_count) const {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    RowMatrixX3d N = RowMatrixX3d::Constant(vertex_count, 3, kNaN);
    std::vector<std::int64_t> first(static_cast<std::size_t>(vertex_count), -1);
    std::vector<std::pair<std::int64_t, std::int64_t>> others;  // (vertex, normal) conflicts
    for (const ObjData& d : runs_) {
      for (const Corner& c : d.corners) {
        if (c.normal < 0) continue;
        auto& f = first[static_cast<std::size_t>(c.vertex)];
        if (f < 0) {
          f = c.normal;
        } else if (f != c.normal) {
          others.emplace_back(c.vertex, c.normal);
        }
      }
    }
    const std::vector<double> normals = joined_normals();
    const auto normal = [&](std::int64_t n) {
      const auto k = static_cast<std::size_t>(3 * n);
      return Eigen::RowVector3d(normals[k], normals[k + 1], normals[k + 2]);
    };
    for (Eigen::Index v = 0; v < vertex_count; ++v) {
      const auto f = first[static_cast<std::size_t>(v)];
      if (f >= 0) N.row(v) = normal(f);
    }
    std::sort(others.begin(), others.end());
    others.erase(std::unique(others.begin(), others.end()), others.end());
    for (const auto& [v, n] : others) N.row(v) += normal(n);
    for (std::size_t i = 0; i < others.size(); ++i) {
      if (i + 1 < others.size() && others[i + 1].first == others[i].first) continue;
      const auto v = others[i].first;
      const double length = N.row(v).norm();
      // Opposite normals cancel: no direction exists, so NaN rather than a made-up one.
      N.row(v) =
          length > 0 ? Eigen::RowVector3d(N.row(v) / length) : Eigen::RowVector3d::Constant(kNaN);
    }
    return N;
  }

  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  const std::filesystem::path& path_;
  std::span<const ObjData> runs_;
  int threads_;
  std::vector<RunStart> start_;  // per run, then the totals
};

/// The control-byte check and the statements of a whole file, read in file order: the
/// reference that the chunked read must equal, and the one that reports errors.
ObjData read_obj_serially(const std::filesystem::path& path, std::string_view data) {
  const std::size_t control = find_control_byte(data);
  if (control != std::string_view::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned char>(data[control]));
    io_detail::fail_at_offset(path, control,
                              std::string("control byte ") + hex + ": binary data, not OBJ text");
  }
  return ObjReader(path, ObjText::whole_file).read(data);
}

/// The statements of a whole file read as runs of lines in parallel, or nothing when the file is
/// too small to split or a run meets anything a run cannot judge alone (an error, whose message
/// needs the face count and line so far, or a relative index): the serial read then gives the
/// exact result or error. Runs without either are read exactly as the serial reader reads them,
/// so the runs one after the other are its statements, whatever the thread count.
std::optional<std::vector<ObjData>> read_obj_chunks(const std::filesystem::path& path,
                                                    std::string_view data, int threads,
                                                    std::size_t chunk_bytes) {
  const std::vector<std::size_t> cuts = io_detail::line_aligned_cuts(data, chunk_bytes);
  const auto chunks = static_cast<std::int64_t>(cuts.size()) - 1;
  if (chunks < 2 || detail::thread_count(threads) < 2) return std::nullopt;
  std::vector<ObjData> runs(static_cast<std::size_t>(chunks));
  std::atomic<bool> serial{false};
  detail::parallel_chunks(chunks, threads, [&](std::int64_t c) {
    if (serial.load(std::memory_order_relaxed)) return;
    const auto k = static_cast<std::size_t>(c);
    const std::string_view text = data.substr(cuts[k], cuts[k + 1] - cuts[k]);
    try {
      if (find_control_byte(text) != std::string_view::npos) throw NeedsWholeFile{};
      runs[k] = ObjReader(path, ObjText::run_of_lines).read(text);
    } catch (const IoError&) {
      serial.store(true, std::memory_order_relaxed);
    } catch (const NeedsWholeFile&) {
      serial.store(true, std::memory_order_relaxed);
    }
  });
  if (serial.load()) return std::nullopt;
  return runs;
}

/// `data` less a UTF-8 byte order mark, after the checks of its start.
std::string_view obj_text(const std::filesystem::path& path, std::string_view data) {
  // OBJ has no header, so a 0-byte file would read as a valid empty mesh; it is nearly always a
  // failed export or copy, so it is reported like the empty files of the other formats.
  if (data.empty()) io_detail::fail(path, "empty file (0 bytes), expected OBJ data");
  // A UTF-8 byte order mark (editors on Windows add one) would turn the first keyword into an
  // unknown one, silently dropping the first vertex and shifting every index.
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (data.starts_with(kByteOrderMark)) data.remove_prefix(kByteOrderMark.size());
  // OBJ ignores statements it does not know, so without these checks any file (an image, a
  // binary, a PLY renamed .obj) would read as an empty mesh. OBJ is text: control bytes other
  // than blanks and line breaks (NUL in UTF-16 and binary data, for a start) mean it is not OBJ
  // (read_obj_serially).
  if (data.starts_with("\xFF\xFE") || data.starts_with("\xFE\xFF")) {
    io_detail::fail(path, "starts with a UTF-16 byte order mark; OBJ files are ASCII/UTF-8 text");
  }
  return data;
}

Mesh obj_mesh(const std::filesystem::path& path, std::span<const ObjData> runs, int threads) {
  Mesh mesh = ObjMeshBuilder(path, runs, threads).build();
  if (mesh.V.rows() == 0) io_detail::fail(path, "no vertices ('v' lines): not an OBJ mesh");
  return mesh;
}

}  // namespace

namespace io_detail {

Mesh parse_obj(const std::filesystem::path& path, std::string_view data) {
  return parse_obj(path, data, 0, kTextChunkBytes);
}

std::optional<Mesh> parse_obj_in_chunks(const std::filesystem::path& path, std::string_view data,
                                        int threads, std::size_t chunk_bytes) {
  const std::string_view text = obj_text(path, data);
  const std::optional<std::vector<ObjData>> runs =
      read_obj_chunks(path, text, threads, chunk_bytes);
  if (!runs) return std::nullopt;
  return obj_mesh(path, *runs, threads);
}

namespace {

/// A file without faces whose last line has no end is most likely an OBJ cut inside its vertex
/// block, not a point cloud: said through the execution's warning (the command prints it).
Mesh warn_if_cut_cloud(const std::filesystem::path& path, std::string_view data, Mesh mesh) {
  if (mesh.F.rows() == 0 && !data.empty() && data.back() != '\n') {
    if (const auto& warn = current_execution().warning) {
      warn(path.string() + ": no faces, and the last line has no end: the file may be cut "
           "short; read as a point cloud of " + std::to_string(mesh.V.rows()) + " vertices");
    }
  }
  return mesh;
}

}  // namespace

Mesh parse_obj(const std::filesystem::path& path, std::string_view data, int threads,
               std::size_t chunk_bytes) {
  if (std::optional<Mesh> mesh = parse_obj_in_chunks(path, data, threads, chunk_bytes)) {
    return warn_if_cut_cloud(path, data, std::move(*mesh));
  }
  const ObjData whole = read_obj_serially(path, obj_text(path, data));
  return warn_if_cut_cloud(path, data, obj_mesh(path, {&whole, 1}, threads));
}

Mesh read_obj(const std::filesystem::path& path, int threads) {
  return parse_obj(path, read_whole_file(path), threads, kTextChunkBytes);
}

}  // namespace io_detail

void write_obj(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options) {
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, ("write_obj: " + path.string()).c_str());
  const bool normals = mesh.has_normals();
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    // `v x y z` lines, then `vn x y z` lines.
    const auto append_rows = [&](std::string_view keyword, const RowMatrixX3d& rows) {
      io_detail::write_lines(sink, rows.rows(), 0, [&](std::string& out, std::int64_t i) {
        out += keyword;
        for (int c = 0; c < 3; ++c) {
          out += ' ';
          io_detail::append_real(out, rows(i, c), options.precision);
        }
        out += '\n';
      });
    };
    append_rows("v", mesh.V);
    if (normals) append_rows("vn", mesh.N);
    io_detail::write_lines(sink, mesh.F.rows(), 0, [&](std::string& out, std::int64_t f) {
      out += 'f';
      for (int c = 0; c < 3; ++c) {
        const auto index = static_cast<std::int64_t>(mesh.F(f, c)) + 1;
        out += ' ';
        io_detail::append_number(out, index);
        if (normals) {
          out += "//";
          io_detail::append_number(out, index);
        }
      }
      out += '\n';
    });
  });
}

}  // namespace focal
