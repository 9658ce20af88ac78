// libFuzzer target for PCL's .pcd reader (scripts/fuzz.sh builds and runs it; seeds in
// corpus/pcd/).
#include "fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return focal::fuzz::check_reader(&focal::io_detail::parse_pcd, "fuzz.pcd", data, size);
}
