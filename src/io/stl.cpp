// STL reading, ascii and binary. STL stores triangles without shared vertices; the parsers return
// each facet's corners as new vertices in file order, and read_mesh then welds them
// (io/weld.cpp, ReadOptions). Facet normals are not vertex normals
// (and are often zero), so Mesh::N stays empty.

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/detail.h"

namespace focal {
namespace {

using io_detail::fail;
using io_detail::fail_at_line;
using io_detail::fail_at_offset;

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kFacetBytes = 50;  // normal, 3 corners (float32 x 12), attribute (uint16)

std::uint32_t load_u32_le(const char* p) {
  unsigned char b[4];
  std::memcpy(b, p, 4);
  return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
         static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
}

float load_f32_le(const char* p) { return std::bit_cast<float>(load_u32_le(p)); }

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

Mesh read_binary(const std::filesystem::path& path, std::string_view data) {
  const std::uint64_t count = load_u32_le(data.data() + kHeaderBytes);
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
  Mesh mesh;
  const auto facets = static_cast<Eigen::Index>(count);
  mesh.V.resize(3 * facets, 3);
  mesh.F.resize(facets, 3);
  mesh.face_source.resize(facets);
  const char* p = data.data() + kHeaderBytes + 4;
  for (Eigen::Index f = 0; f < facets; ++f, p += kFacetBytes) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Index v = 3 * f + c;
      for (int k = 0; k < 3; ++k) mesh.V(v, k) = load_f32_le(p + 12 + 12 * c + 4 * k);
      mesh.F(f, c) = static_cast<std::int32_t>(v);
    }
    mesh.face_source[f] = static_cast<int>(f);
  }
  return mesh;
}

/// solid / facet normal / outer loop / vertex x3 (or more: fan-triangulated) / endloop /
/// endfacet / endsolid; several solids in one file are read one after the other.
class AsciiStlReader {
 public:
  explicit AsciiStlReader(const std::filesystem::path& path) : path_(path) {}

  Mesh read(std::string_view text) {
    io_detail::LineCursor cursor(text);
    std::string_view line;
    std::vector<std::string_view> tokens;
    while (cursor.next(line)) {
      line_ = cursor.line_number();
      io_detail::split_tokens(line, tokens);
      if (tokens.empty() || tokens[0].front() == '#') continue;  // blank or a comment line
      handle(tokens);
    }
    if (state_ != State::outside) fail_at_line(path_, line_, "file ends inside a solid");
    Mesh mesh;
    mesh.V = Eigen::Map<const RowMatrixX3d>(positions_.data(),
                                            static_cast<Eigen::Index>(positions_.size() / 3), 3);
    triangles_.move_into(mesh);
    return mesh;
  }

 private:
  enum class State { outside, solid, facet, loop, loop_done };

  void expect(State state, std::string_view keyword) const {
    if (state_ != state) {
      fail_at_line(path_, line_, "unexpected '" + std::string(keyword) + "'");
    }
  }

  void handle(const std::vector<std::string_view>& tokens) {
    const std::string key = io_detail::to_lower(tokens[0]);
    if (key == "solid") {
      expect(State::outside, key);
      state_ = State::solid;
    } else if (key == "facet") {
      expect(State::solid, key);
      state_ = State::facet;
    } else if (key == "outer") {
      expect(State::facet, key);
      state_ = State::loop;
      corners_.clear();
    } else if (key == "vertex") {
      expect(State::loop, key);
      add_vertex(tokens);
    } else if (key == "endloop") {
      expect(State::loop, key);
      state_ = State::loop_done;
    } else if (key == "endfacet") {
      expect(State::loop_done, key);
      end_facet();
      state_ = State::solid;
    } else if (key == "endsolid") {
      expect(State::solid, key);
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
  State state_ = State::outside;
  std::vector<double> positions_;
  std::vector<std::int32_t> corners_;
  std::int32_t facets_ = 0;
  io_detail::TriangleCollector triangles_;
};

}  // namespace

namespace io_detail {

Mesh read_stl(const std::filesystem::path& path) { return parse_stl(path, read_whole_file(path)); }

Mesh parse_stl(const std::filesystem::path& path, std::string_view data) {
  // A UTF-8 byte order mark before an ascii `solid` (editors on Windows add one).
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (data.starts_with(kByteOrderMark) && starts_with_solid(data.substr(kByteOrderMark.size()))) {
    data.remove_prefix(kByteOrderMark.size());
  }
  // Binary files often start with "solid" too, so the size is the deciding evidence: a binary
  // file is exactly 84 + 50 * (facet count in bytes 80..83) bytes long.
  if (data.size() >= kHeaderBytes + 4) {
    const std::uint64_t count = load_u32_le(data.data() + kHeaderBytes);
    const bool size_matches = data.size() == kHeaderBytes + 4 + count * kFacetBytes;
    if (size_matches && !(starts_with_solid(data) && ends_with_endsolid(data))) {
      return read_binary(path, data);
    }
  }
  // Ascii STL never contains NUL bytes; binary data (zero attribute bytes) nearly always does,
  // so a binary file with a wrong size gets the size error rather than an ascii syntax error.
  if (starts_with_solid(data) && data.find('\0') == std::string_view::npos) {
    return AsciiStlReader(path).read(data);
  }
  if (data.size() < kHeaderBytes + 4) {
    fail(path, "too short for a binary STL (" + std::to_string(data.size()) + " bytes) and " +
                   (starts_with_solid(data) ? "not ascii text" : "does not start with 'solid'"));
  }
  return read_binary(path, data);  // reports the size mismatch
}

}  // namespace io_detail
}  // namespace focal
