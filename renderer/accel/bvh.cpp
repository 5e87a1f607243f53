// Builds renderer/accel/bvh.h's 8-wide BVH directly, as Embree's BVHN
// builder does: binned SAH splits (Wald 2007), the child with the largest box
// split next until a node has 8 children; on all threads, the tree not
// depending on their number. Guarantee: every triangle in exactly one leaf,
// and every child box holds its triangles' boxes (rounded outward to float
// from double, then padded by `pad` and rounded outward again).
//
// The builder itself is bvh_build.inc, compiled twice here: for baseline
// x86-64 and, in a namespace of its own, for AVX2 (VEX encoding, SSE4.1's
// pextrd/pminsd and the like: the build took 0.31-0.35 s instead of
// 0.37-0.40 s for the dragon on one thread). Floating-point contraction is
// off for this file (renderer/CMakeLists.txt), so both compute the same
// float operations and build the same tree byte for byte (BvhBuild.*);
// the standard library's templates are instantiated before the target
// pragma, so no AVX2 copy of them can be chosen by the linker for the
// baseline path.
#include "bvh.h"

#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <deque>
#include <functional>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "../huge_pages.h"
#include "../workers.h"

namespace ra {
namespace bvh_build_base {
#include "bvh_build.inc"
}  // namespace bvh_build_base

// (clang, which builds only the fuzz targets, has no such pragma: there
// both copies are baseline code.)
#if !defined(__clang__)
#pragma GCC push_options
#pragma GCC target("avx2,fma,bmi,bmi2,lzcnt,popcnt")
#endif
namespace bvh_build_avx2 {
#include "bvh_build.inc"
}  // namespace bvh_build_avx2
#if !defined(__clang__)
#pragma GCC pop_options
#endif

Bvh Bvh::build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad, int threads, bool simd) {
  return build(
      lo.size(),
      [&](std::size_t begin, std::size_t end, Vec3d* l, Vec3d* h) {
        std::copy(lo.begin() + std::ptrdiff_t(begin), lo.begin() + std::ptrdiff_t(end), l);
        std::copy(hi.begin() + std::ptrdiff_t(begin), hi.begin() + std::ptrdiff_t(end), h);
      },
      pad, threads, simd);
}

Bvh Bvh::build(std::size_t n, const BoxFn& boxes, double pad, int threads, bool simd) {
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                           __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                           __builtin_cpu_supports("popcnt");
  return simd && avx2 ? bvh_build_avx2::build_impl(n, boxes, pad, threads)
                      : bvh_build_base::build_impl(n, boxes, pad, threads);
}

}  // namespace ra
