// libFuzzer target: the MTL parser on arbitrary bytes (no file checks).
#include <cstdint>
#include <string_view>

#include "../errors.h"
#include "../formats/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> warnings;
  try {
    (void)ra::parse_mtl(text, "fuzz.mtl", "base", false, warnings);
  } catch (const ra::InputError&) {
  }
  return 0;
}
