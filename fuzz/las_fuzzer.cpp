// libFuzzer target for the ASPRS LAS reader (scripts/fuzz.sh builds and runs it; seeds in
// corpus/las/).
#include "fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return focal::fuzz::check_reader(&focal::io_detail::parse_las, "fuzz.las", data, size);
}
