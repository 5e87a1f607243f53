// The check shared by the PLY and OFF libFuzzer targets: InputError is the
// expected rejection; any other exception, crash or sanitizer report is a
// finding; a mesh the reader accepts must be valid (every index in range,
// every coordinate finite), else abort() makes it a finding.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "../errors.h"
#include "../formats/polymesh_io.h"

namespace ra::fuzz {

template <class Parse>
int polymesh_one_input(const std::uint8_t* data, std::size_t size, Parse parse) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const ra::PolyMesh m = parse(bytes);
    for (int i : m.indices)
      if (i < 0 || std::size_t(i) >= m.positions.size()) std::abort();
    for (const auto& p : m.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  } catch (const ra::InputError&) {
  }
  return 0;
}

}  // namespace ra::fuzz
