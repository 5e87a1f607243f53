// Memory an image-sized piece of work will need, checked before the work
// (a 16384x16384 render died of std::bad_alloc after 37 s).
#pragma once
#include <cstdint>
#include <string>

namespace ra {

// Bytes this process can still allocate: the smaller of what the
// address-space limit (RLIMIT_AS, `ulimit -v`) leaves beside what is mapped
// now, and the system's MemAvailable + SwapFree. UINT64_MAX if unknown.
std::uint64_t available_memory();

// Only the address-space limit's part of it (what RLIMIT_AS leaves beside
// what is mapped now): address space, not memory, is what a library's
// mappings take. UINT64_MAX when there is no limit.
std::uint64_t address_space_left();

// Throws InputError "WxH needs about N MB for its image buffers; M MB are
// available ..." when width x height x bytes_per_pixel exceeds
// available_memory(). `what` names the work ("render", "compare").
void check_image_memory(const std::string& what, int width, int height, int bytes_per_pixel);

}  // namespace ra
