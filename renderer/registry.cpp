#include "registry.h"

#include <stdexcept>

#include <cstring>
#include <utility>

#include "methods/adapter.h"
#include "methods/angles.h"
#include "methods/areas.h"
#include "methods/baldwin.h"
#include "methods/cramer.h"
#include "methods/exact.h"
#include "methods/moller.h"
#include "methods/plane.h"
#include "methods/sameside.h"
#include "methods/sphere_codeproject.h"
#include "methods/sphere_kraus.h"
#include "methods/sphere_stable.h"
#include "methods/triple.h"
#include "methods/watertight.h"

namespace ra {

std::string_view kind_name(Kind k) {
  switch (k) {
    case Kind::triangle:
      return "triangle";
    case Kind::sphere:
      return "sphere";
    case Kind::plane:
      return "plane";
  }
  return "?";
}

namespace {

// Adapts a method namespace's templated `hit`/`any` to the adapter's M.
#define RA_VERTEX_METHOD(Struct, ns)                                                                                \
  struct Struct {                                                                                                   \
    template <class T>                                                                                              \
    static std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, \
                                             bool cull) {                                                           \
      return ns::hit(r, a, b, c, cull);                                                                             \
    }                                                                                                               \
    template <class T>                                                                                              \
    static bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {             \
      return ns::any(r, a, b, c, cull);                                                                             \
    }                                                                                                               \
  }
RA_VERTEX_METHOD(CramerM, cramer);
RA_VERTEX_METHOD(TripleM, triple);
RA_VERTEX_METHOD(WatertightM, watertight);
RA_VERTEX_METHOD(BaldwinM, baldwin);
#undef RA_VERTEX_METHOD

// The documents' methods that decide only t (ns::accept); detail::DecidesT
// (methods/point_barycentrics.h) gives their hit and any.
#define RA_DECIDES_T(Struct, ns)                                                                                       \
  struct Struct##Doc {                                                                                                 \
    template <class T>                                                                                                 \
    static std::optional<T> accept(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) { \
      return ns::accept(r, a, b, c, cull);                                                                             \
    }                                                                                                                  \
  };                                                                                                                   \
  using Struct = detail::DecidesT<Struct##Doc>
RA_DECIDES_T(AnglesM, angles);
RA_DECIDES_T(AreasM, areas);
RA_DECIDES_T(SamesideM, sameside);
#undef RA_DECIDES_T

struct MollerM {
  template <class T>
  static std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                           bool cull) {
    return moller::hit(r, a, b, c, cull);
  }
};

// Baldwin's prepared path stores its transform instead of the vertices; its
// direct path (from the adapter) builds the transform on every call.
template <class T>
TriangleKernels<T> baldwin_kernels() {
  TriangleKernels<T> k = detail::vertex_only_kernels<BaldwinM, T>();
  k.prepare = [](const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, void* out) {
    const baldwin::Transform<T> tr = baldwin::prepare(a, b, c);
    std::memcpy(out, &tr, sizeof tr);
  };
  k.hit_pre = [](const Ray<T>& r, const void* pre, bool cull) {
    return baldwin::hit(r, *static_cast<const baldwin::Transform<T>*>(pre), cull);
  };
  k.any_pre = [](const Ray<T>& r, const void* pre, bool cull) {
    return baldwin::any(r, *static_cast<const baldwin::Transform<T>*>(pre), cull);
  };
  k.pre_bytes = sizeof(baldwin::Transform<T>);
  return k;
}

// exact's prepared path stores the vertices and its triangle terms (the
// normal in the stage 1b compute type and the permanents): the same answers.
struct ExactM {
  template <class T>
  static std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                           bool cull) {
    return exact::hit(r, a, b, c, cull);
  }
  template <class T>
  static bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
    return exact::any(r, a, b, c, cull);
  }
};
template <class T>
TriangleKernels<T> exact_kernels() {
  TriangleKernels<T> k = detail::vertex_only_kernels<ExactM, T>();
  using P = exact::detail::Prepared<T>;
  k.prepare = [](const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, void* out) {
    const P p = exact::detail::prepare(a, b, c);
    std::memcpy(out, &p, sizeof p);
  };
  k.hit_pre = [](const Ray<T>& r, const void* pre, bool cull) {
    return exact::hit(r, *static_cast<const P*>(pre), cull);
  };
  k.any_pre = [](const Ray<T>& r, const void* pre, bool cull) {
    return exact::any(r, *static_cast<const P*>(pre), cull);
  };
  k.pre_bytes = sizeof(P);
  return k;
}

template <class T, std::optional<SurfaceHit<T>> (*F)(const Ray<T>&, const Vec3<T>&, T)>
SphereKernels<T> sphere_kernels() {
  SphereKernels<T> k;
  k.hit = F;
  k.any = [](const Ray<T>& r, const Vec3<T>& c, T rad) { return F(r, c, rad).has_value(); };
  return k;
}

template <class T>
PlaneKernels<T> plane_kernels() {
  PlaneKernels<T> k;
  k.hit = [](const Ray<T>& r, const Vec3<T>& n, T d) { return plane::hit(r, n, d); };
  k.any = [](const Ray<T>& r, const Vec3<T>& n, T d) { return plane::hit(r, n, d).has_value(); };
  return k;
}

