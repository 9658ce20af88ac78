// PCL's .pcd reader (src/io/pcd.cpp) on files built byte by byte: ascii, binary and
// binary_compressed (LZF) bodies, fields of every type in any order, skipped fields, organised
// clouds with NaN points, and the errors of malformed files (what and where).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <type_traits>
#include <vector>

#include "focal/core/error.h"
#include "io/format_readers.h"

namespace focal {
namespace {

Mesh parse(const std::string& bytes) { return io_detail::parse_pcd("cloud.pcd", bytes); }

/// The error of parsing `bytes`, which must be an IoError naming the file.
std::string error_of(const std::string& bytes) {
  try {
    (void)parse(bytes);
  } catch (const IoError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cloud.pcd"), std::string::npos) << message;
    return message;
  }
  ADD_FAILURE() << "no IoError";
  return {};
}

/// That parsing `bytes` fails with a message holding `part`.
void expect_error(const std::string& bytes, const std::string& part) {
  const std::string message = error_of(bytes);
  EXPECT_NE(message.find(part), std::string::npos)
      << "message \"" << message << "\" lacks \"" << part << "\"";
}

std::string header(const std::string& fields, const std::string& size, const std::string& type,
                   int points, const std::string& data, const std::string& count = "") {
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " +
         size + "\nTYPE " + type + "\n" + (count.empty() ? "" : "COUNT " + count + "\n") +
         "WIDTH " + std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         std::to_string(points) + "\nDATA " + data + "\n";
}

/// Little-endian bytes of a value.
template <class T>
std::string bytes_of(T value) {
  std::string out(sizeof(T), '\0');
  auto bits = std::bit_cast<
      std::conditional_t<sizeof(T) == 8, std::uint64_t,
                         std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint16_t>>>(value);
  for (std::size_t b = 0; b < sizeof(T); ++b, bits >>= 8) out[b] = static_cast<char>(bits & 0xff);
  return out;
}

void expect_rows(const RowMatrixX3d& M, std::initializer_list<std::array<double, 3>> rows) {
  ASSERT_EQ(M.rows(), static_cast<Eigen::Index>(rows.size()));
  Eigen::Index i = 0;
  for (const auto& r : rows) {
    for (int d = 0; d < 3; ++d) {
      if (std::isnan(r[d])) {
        EXPECT_TRUE(std::isnan(M(i, d))) << i << "," << d;
      } else {
        EXPECT_EQ(M(i, d), r[d]) << i << "," << d;
      }
    }
    ++i;
  }
}

TEST(PcdRead, AsciiWithSkippedFieldsAndACountAboveOne) {
  // rgb and a 2-value field between the position and the normal, as PCL lays out its types.
  const Mesh m =
      parse(header("x y z rgb pair normal_x normal_y normal_z curvature", "4 4 4 4 4 4 4 4 4",
                   "F F F U F F F F F", 2, "ascii", "1 1 1 1 2 1 1 1 1") +
            "0.5 -1 2 4291322930 7 8 0 0 1 0.25\n"
            "nan nan nan 0 0 0 0 1 0 0\n");
  expect_rows(m.V, {{0.5, -1, 2}, {NAN, NAN, NAN}});
  expect_rows(m.N, {{0, 0, 1}, {0, 1, 0}});
  EXPECT_EQ(m.F.rows(), 0);
}

TEST(PcdRead, BinaryRecordsOfEveryTypeInAnyOrder) {
  // y double, x float, z int16, an unused uint8, then the normal as nx ny nz floats.
  std::string body;
  const double y[2] = {2.5, -1e-3};
  const float x[2] = {1.25f, 3.0f};
  const std::int16_t z[2] = {-7, 300};
  for (int i = 0; i < 2; ++i) {
    body += bytes_of(y[i]) + bytes_of(x[i]) + bytes_of(z[i]) + std::string(1, '\x05');
    body += bytes_of(0.0f) + bytes_of(i == 0 ? 1.0f : -1.0f) + bytes_of(0.0f);
  }
  const Mesh m =
      parse(header("y x z label nx ny nz", "8 4 2 1 4 4 4", "F F I U F F F", 2, "binary") + body);
  expect_rows(m.V, {{1.25, 2.5, -7}, {3.0, -1e-3, 300}});
  expect_rows(m.N, {{0, 1, 0}, {0, -1, 0}});
}

/// LZF data of literal runs only (a control byte c < 32 copies c + 1 bytes): valid input for
/// any decoder of the format.
std::string lzf_literals(const std::string& data) {
  std::string out;
  for (std::size_t at = 0; at < data.size(); at += 32) {
    const std::size_t n = std::min<std::size_t>(32, data.size() - at);
    out += static_cast<char>(n - 1);
    out += data.substr(at, n);
  }
  return out;
}

std::string compressed_body(const std::string& lzf, std::size_t uncompressed) {
  return bytes_of(static_cast<std::uint32_t>(lzf.size())) +
         bytes_of(static_cast<std::uint32_t>(uncompressed)) + lzf;
}

TEST(PcdRead, CompressedFieldByFieldWithABackReference) {
  // Two points x y z float, padding "_" left out of the planes: x plane, y plane = x plane (a
  // back reference of 8 bytes at distance 8), z plane.
  const std::string xs = bytes_of(1.5f) + bytes_of(-2.0f);
  const std::string zs = bytes_of(4.0f) + bytes_of(8.0f);
  std::string lzf = std::string(1, '\x07') + xs;  // 8 literal bytes
  lzf += std::string(1, static_cast<char>((8 - 2) << 5)) + std::string(1, '\x07');
  lzf += std::string(1, '\x07') + zs;
  const Mesh m = parse(header("x y z _", "4 4 4 4", "F F F U", 2, "binary_compressed") +
                       compressed_body(lzf, 24));
  expect_rows(m.V, {{1.5, 1.5, 4}, {-2, -2, 8}});
  EXPECT_EQ(m.N.rows(), 0);
}

TEST(PcdRead, CompressedLiteralsAndALongRun) {
  // 40 equal bytes: one literal, then a reference of length 39 at distance 1 (length 7 + 30 + 2).
  const std::string plane(40, '\0');  // ten zero floats per axis
  const std::string run =
      std::string(1, '\x00') + std::string(1, '\0') + "\xE0\x1E" + std::string(1, '\0');
  const std::string lzf = run + lzf_literals(plane) + run;
  const Mesh m =
      parse(header("x y z", "4 4 4", "F F F", 10, "binary_compressed") + compressed_body(lzf, 120));
  ASSERT_EQ(m.V.rows(), 10);
  EXPECT_EQ(m.V.cwiseAbs().maxCoeff(), 0.0);
}

TEST(PcdRead, ErrorsSayWhatAndWhere) {
  const std::string xyz = header("x y z", "4 4 4", "F F F", 2, "binary");
  // One byte short (the fuzzer's first finding: a read past the end).
  expect_error(xyz + std::string(23, '\0'),
               "header declares 2 points but the 23 bytes that follow can hold at most 1");
  expect_error(xyz + std::string(20, '\0'),
               "line 11: header declares 2 points but the 20 bytes that follow can hold at most 1");
  expect_error(header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n4 5\n",
               "line 12: expected 3 values, found 2");
  expect_error(header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2 3\n4 5 6\n",
               "more points than the header's 1");
  expect_error(header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n\n\n\n\n",
               "the header says 2 points, the file has 1");
  expect_error(header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 two 3\n",
               "field 'y': 'two' is not a number");
  expect_error(header("x y", "4 4", "F F", 1, "ascii") + "1 2\n", "no z");
  expect_error(header("x y z", "4 4", "F F F", 1, "ascii"), "line 4");
  expect_error(header("x y z", "4 4 3", "F F F", 1, "ascii"), "TYPE F and SIZE 3");
  expect_error(header("x y z", "4 4 4", "F F F", 1, "lzma"), "DATA 'lzma'");
  expect_error(
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\n"
      "POINTS 2\nDATA ascii\n",
      "POINTS 2 is not WIDTH x HEIGHT 3 x 1");
  expect_error("ply\nformat ascii 1.0\n", "unknown header keyword 'ply'");
  expect_error("# only a comment\n", "no DATA line");
  const std::string c = header("x y z", "4 4 4", "F F F", 1, "binary_compressed");
  // A reference before the start of the output; a size that is not the points'; a size past
  // the end of the file; an expansion no LZF data can give.
  expect_error(c + compressed_body("\x20\x05", 12), "corrupt");
  expect_error(c + compressed_body(lzf_literals(std::string(12, '\0')), 16),
               "is not the 1 points' 12 bytes");
  expect_error(c + bytes_of(std::uint32_t{99}) + bytes_of(std::uint32_t{12}), "exceeds");
  const std::string many = header("x y z", "4 4 4", "F F F", 100000000, "binary_compressed");
  expect_error(many + compressed_body(std::string("\x00\x01", 2), 1200000000), "corrupt");
}

}  // namespace
}  // namespace focal
