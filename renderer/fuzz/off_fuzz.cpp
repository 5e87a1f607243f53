// libFuzzer target: the OFF reader ([ST][C][N]OFF) on
// arbitrary bytes. InputError is the expected rejection; any other exception,
// crash or sanitizer report is a finding; a mesh it accepts must be valid
// (every index in range, every coordinate finite).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "../errors.h"
#include "../formats/polymesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const ra::PolyMesh m = ra::parse_off(bytes, "fuzz.off");
    for (int i : m.indices)
      if (i < 0 || std::size_t(i) >= m.positions.size()) std::abort();
    for (const auto& p : m.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  } catch (const ra::InputError&) {
  }
  return 0;
}
