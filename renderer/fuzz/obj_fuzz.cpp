// libFuzzer target: the OBJ parser on arbitrary bytes, serial and parallel
// (which must agree), with mtllib resolution off. InputError is the expected
// way to reject input; anything else (crash, sanitizer report, another
// exception, a serial/parallel mismatch) is a finding.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "../errors.h"
#include "../formats/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  ra::ObjOptions opt;
  opt.load_materials = false;
  size_t serial_tris = 0;
  bool serial_ok = false;
  try {
    const ra::Mesh m = ra::parse_obj(text, "fuzz.obj", opt);
    serial_tris = m.triangles.size();
    serial_ok = true;
    (void)m.area();
    (void)m.bounding_sphere();
  } catch (const ra::InputError&) {
  }
  opt.threads = 3;
  opt.parallel_min_bytes = 0;
  try {
    const ra::Mesh m = ra::parse_obj(text, "fuzz.obj", opt);
    if (!serial_ok || m.triangles.size() != serial_tris) std::abort();
  } catch (const ra::InputError&) {
    if (serial_ok) std::abort();
  }
  return 0;
}
