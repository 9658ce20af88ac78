// PCL's point-cloud format (.pcd, versions 0.5 to 0.7): a text header of keyword lines (VERSION,
// FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, then DATA), then the points:
//  - DATA ascii: one point per line, the fields' values in order (COUNT values for a field);
//  - DATA binary: one packed record per point, the fields' bytes in order, little-endian (PCL
//    writes its machine's order, little-endian on every platform it builds for);
//  - DATA binary_compressed: the sizes of the compressed and of the uncompressed data (two
//    little-endian uint32), then the data compressed with LZF, laid out field by field (every
//    point's x, then every point's y, ...; the padding fields "_" left out).
// x y z are the positions; normal_x normal_y normal_z (or nx ny nz) the normals when all three
// are fields; the other fields (rgb, intensity, curvature, ...) are skipped. An organised cloud's
// invalid points (NaN x y z) are read as they are, rows the estimators leave out. VIEWPOINT, the
// sensor's pose, is not applied (PCL's readers do not move the points by it either).

#include <array>
#include <cctype>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

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

/// One FIELDS entry with its SIZE, TYPE and COUNT, and where its first value lies: in a binary
/// record (`offset`, bytes) and in the compressed data's field-by-field layout (`plane`, bytes per
/// point before its plane).
struct Field {
  std::string name;
  int size = 0;
  char type = 0;  ///< 'F' float, 'I' signed, 'U' unsigned
  int count = 1;
  std::size_t offset = 0;
  std::size_t plane = 0;
};

enum class Data { ascii, binary, compressed };

struct Header {
  std::vector<Field> fields;
  std::uint64_t points = 0;
  Data data = Data::ascii;
  std::size_t body = 0;       ///< offset of the first byte after the DATA line
  std::size_t data_line = 0;  ///< its line number, for messages
  std::size_t record = 0;     ///< bytes per point in a binary record
  std::size_t planes = 0;     ///< bytes per point in the compressed layout (no padding)
};

std::int64_t positive_integer(const std::filesystem::path& path, std::size_t line,
                              std::string_view token, std::string_view what) {
  std::int64_t value = 0;
  if (!io_detail::parse_int(token, value) || value < 0) {
    fail_at_line(path, line,
                 std::string(what) + ": " + io_detail::quoted(token) + " is not a count >= 0");
  }
  return value;
}

/// The values of a SIZE, TYPE or COUNT line, one per field.
void expect_one_per_field(const std::filesystem::path& path, std::size_t line,
                          const std::vector<std::string_view>& tokens, std::size_t fields) {
  if (fields == 0) fail_at_line(path, line, io_detail::quoted(tokens[0]) + " before FIELDS");
  if (tokens.size() - 1 != fields) {
    fail_at_line(path, line,
                 io_detail::quoted(tokens[0]) + " has " + std::to_string(tokens.size() - 1) +
                     " values for " + std::to_string(fields) + " fields");
  }
}

void check_field_types(const std::filesystem::path& path, std::size_t line, const Field& f) {
  const bool integer = (f.type == 'I' || f.type == 'U') &&
                       (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8);
  const bool floating = f.type == 'F' && (f.size == 4 || f.size == 8);
  if (!integer && !floating) {
    fail_at_line(path, line,
                 "field " + io_detail::quoted(f.name) + " has TYPE " + std::string(1, f.type) +
                     " and SIZE " + std::to_string(f.size) +
                     " (expected F of 4 or 8 bytes, or I or U of 1, 2, 4 or 8)");
  }
}

/// A SIZE, TYPE or COUNT line's values into the fields.
void read_field_values(const std::filesystem::path& path, std::size_t line, std::string_view key,
                       const std::vector<std::string_view>& tokens, std::vector<Field>& fields) {
  expect_one_per_field(path, line, tokens, fields.size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string_view t = tokens[i + 1];
    if (key == "type") {
      if (t.size() != 1)
        fail_at_line(path, line, "TYPE " + io_detail::quoted(t) + " is not F, I or U");
      fields[i].type = static_cast<char>(std::toupper(static_cast<unsigned char>(t[0])));
      continue;
    }
    const std::int64_t v = positive_integer(path, line, t, key == "size" ? "SIZE" : "COUNT");
    if (v < 1 || v > 1024) {
      fail_at_line(
          path, line,
          io_detail::quoted(tokens[0]) + " " + io_detail::quoted(t) + " is not between 1 and 1024");
    }
    (key == "size" ? fields[i].size : fields[i].count) = static_cast<int>(v);
  }
}

