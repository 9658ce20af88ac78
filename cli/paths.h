#pragma once
// Output-path checks shared by the subcommands, done before any work so that a wrong name is a
// usage error (exit 1) and not a failure after minutes of computing; and the output options
// shared by the commands that write fields, meshes or points.

#include <CLI/CLI.hpp>
#include <initializer_list>
#include <string>

#include "focal/io/mesh_io.h"

namespace focal::cli {

/// The output options of `curvature`, `focal-mesh` and `normals`.
struct OutputFlags {
  bool float32 = false;  ///< --float32: real numbers written as floats (Precision::float32)

  void add_to(CLI::App& command);
  [[nodiscard]] Precision precision() const {
    return float32 ? Precision::float32 : Precision::float64;
  }
};

/// The lower-case extension of a path, with its dot (".ply").
[[nodiscard]] std::string lower_extension(const std::string& path);

/// \throw CLI::ValidationError naming `option` unless the path ends in one of `allowed`.
void require_extension(const std::string& option, const std::string& path,
                       std::initializer_list<const char*> allowed);

/// Checks an output path of a run before any work (CLI::ValidationError naming `option`, exit 1):
///  - it may not be the input file (the same file also through a link or another name);
///  - an existing file with no write permission bit is not replaced unless `force`.
/// A symbolic link as output is written through to the file it points to (io/atomic_file.h).
void check_output(const std::string& option, const std::string& output, const std::string& input,
                  bool force);

}  // namespace focal::cli
