// CSV writing (RFC 4180): a header of column names, then one row per element.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/number_text.h"

namespace focal {
namespace {

Eigen::Index column_length(const CsvColumn& column) {
  return std::visit([](const auto& v) { return static_cast<Eigen::Index>(v.size()); },
                    column.values);
}

/// Words go out as they are unless they hold a separator, quote or line break; only then are
/// they quoted (with quotes doubled), so that every row keeps its column count.
void append_field(std::string& out, std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    out += text;
    return;
  }
  out += '"';
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
}

}  // namespace

void write_csv(const std::filesystem::path& path, std::span<const CsvColumn> columns) {
  write_csv(path, columns, WriteOptions{});
}

void write_csv(const std::filesystem::path& path, std::span<const CsvColumn> columns,
               const WriteOptions& options) {
  const Eigen::Index rows = columns.empty() ? 0 : column_length(columns.front());
  for (const auto& column : columns) {
    if (column_length(column) != rows) {
      throw InvalidInput("write_csv: " + path.string() + ": column '" + column.name + "' has " +
                         std::to_string(column_length(column)) + " values but column '" +
                         columns.front().name + "' has " + std::to_string(rows));
    }
  }
  const auto append_row = [&](std::string& out, Eigen::Index r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) out += ',';
      if (const auto* numbers = std::get_if<Eigen::VectorXd>(&columns[c].values)) {
        io_detail::append_real(out, (*numbers)[r], options.precision);
      } else {
        append_field(out, std::get<std::vector<std::string>>(
                              columns[c].values)[static_cast<std::size_t>(r)]);
      }
    }
    out += '\n';
  };
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    std::string& out = sink.buffer();
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) out += ',';
      append_field(out, columns[c].name);
    }
    out += '\n';
    io_detail::write_lines(sink, rows, 0, append_row);
  });
}

}  // namespace focal