Data data_kind(const std::filesystem::path& path, std::size_t line, std::string_view word) {
  const std::string kind = io_detail::to_lower(word);
  if (kind == "ascii") return Data::ascii;
  if (kind == "binary") return Data::binary;
  if (kind == "binary_compressed") return Data::compressed;
  fail_at_line(
      path, line,
      "DATA " + io_detail::quoted(word) + " (expected ascii, binary or binary_compressed)");
}

/// The header's counts, as the lines before DATA give them.
struct Counts {
  std::optional<std::uint64_t> width, height, points;
  bool sizes = false, types = false;
};

/// At the DATA line (`line`): checks that the header is complete and lays out the records.
void finish_header(const std::filesystem::path& path, std::size_t line, const Counts& c,
                   Header& h) {
  if (h.fields.empty()) fail_at_line(path, line, "no FIELDS line before DATA");
  if (!c.sizes || !c.types) fail_at_line(path, line, "no SIZE or TYPE line before DATA");
  for (Field& f : h.fields) check_field_types(path, line, f);
  if (c.points && c.width && c.height && *c.points != *c.width * *c.height) {
    fail_at_line(path, line,
                 "POINTS " + std::to_string(*c.points) + " is not WIDTH x HEIGHT " +
                     std::to_string(*c.width) + " x " + std::to_string(*c.height));
  }
  if (!c.points && !(c.width && c.height)) {
    fail_at_line(path, line, "no POINTS, nor WIDTH and HEIGHT");
  }
  h.points = c.points ? *c.points : *c.width * *c.height;
  for (Field& f : h.fields) {
    f.offset = h.record;
    h.record += static_cast<std::size_t>(f.size) * static_cast<std::size_t>(f.count);
    if (f.name == "_") continue;
    f.plane = h.planes;
    h.planes += static_cast<std::size_t>(f.size) * static_cast<std::size_t>(f.count);
  }
}

Header parse_header(const std::filesystem::path& path, std::string_view text) {
  Header h;
  Counts c;
  io_detail::LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (cursor.next(line)) {
    const std::size_t n = cursor.line_number();
    if (!line.empty() && line.front() == '#') continue;
    io_detail::split_tokens(line, tokens);
    if (tokens.empty()) continue;
    const std::string key = io_detail::to_lower(tokens[0]);
    if (key == "version" || key == "viewpoint") continue;
    if (key == "fields" || key == "columns") {
      if (tokens.size() < 2) fail_at_line(path, n, "FIELDS names no field");
      h.fields.clear();
      for (std::size_t i = 1; i < tokens.size(); ++i) h.fields.push_back({std::string(tokens[i])});
      c.sizes = c.types = false;  // a second FIELDS line needs its own
    } else if (key == "size" || key == "type" || key == "count") {
      read_field_values(path, n, key, tokens, h.fields);
      c.sizes = c.sizes || key == "size";
      c.types = c.types || key == "type";
    } else if (key == "width" || key == "height" || key == "points") {
      if (tokens.size() != 2)
        fail_at_line(path, n, io_detail::quoted(tokens[0]) + " takes one count");
      const auto v = static_cast<std::uint64_t>(positive_integer(path, n, tokens[1], tokens[0]));
      (key == "width" ? c.width : key == "height" ? c.height : c.points) = v;
    } else if (key == "data") {
      if (tokens.size() != 2) fail_at_line(path, n, "DATA takes one word");
      h.data = data_kind(path, n, tokens[1]);
      h.body = cursor.offset();
      h.data_line = n;
      finish_header(path, n, c, h);
      return h;
    } else {
      fail_at_line(path, n, "unknown header keyword " + io_detail::quoted(tokens[0]));
    }
  }
  fail(path, "the header has no DATA line (not a PCD file?)");
}

/// The fields read: x y z, and the normal's three when all are there.
struct Roles {
  std::array<const Field*, 3> position{};
  std::optional<std::array<const Field*, 3>> normal;
};

Roles roles_of(const std::filesystem::path& path, const Header& h) {
  const auto find = [&](std::string_view a, std::string_view b) -> const Field* {
    for (const Field& f : h.fields) {
      if (f.name == a || f.name == b) return &f;
    }
    return nullptr;
  };
  Roles r;
  r.position = {find("x", "x"), find("y", "y"), find("z", "z")};
  const std::array<const Field*, 3> normal{find("normal_x", "nx"), find("normal_y", "ny"),
                                           find("normal_z", "nz")};
  if (normal[0] && normal[1] && normal[2]) r.normal = normal;
  for (int d = 0; d < 3; ++d) {
    if (!r.position[d]) fail(path, std::string("the FIELDS have no ") + "xyz"[d]);
  }
  return r;
}

