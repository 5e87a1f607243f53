// Finds and loads the image module (image_module.h) on first use, so that a
// process which never touches an image never maps OpenImageIO.
#include "image_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <algorithm>
#include <cstdint>
#include <mutex>
#include <thread>
#include <string>
#include <system_error>

#include "errors.h"
#include "memory_budget.h"

namespace ra::image_module {
namespace {

namespace fs = std::filesystem;

// Where the module may be, most specific first (see api()).
std::vector<std::string> candidates() {
  std::vector<std::string> out;
  if (const char* env = std::getenv("RAYAUDIT_IMAGE_MODULE"); env && *env) return {env};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back((exe.parent_path() / kFileName).string());
    out.push_back((exe.parent_path().parent_path() / RAYAUDIT_INSTALL_LIBDIR / "rayaudit" / kFileName).string());
  }
  out.push_back(kFileName);  // no slash: dlopen searches the executable's RUNPATH
  out.push_back((fs::path(RAYAUDIT_INSTALL_FULL_LIBDIR) / "rayaudit" / kFileName).string());
  return out;
}

// OpenImageIO and its ~260 libraries map about 430 MB of address space as
// they load, and some start threads in their initialisers (log4cplus: 4,
// each with a stack and a malloc arena). Under an address-space limit
// (`ulimit -v`, prlimit --as) that leaves less, the load or the first read
// aborted, segfaulted or hung inside those libraries (410-450
// MB), and up to ~540 MB a valid texture's read failed as "cannot be
// allocated". Measured on Debian 12 (2 cores): an 8x8 textured render needs
// about 525 MB beside the 10 MB mapped before; with a margin, 560 MB and a
// thread stack (8 MB) a core beyond 2. Refused here, before dlopen.
void check_address_space() {
  const std::uint64_t cores = std::max(2u, std::thread::hardware_concurrency());
  const std::uint64_t need = (std::uint64_t(560) << 20) + (std::uint64_t(8) << 20) * (cores - 2);
  const std::uint64_t left = address_space_left();
  if (left < need)
    throw InputError(located(kFileName, 0,
                             "the image module (OpenImageIO) needs about " + std::to_string(need >> 20) +
                                 " MB of address space to load, but only " + std::to_string(left >> 20) +
                                 " MB are left under the address-space limit (`ulimit -v`): raise it"));
}

const Api* load() {
  std::string tried;
  for (const std::string& path : candidates()) {
    const bool by_name = path.find('/') == std::string::npos;
    std::error_code ec;
    tried += (tried.empty() ? "" : ", ") + (by_name ? "the library path" : path);
    if (!by_name && !fs::exists(path, ec)) continue;
    void* handle = nullptr;
    try {
      // Through a pointer of a type that may throw: glibc declares dlopen
      // noexcept, and the handler would be compiled away.
      void* (*volatile open_fn)(const char*, int) = ::dlopen;
      handle = open_fn(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    } catch (const std::system_error& e) {
      // OpenImageIO's dependencies start threads in their initialisers: under
      // a low `ulimit -v` that throws out of dlopen ("rayaudit: error:
      // Resource temporarily unavailable", naming nothing).
      throw InputError(
          located(by_name ? std::string(kFileName) : path, 0,
                  std::string("cannot load the image module: ") + e.what() +
                      " (a library's thread could not start: is the address-space limit `ulimit -v` too low?)"));
    }
    if (!handle) {
      // A file that is there but does not load (a missing OpenImageIO
      // library, a wrong architecture) is the answer, not the next place.
      if (!by_name) throw InputError(located(path, 0, std::string("cannot load the image module: ") + ::dlerror()));
      ::dlerror();
      continue;
    }
    using Entry = const Api* (*)();
    auto entry = reinterpret_cast<Entry>(::dlsym(handle, "rayaudit_image_module_api"));
    const Api* api = entry ? entry() : nullptr;
    if (!api || api->version != kVersion || api->size != sizeof(Api))
      throw InputError(located(
          path, 0, "not the image module of this rayaudit (version " RAYAUDIT_VERSION "): rebuild or reinstall it"));
    return api;
  }
  throw InputError(located(kFileName, 0,
                           "the image module (OpenImageIO reading and writing) is not installed: looked for " + tried +
                               "; set RAYAUDIT_IMAGE_MODULE to its path"));
}

}  // namespace

const Api& api() {
  // Loaded once; a failure is thrown again on every call.
  static std::mutex m;
  static const Api* loaded = nullptr;
  std::lock_guard<std::mutex> lock(m);
  if (!loaded) {
    check_address_space();
    loaded = load();
  }
  return *loaded;
}

}  // namespace ra::image_module
