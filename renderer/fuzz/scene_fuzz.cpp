// libFuzzer target: the scene JSON reader on arbitrary bytes (relative mesh
// and texture paths resolve under a directory that does not exist).
// InputError is the expected rejection; a nlohmann or filesystem exception
// escaping, a crash or a sanitizer report is a finding.
#include <cstdint>
#include <string>

#include "../errors.h"
#include "../scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)ra::parse_scene_json(text, "/nonexistent-fuzz-dir/scene.json");
  } catch (const ra::InputError&) {
  }
  return 0;
}
