// PLY reading: ascii, binary little and big endian. The header (ply_header.cpp), the binary
// body (ply_binary.cpp) and the ascii body (ply_ascii.cpp) share io/ply_read.h; the types, names
// and byte order shared with the writer are in io/ply.h.

#include "io/ply_read.h"

#include <optional>
#include <utility>

#include "focal/io/mesh_io.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/text_scan.h"

namespace focal::io_detail {

using ply::BodyPlan;
using ply::parse_header;
using ply::plan_body;
using ply::PlyEncoding;
using ply::PlyHeader;

Mesh read_ply(const std::filesystem::path& path, int threads) {
  return parse_ply(path, read_whole_file(path), threads);
}

Mesh parse_ply(const std::filesystem::path& path, std::string_view data) {
  return parse_ply(path, data, 0);
}

Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads) {
  return parse_ply(path, data, threads, kTextChunkBytes);
}

std::optional<Mesh> parse_ply_in_chunks(const std::filesystem::path& path, std::string_view data,
                                        int threads, std::size_t chunk_bytes) {
  const PlyHeader header = parse_header(path, data);
  if (header.encoding != PlyEncoding::ascii) return std::nullopt;
  const BodyPlan plan = plan_body(path, header);
  return read_ascii_runs(path, header, plan, data.substr(header.body_offset), threads, chunk_bytes);
}

Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads,
               std::size_t chunk_bytes) {
  const PlyHeader header = parse_header(path, data);
  const BodyPlan plan = plan_body(path, header);
  if (header.encoding == PlyEncoding::ascii) {
    return read_ascii_body(path, data, header, plan, threads, chunk_bytes);
  }
  return read_binary_body(path, data, header, plan, threads);
}

}  // namespace focal::io_detail
