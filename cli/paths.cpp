#include "paths.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <filesystem>

namespace focal::cli {

void OutputFlags::add_to(CLI::App& command) {
  command.add_flag("--float32", float32,
                   "write real numbers as float32: PLY `float` positions, normals and fields; "
                   "CSV/text numbers as the shortest text of the float (smaller files; about 7 "
                   "significant digits instead of bit-exact doubles)");
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void require_extension(const std::string& option, const std::string& path,
                       std::initializer_list<const char*> allowed) {
  const std::string ext = lower_extension(path);
  std::string names;
  for (const char* a : allowed) {
    if (ext == a) return;
    names += (names.empty() ? "" : ", ") + std::string(a);
  }
  throw CLI::ValidationError(option, "output must end in " + names + ", got '" + path + "'");
}

void check_output(const std::string& option, const std::string& output, const std::string& input,
                  bool force) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!input.empty() && fs::equivalent(input, output, ec) && !ec) {
    throw CLI::ValidationError(option,
                               "'" + output + "' is the input file; refusing to overwrite it");
  }
  const fs::file_status status = fs::status(output, ec);
  const auto writable = fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write;
  if (!force && fs::is_regular_file(status) &&
      (status.permissions() & writable) == fs::perms::none) {
    throw CLI::ValidationError(option, "'" + output + "' is read-only; --force replaces it");
  }
}

}  // namespace focal::cli
