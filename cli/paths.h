#pragma once
// Output-path checks shared by the subcommands, done before any work so that a wrong name is a
// usage error (exit 1) and not a failure after minutes of computing.

#include <initializer_list>
#include <string>

namespace focal::cli {

/// The lower-case extension of a path, with its dot (".ply").
[[nodiscard]] std::string lower_extension(const std::string& path);

/// \throw CLI::ValidationError naming `option` unless the path ends in one of `allowed`.
void require_extension(const std::string& option, const std::string& path,
                       std::initializer_list<const char*> allowed);

}  // namespace focal::cli
