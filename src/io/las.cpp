// ASPRS LAS (.las, versions 1.0 to 1.4), the LiDAR exchange format: a binary public header
// block, variable-length records (skipped), then fixed-length point records whose first 12
// bytes are X, Y, Z as little-endian int32, scaled and offset by the header (x = X * x_scale +
// x_offset). Every point data format (0 to 10) starts so, which is all focal reads: LAS has no
// normals, so they are estimated from the positions (an airborne scan is one-sided: --viewpoint
// above it orients them). LAZ (LASzip-compressed, point format with bit 7 or 6 set) is an error
// naming a way out.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/bytes.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"

namespace focal {
namespace {

using io_detail::fail;

/// Byte offsets in the public header block (LAS 1.4 specification, table 3).
constexpr std::size_t kVersionMajor = 24;
constexpr std::size_t kVersionMinor = 25;
constexpr std::size_t kHeaderSize = 94;
constexpr std::size_t kOffsetToPoints = 96;
constexpr std::size_t kPointFormat = 104;
constexpr std::size_t kRecordLength = 105;
constexpr std::size_t kLegacyCount = 107;
constexpr std::size_t kScale = 131;    ///< x, y, z float64
constexpr std::size_t kOffset = 155;   ///< x, y, z float64
constexpr std::size_t kCount14 = 247;  ///< LAS 1.4: uint64 number of point records
constexpr std::size_t kHeaderBytes10 = 227;
constexpr std::size_t kHeaderBytes14 = 375;

/// The little-endian T at byte `at` of the file.
template <class T>
T load_at(std::string_view data, std::size_t at) {
  return io_detail::load_little_endian<T>(data.data() + at);
}

struct LasHeader {
  std::size_t offset = 0;  ///< of the first point record
  std::size_t record = 0;  ///< bytes per point record
  std::uint64_t points = 0;
  double scale[3] = {1, 1, 1};
  double shift[3] = {0, 0, 0};
};

LasHeader parse_header(const std::filesystem::path& path, std::string_view data) {
  if (data.size() < kHeaderBytes10 || data.substr(0, 4) != "LASF") {
    fail(path, "not a LAS file (no 'LASF' signature and 227-byte header)");
  }
  const int major = static_cast<unsigned char>(data[kVersionMajor]);
  const int minor = static_cast<unsigned char>(data[kVersionMinor]);
  if (major != 1 || minor > 4) {
    fail(path, "LAS version " + std::to_string(major) + "." + std::to_string(minor) +
                   " (expected 1.0 to 1.4)");
  }
  LasHeader h;
  const auto header_size = load_at<std::uint16_t>(data, kHeaderSize);
  h.offset = load_at<std::uint32_t>(data, kOffsetToPoints);
  const int format = static_cast<unsigned char>(data[kPointFormat]);
  h.record = load_at<std::uint16_t>(data, kRecordLength);
  if (format & 0xC0) {
    fail(path,
         "LAZ (LASzip-compressed) points are not read; decompress the file first (laszip "
         "-i in.laz -o out.las, or pdal translate in.laz out.las)");
  }
  if (format > 10)
    fail(path, "point data format " + std::to_string(format) + " (expected 0 to 10)");
  if (header_size < kHeaderBytes10 || h.offset < header_size || h.offset > data.size()) {
    fail(path, "header size " + std::to_string(header_size) + " and offset to point data " +
                   std::to_string(h.offset) + " do not fit the file's " +
                   std::to_string(data.size()) + " bytes");
  }
  if (h.record < 12) {
    fail(path, "point records of " + std::to_string(h.record) + " bytes (X, Y, Z need 12)");
  }
  h.points = load_at<std::uint32_t>(data, kLegacyCount);
  if (minor >= 4 && header_size >= kHeaderBytes14) {
    const auto count = load_at<std::uint64_t>(data, kCount14);
    if (count != 0) h.points = count;
  }
  for (int d = 0; d < 3; ++d) {
    h.scale[d] = load_at<double>(data, kScale + 8 * static_cast<std::size_t>(d));
    h.shift[d] = load_at<double>(data, kOffset + 8 * static_cast<std::size_t>(d));
    if (!std::isfinite(h.scale[d]) || h.scale[d] == 0.0 || !std::isfinite(h.shift[d])) {
      fail(path,
           std::string("the ") + "xyz"[d] + " scale and offset must be finite, the scale nonzero");
    }
  }
  io_detail::check_records_fit(path, "byte offset " + std::to_string(h.offset), h.points, h.record,
                               data.size() - h.offset, "points");
  io_detail::require_memory_for(path, h.points, io_detail::kVertexBytes, "points");
  return h;
}

}  // namespace

namespace io_detail {

Mesh parse_las(const std::filesystem::path& path, std::string_view data) {
  const LasHeader h = parse_header(path, data);
  const auto n = static_cast<Eigen::Index>(h.points);
  Mesh mesh;
  mesh.V.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::size_t at = h.offset + static_cast<std::size_t>(i) * h.record;
    for (int d = 0; d < 3; ++d) {
      const auto raw = load_at<std::int32_t>(data, at + 4 * static_cast<std::size_t>(d));
      mesh.V(i, d) = raw * h.scale[d] + h.shift[d];
    }
  }
  mesh.F.resize(0, 3);
  return mesh;
}

Mesh read_las(const std::filesystem::path& path) {
  const FileBytes bytes = read_whole_file(path);
  return parse_las(path, bytes.view());
}

}  // namespace io_detail
}  // namespace focal
