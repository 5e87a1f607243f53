#include "registry.h"

#include <stdexcept>

#include "methods/adapter.h"
#include "methods/moller.h"
#include "methods/plane.h"
#include "methods/sphere_stable.h"

namespace ra {

std::string_view kind_name(Kind k) {
  switch (k) {
    case Kind::triangle: return "triangle";
    case Kind::sphere: return "sphere";
    case Kind::plane: return "plane";
  }
  return "?";
}

namespace {

struct MollerM {
  template <class T>
  static std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b,
                                           const Vec3<T>& c, bool cull) {
    return moller::hit(r, a, b, c, cull);
  }
};

template <class T> SphereKernels<T> sphere_kernels_stable() {
  SphereKernels<T> k;
  k.hit = [](const Ray<T>& r, const Vec3<T>& c, T rad) { return sphere_stable::hit(r, c, rad); };
  k.any = [](const Ray<T>& r, const Vec3<T>& c, T rad) { return sphere_stable::hit(r, c, rad).has_value(); };
  return k;
}

template <class T> PlaneKernels<T> plane_kernels() {
  PlaneKernels<T> k;
  k.hit = [](const Ray<T>& r, const Vec3<T>& n, T d) { return plane::hit(r, n, d); };
  k.any = [](const Ray<T>& r, const Vec3<T>& n, T d) { return plane::hit(r, n, d).has_value(); };
  return k;
}

std::vector<Method> build() {
  std::vector<Method> m;
  {
    Method x{"moller", Kind::triangle, "Moller & Trumbore, JGT 1997",
             "Moller-Trumbore: edge vectors and a determinant, no stored plane"};
    x.tri_f = detail::vertex_only_kernels<MollerM, float>();
    x.tri_d = detail::vertex_only_kernels<MollerM, double>();
    m.push_back(x);
  }
  {
    Method x{"stable", Kind::sphere, "Ray Tracing Gems ch. 7 (Haines et al. 2019)",
             "stable quadratic roots and the geometric discriminant"};
    x.sph_f = sphere_kernels_stable<float>();
    x.sph_d = sphere_kernels_stable<double>();
    m.push_back(x);
  }
  {
    Method x{"plane", Kind::plane, "POV-Ray 3.7 planes.cpp", "ray/plane, two-sided"};
    x.pln_f = plane_kernels<float>();
    x.pln_d = plane_kernels<double>();
    m.push_back(x);
  }
  return m;
}

}  // namespace

const std::vector<Method>& methods() {
  static const std::vector<Method> all = build();
  return all;
}

const Method* find_method(std::string_view name) {
  for (const auto& m : methods())
    if (m.name == name) return &m;
  return nullptr;
}

std::string method_names(Kind kind) {
  std::string s;
  for (const auto& m : methods())
    if (m.kind == kind) s += (s.empty() ? "" : ", ") + m.name;
  return s;
}

const Method& default_method(Kind kind) {
  const char* name = kind == Kind::triangle ? "moller" : kind == Kind::sphere ? "stable" : "plane";
  const Method* m = find_method(name);
  if (!m) throw std::logic_error("default method missing from registry");
  return *m;
}

}  // namespace ra
