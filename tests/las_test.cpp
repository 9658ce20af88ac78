// The ASPRS LAS reader (src/io/las.cpp) on files built byte by byte: versions 1.2 and 1.4,
// records longer than X Y Z, variable-length records before the points, and the errors of
// malformed files. (Checked once against laspy 2.7's files: the same doubles, docs/IO.md.)

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <string>
#include <type_traits>
#include <vector>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/format_readers.h"

namespace focal {
namespace {

Mesh parse(const std::string& bytes) { return io_detail::parse_las("scan.las", bytes); }

void expect_error(const std::string& bytes, const std::string& part) {
  try {
    (void)parse(bytes);
    ADD_FAILURE() << "no IoError for " << part;
  } catch (const IoError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("scan.las"), std::string::npos) << message;
    EXPECT_NE(message.find(part), std::string::npos) << message << " lacks " << part;
  }
}

template <class T>
void put(std::string& out, std::size_t at, T value) {
  auto bits = std::bit_cast<std::conditional_t<
      sizeof(T) == 8, std::uint64_t,
      std::conditional_t<sizeof(T) == 4, std::uint32_t,
                         std::conditional_t<sizeof(T) == 2, std::uint16_t, std::uint8_t>>>>(value);
  for (std::size_t b = 0; b < sizeof(T); ++b, bits >>= 8) {
    out[at + b] = static_cast<char>(bits & 0xff);
  }
}

/// A LAS file: `header` bytes of header (227 for 1.2, 375 for 1.4), `gap` bytes of
/// variable-length records, then the points' X Y Z (int32) in records of `record` bytes.
std::string las(int minor, std::size_t header, std::size_t gap, std::uint16_t record, int format,
                const std::vector<std::array<std::int32_t, 3>>& points) {
  // X Y Z are written even into records too short for them (an error case): room for them.
  const std::size_t tail = record < 12 ? 12 - record : 0;
  std::string out(header + gap + record * points.size() + tail, '\0');
  out.replace(0, 4, "LASF");
  put<std::uint8_t>(out, 24, 1);
  put<std::uint8_t>(out, 25, static_cast<std::uint8_t>(minor));
  put<std::uint16_t>(out, 94, static_cast<std::uint16_t>(header));
  put<std::uint32_t>(out, 96, static_cast<std::uint32_t>(header + gap));
  put<std::uint8_t>(out, 104, static_cast<std::uint8_t>(format));
  put<std::uint16_t>(out, 105, record);
  const double scale[3] = {0.01, 0.01, 0.001}, offset[3] = {500000, 5000000, -10};
  for (int d = 0; d < 3; ++d) {
    put<double>(out, 131 + 8 * static_cast<std::size_t>(d), scale[d]);
    put<double>(out, 155 + 8 * static_cast<std::size_t>(d), offset[d]);
  }
  if (minor >= 4) {
    put<std::uint64_t>(out, 247, points.size());  // the legacy count left 0, as 1.4 allows
  } else {
    put<std::uint32_t>(out, 107, static_cast<std::uint32_t>(points.size()));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int d = 0; d < 3; ++d)
      put<std::int32_t>(out, header + gap + i * record + 4 * d, points[i][d]);
  }
  return out;
}

TEST(LasRead, PositionsAreTheScaledAndOffsetIntegers) {
  const std::vector<std::array<std::int32_t, 3>> points{{0, 0, 0}, {-150, 2500, 123456}};
  for (const std::string& file : {las(2, 227, 0, 20, 0, points), las(4, 375, 54, 30, 6, points)}) {
    const Mesh m = parse(file);
    ASSERT_EQ(m.V.rows(), 2);
    EXPECT_EQ(m.F.rows(), 0);
    EXPECT_EQ(m.N.rows(), 0);
    EXPECT_EQ(m.V(0, 0), 500000.0);
    EXPECT_EQ(m.V(1, 0), -150 * 0.01 + 500000.0);
    EXPECT_EQ(m.V(1, 1), 2500 * 0.01 + 5000000.0);
    EXPECT_EQ(m.V(1, 2), 123456 * 0.001 - 10.0);
  }
}

TEST(LasRead, ErrorsSayWhatIsWrong) {
  const std::vector<std::array<std::int32_t, 3>> two{{1, 2, 3}, {4, 5, 6}};
  const std::string good = las(2, 227, 0, 20, 1, two);
  expect_error("PK\x03\x04", "not a LAS file");
  std::string v2 = good;
  v2[24] = 2;
  expect_error(v2, "LAS version 2.2");
  expect_error(las(2, 227, 0, 20, 0x80 | 1, two), "LAZ (LASzip-compressed) points are not read");
  expect_error(las(2, 227, 0, 20, 11, two), "point data format 11");
  expect_error(las(2, 227, 0, 8, 0, two), "point records of 8 bytes");
  expect_error(good.substr(0, good.size() - 1),
               "byte offset 227: header declares 2 points but the 39 bytes that follow can hold "
               "at most 1");
  std::string far = good;
  put<std::uint32_t>(far, 96, 1u << 30);
  expect_error(far, "offset to point data");
  std::string many = good;
  put<std::uint32_t>(many, 107, 1000);
  expect_error(many, "header declares 1000 points");
  std::string flat = good;
  put<double>(flat, 131, 0.0);
  expect_error(flat, "scale nonzero");
}

TEST(LasRead, ReadMeshTakesLasAndLazButWritesNeither) {
  EXPECT_EQ(mesh_format_from_path("a.LAS"), MeshFormat::las);
  EXPECT_EQ(mesh_format_from_path("a.laz"), MeshFormat::las);
  EXPECT_EQ(mesh_format_from_path("a.pcd"), MeshFormat::pcd);
  Mesh cloud;
  cloud.V = RowMatrixX3d::Zero(1, 3);
  cloud.F.resize(0, 3);
  const auto dir = std::filesystem::temp_directory_path();
  for (const char* name : {"focal_las_test.las", "focal_las_test.pcd"}) {
    try {
      write_mesh(dir / name, cloud);
      ADD_FAILURE() << "wrote " << name;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("is not supported"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(dir / name));
  }
}

}  // namespace
}  // namespace focal
