#include "io/number_text.h"

#include <charconv>
#include <cmath>

namespace focal::io_detail {

namespace {
template <class T>
void append_floating(std::string& out, T value) {
  if (std::isnan(value)) {
    out += "nan";  // never "-nan": readers and spreadsheets agree on "nan"
    return;
  }
  if (std::isinf(value)) {
    out += value > 0 ? "inf" : "-inf";
    return;
  }
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}
}  // namespace

void append_number(std::string& out, double value) { append_floating(out, value); }
void append_number(std::string& out, float value) { append_floating(out, value); }

void append_number(std::string& out, std::int64_t value) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}

}  // namespace focal::io_detail
