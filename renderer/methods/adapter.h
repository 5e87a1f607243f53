// Builds a registry entry's kernels from a method written as plain templated
// functions, so each method file holds only its arithmetic.
#pragma once
#include <concepts>
#include <cstring>

#include "../registry.h"

namespace ra::detail {

// Prepared storage for methods that need only the three vertices.
template <class T>
struct VertexPre {
  Vec3<T> a, b, c;
};

// M provides: template <class T> static std::optional<TriangleHit<T>>
//   hit(const Ray<T>&, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull);
// and optionally `any` with the same parameters returning bool (used by both
// any-hit entries when present; otherwise any-hit is "hit has a value").
template <class M, class T>
concept HasAny = requires(const Ray<T>& r, const Vec3<T>& v) {
  { M::template any<T>(r, v, v, v, true) } -> std::same_as<bool>;
};

template <class M, class T>
bool any_hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  if constexpr (HasAny<M, T>)
    return M::template any<T>(r, a, b, c, cull);
  else
    return M::template hit<T>(r, a, b, c, cull).has_value();
}

template <class M, class T>
TriangleKernels<T> vertex_only_kernels() {
  TriangleKernels<T> k;
  k.hit = [](const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
    return M::template hit<T>(r, a, b, c, cull);
  };
  k.any = [](const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
    return any_hit<M, T>(r, a, b, c, cull);
  };
  k.prepare = [](const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, void* out) {
    VertexPre<T> p{a, b, c};
    std::memcpy(out, &p, sizeof p);
  };
  k.hit_pre = [](const Ray<T>& r, const void* pre, bool cull) {
    const auto* p = static_cast<const VertexPre<T>*>(pre);
    return M::template hit<T>(r, p->a, p->b, p->c, cull);
  };
  k.any_pre = [](const Ray<T>& r, const void* pre, bool cull) {
    const auto* p = static_cast<const VertexPre<T>*>(pre);
    return any_hit<M, T>(r, p->a, p->b, p->c, cull);
  };
  k.pre_bytes = sizeof(VertexPre<T>);
  return k;
}

}  // namespace ra::detail
