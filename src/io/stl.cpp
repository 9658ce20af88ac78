// STL reading, ascii and binary. STL stores triangles without shared vertices; the parsers return
// each facet's corners as new vertices in file order, and read_mesh then welds them
// (io/weld.cpp, ReadOptions). Facet normals are not vertex normals
// (and are often zero), so Mesh::N stays empty.

#include <algorithm>
#include <atomic>
#include <limits>
#include <optional>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/bytes.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/text_scan.h"

namespace focal {
namespace {

using io_detail::fail;
using io_detail::fail_at_line;
using io_detail::fail_at_offset;
using io_detail::load_little_endian;

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kFacetBytes = 50;  // normal, 3 corners (float32 x 12), attribute (uint16)

/// Skips blanks and `#` comment lines (some exporters write one before `solid`).
std::string_view skip_leading_comments(std::string_view data) {
  for (;;) {
    const std::size_t first = data.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos) return {};
    data.remove_prefix(first);
    if (data.front() != '#') return data;
    const std::size_t end = data.find('\n');
    if (end == std::string_view::npos) return {};
    data.remove_prefix(end + 1);
  }
}

/// Whether `text` starts with `keyword`, ignoring ASCII case (`SOLID` is as common as `solid`).
bool starts_with_keyword(std::string_view text, std::string_view keyword) {
  return text.size() >= keyword.size() &&
         io_detail::to_lower(text.substr(0, keyword.size())) == keyword;
}

bool starts_with_solid(std::string_view data) {
  return starts_with_keyword(skip_leading_comments(data), "solid");
}

/// True when the last non-blank line starts with "endsolid": an ascii file, even if its size
/// happens to match the binary layout.
bool ends_with_endsolid(std::string_view data) {
  const std::size_t last = data.find_last_not_of(" \t\r\n");
  if (last == std::string_view::npos) return false;
  const std::size_t line_start = data.find_last_of('\n', last);
  std::string_view line = data.substr(line_start == std::string_view::npos ? 0 : line_start + 1);
  line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
  return starts_with_keyword(line, "endsolid");
}

/// `data` without a UTF-8 byte order mark before an ascii `solid` (editors on Windows add one).
std::string_view without_byte_order_mark(std::string_view data) {
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (data.starts_with(kByteOrderMark) && starts_with_solid(data.substr(kByteOrderMark.size()))) {
    data.remove_prefix(kByteOrderMark.size());
  }
  return data;
}

/// Binary files often start with "solid" too, so the size is the deciding evidence: a binary
/// file is exactly 84 + 50 * (facet count in bytes 80..83) bytes long (and not ascii text that
/// ends with `endsolid` and happens to have that size).
bool binary_by_size(std::string_view data) {
  if (data.size() < kHeaderBytes + 4) return false;
  const std::uint64_t count = load_little_endian<std::uint32_t>(data.data() + kHeaderBytes);
  const bool size_matches = data.size() == kHeaderBytes + 4 + count * kFacetBytes;
  return size_matches && !(starts_with_solid(data) && ends_with_endsolid(data));
}

/// Ascii STL never contains NUL bytes; binary data (zero attribute bytes) nearly always does, so
/// a binary file with a wrong size gets the size error rather than an ascii syntax error.
bool ascii_text(std::string_view data) {
  return starts_with_solid(data) && data.find('\0') == std::string_view::npos;
}

Mesh read_binary(const std::filesystem::path& path, std::string_view data, int threads) {
  const std::uint64_t count = load_little_endian<std::uint32_t>(data.data() + kHeaderBytes);
  const std::uint64_t expected = kHeaderBytes + 4 + count * kFacetBytes;
  if (data.size() < expected) {
    const std::uint64_t complete = (data.size() - kHeaderBytes - 4) / kFacetBytes;
    fail_at_offset(path, kHeaderBytes + 4 + complete * kFacetBytes,
                   "file ends inside facet " + std::to_string(complete) + " of " +
                       std::to_string(count) + " (binary STL)");
  }
  if (data.size() > expected) {
    fail_at_offset(path, expected,
                   std::to_string(data.size() - expected) + " bytes follow the " +
                       std::to_string(count) + " facets the binary STL header declares");
  }
  if (3 * count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    fail(path, "too many facets for 32-bit vertex indices");
  }
  io_detail::require_memory_for(path, count,
                                3 * io_detail::kVertexBytes + io_detail::kTriangleBytes, "facets");
  Mesh mesh;
  const auto facets = static_cast<Eigen::Index>(count);
  mesh.V.resize(3 * facets, 3);
  mesh.F.resize(facets, 3);
  mesh.face_source.resize(facets);
  const char* facet_data = data.data() + kHeaderBytes + 4;
  detail::parallel_for(facets, threads, [&](std::int64_t f) {
    const char* p = facet_data + f * static_cast<std::int64_t>(kFacetBytes);
    for (int c = 0; c < 3; ++c) {
      const Eigen::Index v = 3 * f + c;
      for (int k = 0; k < 3; ++k) mesh.V(v, k) = load_little_endian<float>(p + 12 + 12 * c + 4 * k);
      mesh.F(f, c) = static_cast<std::int32_t>(v);
    }
    mesh.face_source[f] = static_cast<int>(f);
  });
  return mesh;
}

/// solid / facet normal / outer loop / vertex x3 (or more: fan-triangulated) / endloop /
/// endfacet / endsolid; several solids in one file are read one after the other.
class AsciiStlReader {
 public:
  enum class State { outside, solid, facet, loop, loop_done };

