// libFuzzer target: the user cases CSV reader (`audit --cases`) on arbitrary
// bytes. InputError is the expected rejection; anything else is a finding.
#include <cstdint>

#include "exact/cases_csv.h"
#include "errors.h"
#include "file_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = fuzz_input_file(data, size, ".csv");
  try {
    (void)ra::audit::read_cases_csv(path);
  } catch (const ra::InputError&) {
  }
  return 0;
}