// Value-initialised, then named (aggregate init would leave the kernels to
// -Wmissing-field-initializers).
Method make(std::string name, Kind kind, std::string source, std::string description) {
  Method x{};
  x.name = std::move(name);
  x.kind = kind;
  x.source = std::move(source);
  x.description = std::move(description);
  return x;
}

template <class M>
Method triangle_method(std::string name, std::string source, std::string description) {
  Method x = make(std::move(name), Kind::triangle, std::move(source), std::move(description));
  x.tri_f = detail::vertex_only_kernels<M, float>();
  x.tri_d = detail::vertex_only_kernels<M, double>();
  return x;
}

template <template <class> class F>
Method sphere_method(std::string name, std::string source, std::string description) {
  Method x = make(std::move(name), Kind::sphere, std::move(source), std::move(description));
  x.sph_f = sphere_kernels<float, F<float>::fn>();
  x.sph_d = sphere_kernels<double, F<double>::fn>();
  return x;
}

template <class T>
struct KrausF {
  static constexpr auto fn = &sphere_kraus::hit<T>;
};
template <class T>
struct CodeprojectF {
  static constexpr auto fn = &sphere_codeproject::hit_as_written<T>;
};
template <class T>
struct CodeprojectFixedF {
  static constexpr auto fn = &sphere_codeproject::hit_fixed<T>;
};
template <class T>
struct StableF {
  static constexpr auto fn = &sphere_stable::hit<T>;
};

std::vector<Method> build() {
  std::vector<Method> m;
  // Triangles: the four documents' methods in seed order, then the references.
  m.push_back(triangle_method<AnglesM>("angles", "seeds/000 §2.1",
                                       "plane, then (fa x fb).n etc. >= MINUS_ZERO (-1e-4): edges widened; two-sided"));
  m.push_back(
      triangle_method<CramerM>("cramer", "seeds/000 §2.2",
                               "Cramer's rule with the text's a..l scalars; strict 0 < beta, gamma, beta+gamma < 1"));
  m.push_back(triangle_method<AreasM>(
      "areas", "seeds/001 (ray-triangle)",
      "plane with epsilon5 < distance, then Heron areas, sum <= ABC + epsilon3 (1e-3); a NaN area accepts"));
  m.push_back(triangle_method<TripleM>("triple", "seeds/002 (Cramer, triple products)",
                                       "Cramer's rule via scalar triple products; inclusive 0 <= l2, l3, l2+l3 <= 1"));
  m.push_back(triangle_method<SamesideM>("sameside", "seeds/004 (GetInterSect, PointInTriangle)",
                                         "plane with |N.v| < 1e-6 as parallel, then same side per edge with >= 0"));
  m.push_back(triangle_method<MollerM>("moller", "Moller & Trumbore, JGT 1997",
                                       "Moller-Trumbore: edge vectors and a determinant, no stored plane; det == 0 as "
                                       "parallel (the paper's EPSILON 1e-6 dropped)"));
  m.push_back(
      triangle_method<WatertightM>("watertight", "Woop et al., JCGT 2013 + pbrt-v4 deltaT",
                                   "shear to ray space, 2D edge functions (double fallback), conservative t bound"));
  {
    Method x = make("baldwin", Kind::triangle, "Baldwin & Weber, JCGT 2016",
                    "precomputed 3x4 affine map to barycentric space (12 values per triangle)");
    x.tri_f = baldwin_kernels<float>();
    x.tri_d = baldwin_kernels<double>();
    x.precompute_bytes_float = sizeof(baldwin::Transform<float>);    // 48
    x.precompute_bytes_double = sizeof(baldwin::Transform<double>);  // 96
    m.push_back(x);
  }
  {
    Method x =
        make("exact", Kind::triangle,
             "Plucker signs (Woop et al. 2013) certified by a filter (Shewchuk 1997, pbrt-v4 gamma), GMP fallback",
             "decisions of exact arithmetic (closed triangle, closed window); t faithfully rounded; GMP where the "
             "filter cannot tell");
    x.tri_f = exact_kernels<float>();
    x.tri_d = exact_kernels<double>();
    x.precompute_bytes_float = sizeof(exact::detail::Prepared<float>);  // vertices, normal, permanents
    x.precompute_bytes_double = sizeof(exact::detail::Prepared<double>);
    m.push_back(x);
  }
  // Spheres.
  m.push_back(sphere_method<KrausF>("kraus", "seeds/001 (ray-sphere)",
                                    "unit-direction quadratic; nearest root > epsilon5 (1e-5), else the far one"));
  {
    Method x =
        sphere_method<CodeprojectF>("codeproject", "seeds/004 (Line x Sphere)",
                                    "as written: general quadratic, D >= 0, keeps the FAR root (the exit point)");
    x.wrong_on_purpose = true;
    m.push_back(x);
  }
  m.push_back(
      sphere_method<CodeprojectFixedF>("codeproject-fixed", "seeds/004 (Line x Sphere), corrected",
                                       "seeds/004's quadratic keeping the near root (far root only from inside)"));
  m.push_back(sphere_method<StableF>("stable", "Ray Tracing Gems ch. 7 (Haines et al. 2019)",
                                     "stable quadratic roots and the geometric discriminant"));
  // Planes.
  {
    Method x = make("plane", Kind::plane, "POV-Ray 3.7 planes.cpp", "ray/plane, two-sided");
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
