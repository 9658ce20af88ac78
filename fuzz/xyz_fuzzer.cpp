// libFuzzer target for the point-cloud text reader (scripts/fuzz.sh builds and runs it; seeds in
// corpus/xyz/). The name's extension is .xyz: six columns are judged normals or colours.
#include "fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return focal::fuzz::check_reader(&focal::io_detail::parse_xyz, "fuzz.xyz", data, size);
}
