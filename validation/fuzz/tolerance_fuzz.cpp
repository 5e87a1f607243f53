// libFuzzer target: the POV-Ray tolerance JSON reader (scenes/pov/NAME.json)
// on arbitrary bytes. InputError is the expected rejection; a nlohmann
// exception escaping, a crash or a sanitizer report is a finding.
#include <cstdint>

#include "errors.h"
#include "file_input.h"
#include "pov/pov_tolerance.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = fuzz_input_file(data, size, ".json");
  try {
    (void)ra::load_pov_tolerance(path);
  } catch (const ra::InputError&) {
  }
  return 0;
}
