#pragma once
// What every fuzz target checks: a reader given arbitrary bytes either returns a mesh that keeps
// the library's invariants or throws IoError. Anything else (a crash, a sanitizer report, another
// exception, an index out of range, a hang or a huge allocation) is a finding.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "focal/core/error.h"
#include "io/format_readers.h"

namespace focal::fuzz {

using Parser = Mesh (*)(const std::filesystem::path&, std::string_view);

inline int check_reader(Parser parse, const char* name, const std::uint8_t* data,
                        std::size_t size) {
  Mesh mesh;
  try {
    mesh = parse(name, std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const IoError&) {
    return 0;  // malformed input, reported as documented
  }
  const bool valid =
      mesh.V.cols() == 3 && mesh.F.cols() == 3 && mesh.face_source.size() == mesh.F.rows() &&
      (mesh.N.rows() == 0 || mesh.N.rows() == mesh.V.rows()) &&
      (mesh.F.size() == 0 || (mesh.F.minCoeff() >= 0 && mesh.F.maxCoeff() < mesh.V.rows()));
  if (!valid) std::abort();
  return 0;
}

}  // namespace focal::fuzz