template <class T>
double value_at(const unsigned char* p) {
  return static_cast<double>(io_detail::load_little_endian<T>(p));
}

/// A little-endian value of a field's type from its bytes (the sizes checked with the header).
double decode(const unsigned char* p, const Field& f) {
  const bool is_signed = f.type == 'I';
  switch (f.size) {
    case 1:
      return is_signed ? value_at<std::int8_t>(p) : value_at<std::uint8_t>(p);
    case 2:
      return is_signed ? value_at<std::int16_t>(p) : value_at<std::uint16_t>(p);
    case 4:
      if (f.type == 'F') return value_at<float>(p);
      return is_signed ? value_at<std::int32_t>(p) : value_at<std::uint32_t>(p);
    default:
      if (f.type == 'F') return value_at<double>(p);
      return is_signed ? value_at<std::int64_t>(p) : value_at<std::uint64_t>(p);
  }
}

/// LZF decompression (the format of liblzf's lzf_compress, which PCL uses): a control byte c
/// below 32 copies the next c + 1 bytes; otherwise it is a back reference, length (c >> 5) + 2
/// (7 + 2 takes one more byte for the length), distance ((c & 31) << 8 | next byte) + 1 into the
/// output written so far. Any reference or copy outside the buffers is an error.
std::vector<unsigned char> lzf_decompress(const std::filesystem::path& path,
                                          const unsigned char* in, std::size_t in_size,
                                          std::size_t out_size) {
  std::vector<unsigned char> out(out_size);
  std::size_t ip = 0, op = 0;
  const auto corrupt = [&] { fail(path, "the compressed data is corrupt (LZF)"); };
  while (ip < in_size) {
    const unsigned c = in[ip++];
    if (c < 32) {
      const std::size_t length = c + 1;
      if (ip + length > in_size || op + length > out_size) corrupt();
      std::memcpy(out.data() + op, in + ip, length);
      ip += length;
      op += length;
      continue;
    }
    std::size_t length = c >> 5;
    if (length == 7) {
      if (ip >= in_size) corrupt();
      length += in[ip++];
    }
    length += 2;
    if (ip >= in_size) corrupt();
    const std::size_t distance = ((c & 31u) << 8 | in[ip++]) + 1;
    if (distance > op || op + length > out_size) corrupt();
    for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - distance];  // may overlap
  }
  if (op != out_size) {
    fail(path, "the compressed data gives " + std::to_string(op) + " bytes, the header " +
                   std::to_string(out_size));
  }
  return out;
}

class PcdReader {
 public:
  PcdReader(const std::filesystem::path& path, std::string_view text)
      : path_(path),
        text_(text),
        header_(parse_header(path, text)),
        roles_(roles_of(path, header_)) {}

  Mesh read() {
    switch (header_.data) {
      case Data::ascii:
        read_ascii();
        break;
      case Data::binary:
        read_binary();
        break;
      case Data::compressed:
        read_compressed();
        break;
    }
    const auto n = static_cast<Eigen::Index>(header_.points);
    Mesh mesh;
    mesh.V = Eigen::Map<const RowMatrixX3d>(positions_.data(), n, 3);
    if (roles_.normal) mesh.N = Eigen::Map<const RowMatrixX3d>(normals_.data(), n, 3);
    mesh.F.resize(0, 3);
    return mesh;
  }

 private:
  /// Where the points start, for the messages of the checks on their count.
  std::string body_line() const { return "line " + std::to_string(header_.data_line + 1); }

  /// Called once the body is known to hold the points (so the count is bounded by its bytes).
  void reserve_points() {
    const std::uint64_t normal_bytes = roles_.normal ? io_detail::kNormalBytes : 0;
    io_detail::require_memory_for(path_, header_.points, io_detail::kVertexBytes + normal_bytes,
                                  "points");
    positions_.reserve(3 * header_.points);
    if (roles_.normal) normals_.reserve(3 * header_.points);
  }

