// libFuzzer target for the STL reader (scripts/fuzz.sh builds and runs it; seeds in corpus/stl/),
// followed by the welding read_mesh applies: exact by default, or with a tolerance taken from the
// input's first byte, so that the grid-hashing path is fuzzed too. The weld on one thread and on
// three must agree.
#include <cstring>

#include "fuzz_reader.h"

namespace {

focal::Mesh parse_and_weld(const std::filesystem::path& path, std::string_view data) {
  focal::Mesh mesh = focal::io_detail::parse_stl(path, data);
  const auto corners = mesh.V.rows();
  const double tolerance =
      data.empty() ? 0.0 : static_cast<double>(static_cast<unsigned char>(data[0]) % 4) * 0.25;
  focal::Mesh on_three = mesh;
  focal::io_detail::weld_corners(mesh, tolerance, true, 1);
  focal::io_detail::weld_corners(on_three, tolerance, true, 3);
  const auto same_bits = [](const auto& a, const auto& b) {
    return a.size() == b.size() &&
           (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(*a.data()) * a.size()) == 0);
  };
  if (!same_bits(mesh.V, on_three.V) || !same_bits(mesh.F, on_three.F) ||
      !same_bits(mesh.corner_vertex, on_three.corner_vertex)) {
    std::abort();
  }
  if (mesh.corner_vertex.size() != corners || mesh.V.rows() > corners ||
      (corners > 0 &&
       (mesh.corner_vertex.minCoeff() < 0 || mesh.corner_vertex.maxCoeff() >= mesh.V.rows()))) {
    std::abort();
  }
  return mesh;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return focal::fuzz::check_reader(&parse_and_weld, "fuzz.stl", data, size);
}