  /// A reader of a whole file (start outside a solid), or of a run of facets (start in a solid).
  explicit AsciiStlReader(const std::filesystem::path& path, State start = State::outside)
      : path_(path), state_(start) {}

  /// The whole file: its corners in file order, one vertex each.
  Mesh read(std::string_view text) {
    parse(text);
    if (state_ != State::outside) fail_at_line(path_, line_, "file ends inside a solid");
    return take_mesh();
  }

  /// A run of whole facets (facet_aligned_cuts): its corners and facets numbered from 0, as if
  /// the run were the file. IoError also where the run ends in another state than `end` (a
  /// facet cut apart, or a solid not closed): the serial read then judges the file.
  Mesh read_run(std::string_view text, State end) {
    parse(text);
    if (state_ != end) fail_at_line(path_, line_, "a run of facets ends in another state");
    return take_mesh();
  }

 private:
  void parse(std::string_view text) {
    io_detail::LineCursor cursor(text);
    std::string_view line;
    std::vector<std::string_view> tokens;
    while (cursor.next(line)) {
      line_ = cursor.line_number();
      io_detail::split_tokens(line, tokens);
      if (tokens.empty() || tokens[0].front() == '#') continue;  // blank or a comment line
      handle(tokens);
    }
  }

  Mesh take_mesh() {
    Mesh mesh;
    mesh.V = Eigen::Map<const RowMatrixX3d>(positions_.data(),
                                            static_cast<Eigen::Index>(positions_.size() / 3), 3);
    triangles_.move_into(mesh);
    return mesh;
  }

  void expect(State state, std::string_view keyword) const {
    if (state_ != state) {
      fail_at_line(path_, line_, "unexpected '" + std::string(keyword) + "'");
    }
  }

  /// Whether `token` is `keyword` (lower case), ignoring ASCII case, without a copy: this runs
  /// on every line.
  static bool is_keyword(std::string_view token, std::string_view keyword) {
    if (token.size() != keyword.size()) return false;
    for (std::size_t i = 0; i < token.size(); ++i) {
      const char c = token[i];
      if ((c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c) != keyword[i]) return false;
    }
    return true;
  }