  void read_ascii() {
    std::size_t values = 0;
    for (const Field& f : header_.fields) values += static_cast<std::size_t>(f.count);
    // Only a bound against absurd counts (allocation): one byte less than a line of one-digit
    // values per point, so that a file short of a value or a line gets the row's own message.
    io_detail::check_count_fits(path_, body_line(), header_.points, 2 * values - 1,
                                text_.size() - header_.body, "points");
    reserve_points();
    io_detail::LineCursor cursor(text_.substr(header_.body), header_.data_line + 1);
    std::string_view line;
    std::vector<std::string_view> tokens;
    std::uint64_t read = 0;
    while (cursor.next(line)) {
      io_detail::split_tokens(line, tokens);
      if (tokens.empty()) continue;
      if (read == header_.points) {
        fail_at_line(path_, cursor.line_number(),
                     "more points than the header's " + std::to_string(header_.points));
      }
      if (tokens.size() != values) {
        fail_at_line(path_, cursor.line_number(),
                     "expected " + std::to_string(values) + " values, found " +
                         std::to_string(tokens.size()));
      }
      const auto value = [&](const Field* f) {
        const std::size_t at = value_index(*f);
        double v = 0.0;
        if (!io_detail::parse_double(tokens[at], v)) {
          fail_at_line(path_, cursor.line_number(),
                       "field " + io_detail::quoted(f->name) + ": " +
                           io_detail::quoted(tokens[at]) + " is not a number");
        }
        return v;
      };
      for (const Field* f : roles_.position) positions_.push_back(value(f));
      if (roles_.normal) {
        for (const Field* f : *roles_.normal) normals_.push_back(value(f));
      }
      ++read;
    }
    if (read != header_.points) {
      fail(path_, "the header says " + std::to_string(header_.points) + " points, the file has " +
                      std::to_string(read));
    }
  }

  /// Index of a field's first value among a text line's values.
  [[nodiscard]] std::size_t value_index(const Field& f) const {
    std::size_t at = 0;
    for (const Field& g : header_.fields) {
      if (&g == &f) return at;
      at += static_cast<std::size_t>(g.count);
    }
    return at;
  }

  void read_binary() {
    const std::size_t available = text_.size() - header_.body;
    io_detail::check_records_fit(path_, body_line(), header_.points, header_.record, available,
                                 "points");
    reserve_points();
    const auto* body = reinterpret_cast<const unsigned char*>(text_.data() + header_.body);
    for (std::uint64_t i = 0; i < header_.points; ++i) {
      const unsigned char* record = body + i * header_.record;
      for (const Field* f : roles_.position) positions_.push_back(decode(record + f->offset, *f));
      if (roles_.normal) {
        for (const Field* f : *roles_.normal) normals_.push_back(decode(record + f->offset, *f));
      }
    }
  }

  void read_compressed() {
    const std::size_t available = text_.size() - header_.body;
    if (available < 8) fail(path_, "the compressed data has no sizes (8 bytes after DATA)");
    const auto* sizes = reinterpret_cast<const unsigned char*>(text_.data() + header_.body);
    const std::size_t compressed = io_detail::load_little_endian<std::uint32_t>(sizes);
    const std::size_t uncompressed = io_detail::load_little_endian<std::uint32_t>(sizes + 4);
    if (compressed > available - 8) {
      fail(path_, "the compressed data's size " + std::to_string(compressed) + " exceeds the " +
                      std::to_string(available - 8) + " bytes that follow");
    }
    if (static_cast<std::uint64_t>(uncompressed) != header_.points * header_.planes) {
      fail(path_, "the uncompressed size " + std::to_string(uncompressed) + " is not the " +
                      std::to_string(header_.points) + " points' " +
                      std::to_string(header_.points * header_.planes) + " bytes");
    }
    // LZF gives at most 264 bytes per 3 it reads: a larger size is corrupt, and checked before
    // it is allocated.
    if (uncompressed / 88 > compressed + 1) fail(path_, "the compressed data is corrupt (LZF)");
    io_detail::check_records_fit(path_, body_line(), header_.points, header_.planes, uncompressed,
                                 "points");
    reserve_points();
    const std::vector<unsigned char> data =
        lzf_decompress(path_, sizes + 8, compressed, uncompressed);
    const auto at = [&](const Field* f, std::uint64_t i) {
      const std::size_t width =
          static_cast<std::size_t>(f->size) * static_cast<std::size_t>(f->count);
      return decode(data.data() + header_.points * f->plane + i * width, *f);
    };
    for (std::uint64_t i = 0; i < header_.points; ++i) {
      for (const Field* f : roles_.position) positions_.push_back(at(f, i));
      if (roles_.normal) {
        for (const Field* f : *roles_.normal) normals_.push_back(at(f, i));
      }
    }
  }

  const std::filesystem::path& path_;
  std::string_view text_;
  Header header_;
  Roles roles_;
  std::vector<double> positions_;
  std::vector<double> normals_;
};

}  // namespace

namespace io_detail {

Mesh parse_pcd(const std::filesystem::path& path, std::string_view data) {
  return PcdReader(path, data).read();
}

Mesh read_pcd(const std::filesystem::path& path) {
  const FileBytes bytes = read_whole_file(path);
  return parse_pcd(path, bytes.view());
}

}  // namespace io_detail
}  // namespace focal
