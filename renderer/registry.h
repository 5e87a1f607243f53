// The one registry of intersection methods. `render`, `audit` and `bench`
// all choose a method by its name here; nothing else lists them.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hit.h"
#include "ray.h"

namespace ra {

enum class Kind { triangle, sphere, plane };
std::string_view kind_name(Kind k);

// Kernels for one triangle method at one precision. Every method has both
// entry points:
//  - direct: ray + the three vertices (what the audit calls);
//  - prepared: `prepare` writes `pre_bytes` bytes once per triangle, and
//    hit_pre/any_pre read them (what meshes and benchmarks call). Methods with
//    no precomputation store the three vertices.
// `cull` = true rejects triangles seen from the back, where the front is the
// side that the normal (B - A) x (C - A) points to.
template <class T>
struct TriangleKernels {
  std::optional<TriangleHit<T>> (*hit)(const Ray<T>&, const Vec3<T>&, const Vec3<T>&, const Vec3<T>&,
                                       bool cull) = nullptr;
  bool (*any)(const Ray<T>&, const Vec3<T>&, const Vec3<T>&, const Vec3<T>&, bool cull) = nullptr;
  void (*prepare)(const Vec3<T>&, const Vec3<T>&, const Vec3<T>&, void* out) = nullptr;
  std::optional<TriangleHit<T>> (*hit_pre)(const Ray<T>&, const void* pre, bool cull) = nullptr;
  bool (*any_pre)(const Ray<T>&, const void* pre, bool cull) = nullptr;
  std::size_t pre_bytes = 0;
};

// Sphere kernels: centre and radius.
template <class T>
struct SphereKernels {
  std::optional<SurfaceHit<T>> (*hit)(const Ray<T>&, const Vec3<T>& center, T radius) = nullptr;
  bool (*any)(const Ray<T>&, const Vec3<T>& center, T radius) = nullptr;
};

// Plane kernels: the plane is dot(normal, P) = offset, normal unit length.
template <class T>
struct PlaneKernels {
  std::optional<SurfaceHit<T>> (*hit)(const Ray<T>&, const Vec3<T>& normal, T offset) = nullptr;
  bool (*any)(const Ray<T>&, const Vec3<T>& normal, T offset) = nullptr;
};

struct Method {
  std::string name;  // the CLI's name, e.g. "watertight"
  Kind kind;
  std::string source;       // seed file and section, or paper
  std::string description;  // one line
  // Bytes of per-triangle precomputation beyond nothing at all (0 for methods
  // that work from the three vertices alone), in float and in double.
  std::size_t precompute_bytes_float = 0;
  std::size_t precompute_bytes_double = 0;
  // Document variants that are wrong on purpose say so (e.g. codeproject).
  bool wrong_on_purpose = false;

  TriangleKernels<float> tri_f;
  TriangleKernels<double> tri_d;
  SphereKernels<float> sph_f;
  SphereKernels<double> sph_d;
  PlaneKernels<float> pln_f;
  PlaneKernels<double> pln_d;

  template <class T>
  const TriangleKernels<T>& triangle() const {
    if constexpr (sizeof(T) == sizeof(float))
      return tri_f;
    else
      return tri_d;
  }
  template <class T>
  const SphereKernels<T>& sphere() const {
    if constexpr (sizeof(T) == sizeof(float))
      return sph_f;
    else
      return sph_d;
  }
  template <class T>
  const PlaneKernels<T>& plane() const {
    if constexpr (sizeof(T) == sizeof(float))
      return pln_f;
    else
      return pln_d;
  }
};

// All methods, in a fixed order (triangles, spheres, planes).
const std::vector<Method>& methods();
// nullptr when no method has that name.
const Method* find_method(std::string_view name);
// The names of all methods of a kind, comma-separated (for error messages).
std::string method_names(Kind kind);
// The default method of each kind: moller, stable, plane.
const Method& default_method(Kind kind);

}  // namespace ra