  void handle(const std::vector<std::string_view>& tokens) {
    const std::string_view key = tokens[0];
    if (is_keyword(key, "vertex")) {  // the most common line first
      expect(State::loop, "vertex");
      add_vertex(tokens);
    } else if (is_keyword(key, "solid")) {
      expect(State::outside, "solid");
      state_ = State::solid;
    } else if (is_keyword(key, "facet")) {
      expect(State::solid, "facet");
      state_ = State::facet;
    } else if (is_keyword(key, "outer")) {
      expect(State::facet, "outer");
      state_ = State::loop;
      corners_.clear();
    } else if (is_keyword(key, "endloop")) {
      expect(State::loop, "endloop");
      state_ = State::loop_done;
    } else if (is_keyword(key, "endfacet")) {
      expect(State::loop_done, "endfacet");
      end_facet();
      state_ = State::solid;
    } else if (is_keyword(key, "endsolid")) {
      expect(State::solid, "endsolid");
      state_ = State::outside;
    } else {
      fail_at_line(path_, line_, "unknown keyword '" + std::string(tokens[0]) + "'");
    }
  }

  void add_vertex(const std::vector<std::string_view>& tokens) {
    if (tokens.size() != 4) {
      fail_at_line(path_, line_,
                   "expected 3 coordinates, got " + std::to_string(tokens.size() - 1));
    }
    for (std::size_t k = 1; k < 4; ++k) {
      double value = 0.0;
      if (!io_detail::parse_double(tokens[k], value)) {
        fail_at_line(path_, line_, io_detail::quoted(tokens[k]) + " is not a number");
      }
      positions_.push_back(value);
    }
    corners_.push_back(static_cast<std::int32_t>(positions_.size() / 3 - 1));
  }

  void end_facet() {
    if (corners_.size() < 3) {
      fail_at_line(path_, line_,
                   "facet " + std::to_string(facets_) + " has " + std::to_string(corners_.size()) +
                       " vertices; a face needs at least 3");
    }
    triangles_.add_polygon(corners_.data(), corners_.size(), facets_++);
  }

  const std::filesystem::path& path_;
  std::size_t line_ = 0;
  State state_;
  std::vector<double> positions_;
  std::vector<std::int32_t> corners_;
  std::int32_t facets_ = 0;
  io_detail::TriangleCollector triangles_;
};

/// Whether `line` (blanks first allowed) opens a facet: `facet` followed by a blank or nothing.
bool opens_facet(std::string_view line) {
  line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
  return starts_with_keyword(line, "facet") &&
         (line.size() == 5 || line[5] == ' ' || line[5] == '\t' || line[5] == '\r' ||
          line[5] == '\n');
}

/// Offsets that cut ascii STL text into runs of about `chunk_bytes` that start where a facet
/// opens: 0, then repeatedly the first line opening a facet at least `chunk_bytes` past the
/// previous cut, then text.size(). The cuts depend on the text only.
std::vector<std::size_t> facet_aligned_cuts(std::string_view text, std::size_t chunk_bytes) {
  std::vector<std::size_t> cuts{0};
  for (std::size_t next = chunk_bytes; next < text.size(); next = cuts.back() + chunk_bytes) {
    std::size_t newline = text.find('\n', next - 1);
    while (newline != std::string_view::npos && !opens_facet(text.substr(newline + 1))) {
      newline = text.find('\n', newline + 1);
    }
    if (newline == std::string_view::npos) break;
    cuts.push_back(newline + 1);
  }
  cuts.push_back(text.size());
  return cuts;
}

/// The runs' corners and facets, renumbered after those of the runs before, joined in file order.
Mesh join_runs(const std::vector<Mesh>& runs, int threads) {
  std::vector<Eigen::Index> corners(runs.size() + 1, 0), faces(runs.size() + 1, 0);
  std::vector<int> facets(runs.size() + 1, 0);
  for (std::size_t r = 0; r < runs.size(); ++r) {
    corners[r + 1] = corners[r] + runs[r].V.rows();
    faces[r + 1] = faces[r] + runs[r].F.rows();
    const bool any = runs[r].face_source.size() > 0;
    facets[r + 1] = facets[r] + (any ? runs[r].face_source.maxCoeff() + 1 : 0);
  }
  Mesh mesh;
  mesh.V.resize(corners.back(), 3);
  mesh.F.resize(faces.back(), 3);
  mesh.face_source.resize(faces.back());
  detail::parallel_chunks(static_cast<std::int64_t>(runs.size()), threads, [&](std::int64_t c) {
    const auto r = static_cast<std::size_t>(c);
    mesh.V.middleRows(corners[r], runs[r].V.rows()) = runs[r].V;
    mesh.F.middleRows(faces[r], runs[r].F.rows()) =
        runs[r].F.array() + static_cast<std::int32_t>(corners[r]);
    mesh.face_source.segment(faces[r], runs[r].F.rows()) = runs[r].face_source.array() + facets[r];
  });
  return mesh;
}

/// The ascii text read in runs of facets on `threads` threads: the serial reader's Mesh, or
/// nothing where it must judge the file (one run or one thread, an error in a run, a run that
/// does not end between facets, more facets or corners than 32-bit indices hold).
std::optional<Mesh> read_ascii_runs(const std::filesystem::path& path, std::string_view text,
                                    int threads, std::size_t chunk_bytes) {
  const std::vector<std::size_t> cuts = facet_aligned_cuts(text, chunk_bytes);
  const std::size_t runs = cuts.size() - 1;
  if (runs < 2 || detail::thread_count(threads) < 2) return std::nullopt;
  std::vector<Mesh> meshes(runs);
  std::atomic<bool> failed{false};
  using State = AsciiStlReader::State;
  detail::parallel_chunks(static_cast<std::int64_t>(runs), threads, [&](std::int64_t c) {
    const auto r = static_cast<std::size_t>(c);
    if (failed.load(std::memory_order_relaxed)) return;
    try {
      AsciiStlReader reader(path, r == 0 ? State::outside : State::solid);
      meshes[r] = reader.read_run(text.substr(cuts[r], cuts[r + 1] - cuts[r]),
                                  r + 1 == runs ? State::outside : State::solid);
    } catch (const IoError&) {
      failed.store(true, std::memory_order_relaxed);
    }
  });
  if (failed.load()) return std::nullopt;
  std::int64_t corners = 0;
  for (const Mesh& m : meshes) corners += m.V.rows();
  if (corners > std::numeric_limits<std::int32_t>::max()) return std::nullopt;
  return join_runs(meshes, threads);
}

}  // namespace

