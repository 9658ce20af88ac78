#include "io/text_scan.h"

#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numeric>

#include "core/parallel.h"
#include "focal/core/error.h"

namespace focal::io_detail {

bool LineCursor::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t end = text_.find('\n', pos_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  line = text_.substr(pos_, stop - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end == std::string_view::npos ? text_.size() : end + 1;
  ++next_line_;
  return true;
}

std::vector<std::size_t> line_aligned_cuts(std::string_view text, std::size_t chunk_bytes) {
  std::vector<std::size_t> cuts{0};
  std::size_t next = chunk_bytes;
  while (next < text.size()) {
    const std::size_t newline = text.find('\n', next);
    if (newline == std::string_view::npos || newline + 1 >= text.size()) break;
    cuts.push_back(newline + 1);
    next = cuts.back() + chunk_bytes;
  }
  cuts.push_back(text.size());
  return cuts;
}

namespace {
bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// split_tokens, stopping at a token that starts with '#' where `Comments`.
template <bool Comments>
void split(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && is_blank(line[i])) ++i;
    if (Comments && i < n && line[i] == '#') return;
    const std::size_t start = i;
    while (i < n && !is_blank(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}
}  // namespace

void split_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  split<false>(line, tokens);
}

void split_tokens_before_comment(std::string_view line, std::vector<std::string_view>& tokens) {
  // A '#' at the start of the line or after a blank is exactly a '#' that starts a token.
  split<true>(line, tokens);
}

namespace {
/// Offset of the first non-blank byte of `line`, or its size.
std::size_t first_non_blank(std::string_view line) {
  std::size_t i = 0;
  while (i < line.size() && is_blank(line[i])) ++i;
  return i;
}
}  // namespace

bool has_token(std::string_view line) { return first_non_blank(line) < line.size(); }

bool has_token_before_comment(std::string_view line) {
  const std::size_t i = first_non_blank(line);
  return i < line.size() && line[i] != '#';
}

bool parse_double(std::string_view token, double& value) {
  // from_chars rejects '+' but writers emit it ("+1.5e+00").
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ptr != end || token.empty()) return false;
  if (ec == std::errc()) return true;
  // errc::result_out_of_range for 1e999 and for 1e-400 alike; strtod tells them apart (the token
  // is already known to be a well-formed number) and rounds an underflow as C does.
  if (ec != std::errc::result_out_of_range) return false;
  const std::string copy(token);
  const double rounded = std::strtod(copy.c_str(), nullptr);
  if (std::isinf(rounded)) return false;
  value = rounded;
  return true;
}

bool parse_int(std::string_view token, std::int64_t& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end && !token.empty();
}

void TriangleCollector::reserve(std::size_t polygons) {
  corners_.reserve(3 * polygons);
  source_.reserve(polygons);
}

std::size_t fan_triangulate(const std::int32_t* corners, std::size_t count, std::int32_t polygon,
                            std::int32_t* triangles, std::int32_t* source) {
  for (std::size_t k = 1; k + 1 < count; ++k) {
    *triangles++ = corners[0];
    *triangles++ = corners[k];
    *triangles++ = corners[k + 1];
    *source++ = polygon;
  }
  return count < 3 ? 0 : count - 2;
}

void TriangleCollector::add_polygon(const std::int32_t* corners, std::size_t count,
                                    std::int32_t polygon) {
  const std::size_t triangles = count < 3 ? 0 : count - 2;
  corners_.resize(corners_.size() + 3 * triangles);
  source_.resize(source_.size() + triangles);
  (void)fan_triangulate(corners, count, polygon, corners_.data() + corners_.size() - 3 * triangles,
                        source_.data() + source_.size() - triangles);
}

void TriangleCollector::add_strip(const std::int32_t* corners, std::size_t count,
                                  std::int32_t polygon) {
  std::size_t start = 0;  // first corner of the current strip
  for (std::size_t k = 0; k < count; ++k) {
    if (corners[k] < 0) {
      start = k + 1;
      continue;
    }
    if (k < start + 2) continue;
    // Triangle k - start - 2 of the strip (counted from 0): the odd ones are reversed.
    const bool odd = (k - start) % 2 == 1;
    const std::int32_t a = corners[k - 2], b = corners[k - 1], c = corners[k];
    if (a == b || b == c || a == c) continue;
    corners_.push_back(odd ? b : a);
    corners_.push_back(odd ? a : b);
    corners_.push_back(c);
    source_.push_back(polygon);
  }
}

void TriangleCollector::move_into(Mesh& mesh) {
  const auto triangles = static_cast<Eigen::Index>(source_.size());
  mesh.F = Eigen::Map<const RowMatrixX3i>(corners_.data(), triangles, 3);
  mesh.face_source = Eigen::Map<const Eigen::VectorXi>(source_.data(), triangles);
  corners_ = {};
  source_ = {};
}

std::vector<std::int64_t> lines_before_runs(std::string_view body,
                                            std::span<const std::size_t> cuts, int threads,
                                            bool (*counts)(std::string_view)) {
  const std::size_t runs = cuts.size() - 1;
  std::vector<std::int64_t> first(runs + 1, 0);
  detail::parallel_chunks(static_cast<std::int64_t>(runs), threads, [&](std::int64_t c) {
    const auto r = static_cast<std::size_t>(c);
    LineCursor cursor(body.substr(cuts[r], cuts[r + 1] - cuts[r]));
    std::string_view line;
    while (cursor.next(line)) first[r + 1] += counts(line);
  });
  std::partial_sum(first.begin(), first.end(), first.begin());
  return first;
}

namespace {

/// The triangles (F, face_source) of runs read in parallel, one run after the other, into
/// mesh.F and mesh.face_source (copied on `threads` threads).
void join_triangles(std::span<const Mesh> runs, int threads, Mesh& mesh) {
  std::vector<Eigen::Index> start(runs.size() + 1, 0);
  for (std::size_t r = 0; r < runs.size(); ++r) start[r + 1] = start[r] + runs[r].F.rows();
  mesh.F.resize(start.back(), 3);
  mesh.face_source.resize(start.back());
  detail::parallel_chunks(static_cast<std::int64_t>(runs.size()), threads, [&](std::int64_t c) {
    const auto r = static_cast<std::size_t>(c);
    mesh.F.middleRows(start[r], runs[r].F.rows()) = runs[r].F;
    mesh.face_source.segment(start[r], runs[r].F.rows()) = runs[r].face_source;
  });
}

}  // namespace

bool read_runs_joined(std::size_t runs, int threads, Mesh& mesh,
                      const std::function<void(std::size_t, TriangleCollector&)>& read_run) {
  std::vector<Mesh> faces(runs);  // each run's triangles
  std::atomic<bool> failed{false};
  detail::parallel_chunks(static_cast<std::int64_t>(runs), threads, [&](std::int64_t c) {
    const auto r = static_cast<std::size_t>(c);
    if (failed.load(std::memory_order_relaxed)) return;
    try {
      TriangleCollector triangles;
      read_run(r, triangles);
      triangles.move_into(faces[r]);
    } catch (const IoError&) {
      failed.store(true, std::memory_order_relaxed);
    }
  });
  if (failed.load()) return false;
  join_triangles(faces, threads, mesh);
  return true;
}

}  // namespace focal::io_detail
