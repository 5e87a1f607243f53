// Up-front memory estimate for image buffers ("no unbounded
// memory"): refused with a one-line estimate rather than a late bad_alloc.
#include "memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>

#include "errors.h"

namespace ra {

namespace {

// Bytes mapped by this process now (/proc/self/statm's first field).
std::uint64_t mapped_now() {
  std::ifstream in("/proc/self/statm");
  std::uint64_t pages = 0;
  if (!(in >> pages)) return 0;
  return pages * std::uint64_t(::sysconf(_SC_PAGESIZE));
}

// MemAvailable + SwapFree from /proc/meminfo, in bytes; UINT64_MAX if unreadable.
std::uint64_t system_available() {
  std::ifstream in("/proc/meminfo");
  std::uint64_t avail = 0, swap = 0;
  bool found = false;
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string key;
    std::uint64_t kb = 0;
    ls >> key >> kb;
    if (key == "MemAvailable:")
      avail = kb * 1024, found = true;
    else if (key == "SwapFree:")
      swap = kb * 1024;
  }
  return found ? avail + swap : std::numeric_limits<std::uint64_t>::max();
}

std::string megabytes(std::uint64_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MB"; }

}  // namespace

std::uint64_t address_space_left() {
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) != 0 || as.rlim_cur == RLIM_INFINITY)
    return std::numeric_limits<std::uint64_t>::max();
  const std::uint64_t used = mapped_now();
  return as.rlim_cur > used ? as.rlim_cur - used : 0;
}

std::uint64_t available_memory() { return std::min(system_available(), address_space_left()); }

void check_image_memory(const std::string& what, int width, int height, int bytes_per_pixel) {
  const std::uint64_t need = std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(bytes_per_pixel);
  const std::uint64_t avail = available_memory();
  if (need > avail)
    throw InputError(
        what + ": " + std::to_string(width) + "x" + std::to_string(height) + " needs about " + megabytes(need) +
        " for its image buffers, but only " + megabytes(avail) +
        " are available (free memory, or the address-space limit `ulimit -v`): lower the width and height");
}

}  // namespace ra