namespace io_detail {

Mesh read_stl(const std::filesystem::path& path, int threads) {
  return parse_stl(path, read_whole_file(path), threads, kTextChunkBytes);
}

Mesh parse_stl(const std::filesystem::path& path, std::string_view data) {
  return parse_stl(path, data, 0, kTextChunkBytes);
}

std::optional<Mesh> parse_stl_in_chunks(const std::filesystem::path& path, std::string_view data,
                                        int threads, std::size_t chunk_bytes) {
  data = without_byte_order_mark(data);
  if (binary_by_size(data) || !ascii_text(data)) return std::nullopt;
  return read_ascii_runs(path, data, threads, chunk_bytes);
}

Mesh parse_stl(const std::filesystem::path& path, std::string_view data, int threads,
               std::size_t chunk_bytes) {
  data = without_byte_order_mark(data);
  if (binary_by_size(data)) return read_binary(path, data, threads);
  if (ascii_text(data)) {
    std::optional<Mesh> mesh = read_ascii_runs(path, data, threads, chunk_bytes);
    return mesh ? std::move(*mesh) : AsciiStlReader(path).read(data);
  }
  if (data.size() < kHeaderBytes + 4) {
    fail(path, "too short for a binary STL (" + std::to_string(data.size()) + " bytes) and " +
                   (starts_with_solid(data) ? "not ascii text" : "does not start with 'solid'"));
  }
  if (const std::size_t solid = io_detail::to_lower(data.substr(0, 4096)).find("solid");
      solid != std::string_view::npos && data.find('\0') == std::string_view::npos) {
    // Text with `solid` after something other than blanks and # comments: an ascii STL with a
    // line before it, not the binary file whose size error would otherwise be reported.
    const std::string_view first = skip_leading_comments(data);
    fail(path,
         "an ascii STL must start with 'solid' (blank and # comment lines may "
         "come before it), but it starts with '" +
             std::string(first.substr(0, std::min(first.find('\n'), std::size_t{40}))) +
             "'; not a binary STL either (its size does not match its facet count)");
  }
  return read_binary(path, data, threads);  // reports the size mismatch
}

}  // namespace io_detail
}  // namespace focal
