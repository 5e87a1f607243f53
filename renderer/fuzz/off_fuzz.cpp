// libFuzzer target: the OFF reader ([ST][C][N]OFF) on arbitrary bytes,
// checked as polymesh_fuzz.h says.
#include "polymesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ra::fuzz::polymesh_one_input(data, size, [](std::string_view b) { return ra::parse_off(b, "fuzz.off"); });
}
