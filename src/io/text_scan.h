#pragma once
/// \file text_scan.h
/// Scanning text files in parallel runs of whole lines: lines with their numbers, tokens and
/// numbers in them, and the triangles (fans of polygons, strips) that the runs collect and join
/// in file order.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "focal/core/mesh.h"

namespace focal::io_detail {

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

}  // namespace focal::io_detail
