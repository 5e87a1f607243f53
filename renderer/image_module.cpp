// Finds and loads the image module (image_module.h) on first use, so that a
// process which never touches an image never maps OpenImageIO.
#include "image_module.h"

#include <dlfcn.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <filesystem>
#include <mutex>
#include <string>

#include "errors.h"

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

// Address space OpenImageIO needs to load and start: its libraries, and the
// threads log4cplus starts while the module is opened (each with a stack and
// a malloc arena), which abort, crash or hang inside dlopen when the system
// refuses them; with a little less, a valid texture's read failed as
// "cannot be allocated" (HOSTILE2 F28). Measured on Debian 12: an 8x8
// textured render needs about 525 MB beside the 10 MB mapped before; with a
// margin, 560 MB. Refused before dlopen, naming the limit.
constexpr std::uint64_t kModuleAddressSpace = std::uint64_t(560) << 20;

void check_address_space() {
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) != 0 || as.rlim_cur == RLIM_INFINITY) return;
  std::uint64_t pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const std::uint64_t mapped = pages * std::uint64_t(::sysconf(_SC_PAGESIZE));
  const std::uint64_t left = as.rlim_cur > mapped ? as.rlim_cur - mapped : 0;
  if (left < kModuleAddressSpace)
    throw InputError("rayaudit: the image module (OpenImageIO) needs about " +
                     std::to_string(kModuleAddressSpace >> 20) + " MB of address space to load, but the limit (" +
                     std::to_string(as.rlim_cur >> 20) + " MB, `ulimit -v` / RLIMIT_AS) leaves " +
                     std::to_string(left >> 20) + " MB: raise it");
}

const Api* load() {
  check_address_space();
  std::string tried;
  for (const std::string& path : candidates()) {
    const bool by_name = path.find('/') == std::string::npos;
    std::error_code ec;
    tried += (tried.empty() ? "" : ", ") + (by_name ? "the library path" : path);
    if (!by_name && !fs::exists(path, ec)) continue;
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
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
      throw InputError(located(path, 0, "not the image module of this rayaudit (version " RAYAUDIT_VERSION
                                        "): rebuild or reinstall it"));
    return api;
  }
  throw InputError(located(kFileName, 0,
                           "the image module (OpenImageIO reading and writing) is not installed: looked for " +
                               tried + "; set RAYAUDIT_IMAGE_MODULE to its path"));
}

}  // namespace

const Api& api() {
  // Loaded once; a failure is thrown again on every call.
  static std::mutex m;
  static const Api* loaded = nullptr;
  std::lock_guard<std::mutex> lock(m);
  if (!loaded) loaded = load();
  return *loaded;
}

}  // namespace ra::image_module
