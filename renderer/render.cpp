#include "render.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <system_error>
#include <thread>
#include <type_traits>

#include "shading/bump.h"
#include "shading/glass.h"
#include "accel/bounding_sphere.h"
#include "accel/bvh.h"
#include "scene/camera.h"
#include "errors.h"
#include "huge_pages.h"
#include "memory_budget.h"
#include "methods/exact_simd.h"
#include "methods/moller_simd.h"
#include "pov_mesh.h"
#include "registry.h"
#include "shading/texture.h"
#include "workers.h"

namespace ra {

std::optional<Accel> parse_accel(std::string_view s) {
  if (s == "none") return Accel::none;
  if (s == "sphere") return Accel::sphere;
  if (s == "bvh") return Accel::bvh;
  return std::nullopt;
}
const char* accel_name(Accel a) {
  switch (a) {
    case Accel::none:
      return "none";
    case Accel::sphere:
      return "sphere";
    case Accel::bvh:
      return "bvh";
  }
  return "?";
}

namespace {

// POV-Ray skips a light whose N.L is below this (trace.cpp).
constexpr double kMinCosIncidence = 1e-10;

// An allocator whose resize() leaves elements default-initialised (for
// trivial types: unwritten), where every element is written right after:
// a zeroing pass over the 72 MB of the dragon's leaf blocks cost as much
// as writing them.
template <class T>
struct DefaultInit : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInit<U>;
  };
  using std::allocator<T>::allocator;
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// A mesh ready for tracing at precision T: each triangle's prepared bytes
// for the chosen method and the bounding sphere of document 002's
// optimisation (the unit geometric normal is computed at each hit:
// unit_normal). With --accel bvh the prepared bytes are stored in the
// BVH's slot order (bvh.order maps a slot to its triangle), except for
// moller, whose leaves are 4-lane blocks instead (methods/moller_simd.h;
// `pre` stays empty). exact's leaves are 4-lane blocks of vertices too
// (methods/exact_simd.h: its stage 1), beside `pre` in slot order, which
// the lanes that stage 1 does not reject finish from.
template <class T>
struct PreparedMesh {
  const TriangleSet* set = nullptr;
  std::size_t stride = 0;
  std::vector<unsigned char> pre;                                             // per triangle, or per BVH slot
  Bvh bvh;                                                                    // --accel bvh only
  std::vector<moller_simd::Tri4<T>, DefaultInit<moller_simd::Tri4<T>>> tri4;  // per BVH leaf, moller only
  std::vector<exact_simd::Tri4<T>, DefaultInit<exact_simd::Tri4<T>>> xtri4;   // per BVH leaf, exact only
  std::vector<Vec3d> vertex_normal;  // smooth shading without vn: area-weighted
  Vec3d bs_center;
  double bs_radius = 0;
  Vec3d lo, hi;  // the box of its vertices, padded by `pad` (the BVH's padding)
  double pad = 0;
  double scale = 0;                      // max(its size, its farthest coordinate): pad = 1e-5 scale
  std::uint32_t one_leaf = Bvh::kEmpty;  // the BVH's only leaf, when it has one (at most 4 triangles)
  bool cull = false;                     // --cull, and the mesh is closed (cull_unsafe_reason)
  bool lanes4() const { return !tri4.empty() || !xtri4.empty(); }  // 4-lane leaves (moller's or exact's)
};

// Asks for a leaf block's cache lines ahead of its test.
template <class B>
[[gnu::always_inline]] inline void prefetch_block(const B& b) {
  const char* p = reinterpret_cast<const char*>(&b);
  for (std::size_t k = 0; k < sizeof(B); k += 64) __builtin_prefetch(p + k);
}

// A triangle's geometric normal, (B-A)x(C-A) normalised (zero for a
// degenerate one). Computed at each hit rather than stored per triangle:
// 24 bytes a triangle and a pass over the mesh before the first ray, for
// one cross product per shaded hit.
Vec3d unit_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d n = cross(b - a, c - a);  // length = twice the area
  const double len = length(n);
  return len > 0 ? n / len : Vec3d{0, 0, 0};
}

// A kernel's hits stray from their triangle by a few roundings of the
// magnitudes it subtracts (o - v, or o + t d): at precision T, about
// kReachRoundings 2^-24 (or 2^-53) times |o| + |v| (max norm). The BVH's
// padding (1e-5 of the mesh's scale, 168 float roundings) covers that for
// origins within about 9 scales of the mesh: shadow and reflected rays,
// most cameras. A ray from farther out (a camera at 1e5 looking at a unit
// mesh at the origin, 0.01 of rounding at every subtraction, more at a
// grazing angle) is moved along itself first, in double, to just before
// the mesh's bounding sphere (shift), and every mesh test, --accel none,
// sphere or bvh, sees that ray rounded to T: the same kernel answers for
// all three, and its hits are as near their triangles as a near ray's.
// Its t is t0 + the kernel's t.
constexpr double kReachRoundings = 16;
template <class T>
constexpr double unit_roundoff() {
  return sizeof(T) == 4 ? 0x1p-24 : 0x1p-53;
}
// The least T at or above x (the window's tmax for a t that T may not hold).
template <class T>
[[gnu::always_inline]] inline T t_above(double x) {
  if constexpr (sizeof(T) == 4)
    return bvh_detail::round_up(x);
  else
    return x;
}

// Is (t, object, prim) nearer than the best so far? Ties on t go to the lower
// object, then the lower triangle, so the answer does not depend on the order
// an acceleration structure visits them in.
bool nearer(double t, int object, int prim, const SceneHit& best) {
  if (t != best.t) return t < best.t;
  if (object != best.object) return object < best.object;
  return prim < best.prim;
}

}  // namespace

struct Tracer::Impl {
  const Scene& scene;
  RenderOptions opt;
  Camera camera;
  const Method* tri_method;
  const Method* sph_method;
  const Method* pln_method;

  std::vector<PreparedMesh<float>> meshes_f;
  std::vector<PreparedMesh<double>> meshes_d;
  std::vector<int> mesh_index;                 // object -> index into meshes_*, or -1
  TextureCache textures;                       // every texture and bump image, loaded here
  std::map<std::string, Texture> derivatives;  // height bumps: file -> (dx, dy)

  Impl(const Scene& s, const RenderOptions& o) : scene(s), opt(o), camera(s.camera, s.width, s.height) {
    tri_method = find_method(o.triangle_method);
    if (!tri_method || tri_method->kind != Kind::triangle)
      throw InputError("unknown triangle method \"" + o.triangle_method + "\"; valid: " + method_names(Kind::triangle));
    sph_method = find_method(o.sphere_method);
    if (!sph_method || sph_method->kind != Kind::sphere)
      throw InputError("unknown sphere method \"" + o.sphere_method + "\"; valid: " + method_names(Kind::sphere));
    pln_method = &default_method(Kind::plane);
    avx2 = o.simd && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    avx512 = avx2 && o.avx512 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
    if (o.samples_per_axis < 1 || o.samples_per_axis > 16)
      throw InputError("samples per axis must be between 1 and 16");
    mesh_index.assign(s.objects.size(), -1);
    shadow_cache_level1.assign(s.lights.size(), -1);
    shadow_cache_other.assign(s.lights.size(), -1);
    // A set placed by several objects (a scene repeating one mesh) is
    // prepared once (400 placements, 400 BVHs, 3.5 GB).
    std::map<const TriangleSet*, int> prepared;
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      if (s.objects[i].kind != Object::Kind::mesh) continue;
      const auto [it, fresh] =
          prepared.emplace(s.objects[i].mesh.get(), int(opt.use_double ? meshes_d.size() : meshes_f.size()));
      mesh_index[i] = it->second;
      if (!fresh) continue;
      if (opt.use_double)
        meshes_d.push_back(prepare<double>(*s.objects[i].mesh));
      else
        meshes_f.push_back(prepare<float>(*s.objects[i].mesh));
      // exact's leaves read their blocks alone (exact_lane): its records
      // (144 bytes a triangle in double) are not kept. The lone triangles'
      // soup keeps them: its traversals test records.
      auto drop_records = [&](auto& m) {
        if (m.xtri4.empty()) return;
        m.pre = {};
        set_neighbour_prefetch(m, m.xtri4.size() * sizeof(m.xtri4[0]));
      };
      if (opt.use_double)
        drop_records(meshes_d.back());
      else
        drop_records(meshes_f.back());
    }
    // The sphere far rays are moved to (shift): around every mesh, with the
    // least padding and the largest scale among them.
    {
      Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
      auto each = [&](const auto& ms) {
        for (const auto& m : ms) {
          lo = vmin(lo, m.lo);
          hi = vmax(hi, m.hi);
          meshes_pad = std::min(meshes_pad, m.pad);
          meshes_scale = std::max(meshes_scale, m.scale);
        }
      };
      // Not for the documents' angles and areas methods: they accept hits by
      // absolute tolerances, far beyond the rounding of their triangles, so
      // no padding covers them at any distance and moving their rays would
      // only change the documents' own float answers (document 004's cube,
      // seen from 600 units, takes its Heron NaN hits elsewhere).
      const bool absolute_tolerance = tri_method->name == "angles" || tri_method->name == "areas";
      if (!absolute_tolerance && opt.use_double) each(meshes_d);
      if (!absolute_tolerance && !opt.use_double) each(meshes_f);
      if (meshes_scale > 0) {
        meshes_center = (lo + hi) * 0.5;
        meshes_radius = length(hi - lo) * 0.5;
      }
    }
    build_object_bvh();
    init_glass();
    one_mesh_tri4 = avx2 && s.objects.size() == 1 && s.objects[0].kind == Object::Kind::mesh &&
                    !opt.pov_mesh_intersect && (opt.use_double ? meshes_d[0].lanes4() : meshes_f[0].lanes4());
    for (const Object& obj : s.objects) {
      if (obj.kind == Object::Kind::mesh)
        for (const Material& m : obj.mesh->materials) load_textures(m);
      else
        load_textures(obj.material);
    }
  }

  // Loads a material's images once, before any thread renders.
  void load_textures(const Material& m) {
    if (m.texture) load_named(m.texture->file, m.texture->named_at);
    if (m.bump) {
      const Texture& img = load_named(m.bump->file, m.bump->named_at);
      if (m.bump->variant == BumpVariant::height) {
        const std::string key = m.bump->file.lexically_normal().string();
        if (!derivatives.count(key)) {
          // 3 floats a texel, whatever the image's own size a texel.
          const std::uint64_t need = std::uint64_t(img.width) * std::uint64_t(img.height) * 3 * sizeof(float);
          if (need > available_memory())
            throw InputError(located(m.bump->file.string(), 0,
                                     "height bump map of " + std::to_string(img.width) + "x" +
                                         std::to_string(img.height) + " needs " + std::to_string(need >> 20) +
                                         " MB for its derivatives: not enough memory"));
          derivatives.emplace(key, height_derivatives(img));
        }
      }
    }
  }

  // POV-Ray bounds a scene's objects automatically once there are
  // Bounding_Threshold (3) of them; with --accel bvh so do we: a BVH over
  // the boxes of the spheres and meshes (a lone triangle is a one-triangle
  // mesh), planes tested for every ray. 30,000 lone triangles took 31 s at
  // 64x64 by a loop over all objects. The image is the same
  // bits as that loop's (ties on t go to the lower object whatever the
  // order; object_bvh = false renders the loop for the identity tests),
  // provided every hit a kernel reports lies in its object's box:
  //  - a mesh's box is its vertices' box padded as its own BVH's leaves
  //    are, so it holds every leaf that BVH can visit;
  //  - a sphere's box is padded beyond the kernels' rounding: the naive
  //    quadratics (seeds/001, seeds/004) report false hits up to
  //    sqrt(E) outside the sphere, E ~ 256 eps (|o| + |c|)^2 for a ray from
  //    o, so by 2 sqrt(E) with |o|, |c| <= `reach`. A ray from farther out
  //    (a reflection off a far plane) takes the loop instead.
  //  - lone triangles (one-triangle meshes) are not boxes of their own but
  //    one "soup": a mesh of all of them with its own BVH (leaves of 4,
  //    contiguous), each triangle mapped back to its object. The kernels
  //    see the same vertices and window, so the same hits; 30,000 of them
  //    as objects cost 12 times as much as in one mesh (a cache miss per
  //    object), as a soup about the same.
  static constexpr std::size_t kObjectBvhMin = 3;
  bool objects_bounded = false;  // the object BVH (and soup) in use
  Bvh object_bvh;                // over bounded[]; never prefetch_neighbours (traversed without those loops)
  std::vector<int> bounded;      // slot order -> object index
  std::vector<int> unbounded;    // planes
  double reach = 0;              // rays with |o_a| <= reach use object_bvh
  TriangleSet soup_set;          // the lone triangles' vertices, 3 each
  std::vector<int> soup_object;  // soup triangle -> object
  PreparedMesh<float> soup_f;
  PreparedMesh<double> soup_d;

  template <class T>
  const PreparedMesh<T>& soup() const {
    if constexpr (sizeof(T) == 4)
      return soup_f;
    else
      return soup_d;
  }

  bool object_bvh_for(const Vec3d& o) const { return objects_bounded && max_component(abs(o)) <= reach; }

  void build_object_bvh() {
    if (opt.accel != Accel::bvh || !opt.object_bvh || opt.pov_mesh_intersect) return;
    std::vector<int> objs, lone;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
      const Object& o = scene.objects[i];
      if (o.kind == Object::Kind::plane) continue;
      const std::size_t mi = std::size_t(mesh_index[i]);
      const bool one = o.kind == Object::Kind::mesh && o.mesh->triangles.size() == 1 &&
                       !(opt.use_double ? meshes_d[mi].cull : meshes_f[mi].cull);
      (one ? lone : objs).push_back(int(i));
    }
    if (objs.size() + lone.size() < kObjectBvhMin) return;
    objects_bounded = true;
    auto far = [](const Vec3d& p) { return max_component(abs(p)); };
    reach = std::max(far(scene.camera.position), 1.0);
    for (const PointLight& l : scene.lights) reach = std::max(reach, far(l.position));
    for (const int i : lone) {
      const TriangleSet& set = *scene.objects[std::size_t(i)].mesh;
      const auto& t = set.triangles[0];
      const int base = int(soup_set.positions.size());
      for (int v = 0; v < 3; ++v) {
        soup_set.positions.push_back(set.positions[std::size_t(t.v[std::size_t(v)])]);
        reach = std::max(reach, far(soup_set.positions.back()));
      }
      soup_set.triangles.push_back(MeshTriangle3{{base, base + 1, base + 2}, {-1, -1, -1}, {-1, -1, -1}, 0});
      soup_object.push_back(i);
    }
    soup_set.name = "lone triangles";
    soup_set.materials = {Material{}};
    if (!lone.empty()) {
      if (opt.use_double)
        soup_d = prepare<double>(soup_set, false);
      else
        soup_f = prepare<float>(soup_set, false);
    }
    std::vector<Vec3d> lo(objs.size()), hi(objs.size());
    for (std::size_t k = 0; k < objs.size(); ++k) {
      const Object& o = scene.objects[std::size_t(objs[k])];
      if (o.kind == Object::Kind::sphere) {
        const Vec3d r{o.sphere.radius, o.sphere.radius, o.sphere.radius};
        lo[k] = o.sphere.center - r;
        hi[k] = o.sphere.center + r;
      } else {
        const int mi = mesh_index[std::size_t(objs[k])];
        lo[k] = opt.use_double ? meshes_d[std::size_t(mi)].lo : meshes_f[std::size_t(mi)].lo;
        hi[k] = opt.use_double ? meshes_d[std::size_t(mi)].hi : meshes_f[std::size_t(mi)].hi;
      }
      reach = std::max(reach, std::max(far(lo[k]), far(hi[k])));
    }
    // A mesh's box is padded for rays from near it; the object BVH tests
    // the ray from anywhere within `reach` (a far camera) while the meshes'
    // kernels see it moved and rounded again (shift), off its line by a
    // few roundings of `reach`: the boxes are widened by that.
    for (std::size_t k = 0; k < objs.size(); ++k) {
      const Object& o = scene.objects[std::size_t(objs[k])];
      if (o.kind != Object::Kind::mesh) continue;
      const std::size_t mi = std::size_t(mesh_index[std::size_t(objs[k])]);
      const double scale = opt.use_double ? meshes_d[mi].scale : meshes_f[mi].scale;
      const double w = kReachRoundings * (opt.use_double ? unit_roundoff<double>() : unit_roundoff<float>()) *
                       (reach + scale) * (1 + 0x1p-20);
      lo[k] = lo[k] - Vec3d{w, w, w};
      hi[k] = hi[k] + Vec3d{w, w, w};
    }
    const double eps = opt.use_double ? 0x1p-52 : 0x1p-23;
    const double sphere_pad = 2 * std::sqrt(256 * eps) * 2 * reach;
    for (std::size_t k = 0; k < objs.size(); ++k) {
      const Object& o = scene.objects[std::size_t(objs[k])];
      if (o.kind != Object::Kind::sphere) continue;
      const double own = 1e-5 * std::max(2 * o.sphere.radius, far(o.sphere.center) + o.sphere.radius);
      const double pad = std::max(own, sphere_pad);
      lo[k] = lo[k] - Vec3d{pad, pad, pad};
      hi[k] = hi[k] + Vec3d{pad, pad, pad};
    }
    if (!objs.empty()) object_bvh = Bvh::build(lo, hi, 0.0, objs.size() < 4096 ? 1 : opt.threads);
    bounded.resize(object_bvh.order.size(), -1);
    for (std::size_t slot = 0; slot < object_bvh.order.size(); ++slot)
      if (object_bvh.order[slot] != Bvh::kNoTriangle) bounded[slot] = objs[object_bvh.order[slot]];
    for (std::size_t i = 0; i < scene.objects.size(); ++i)
      if (scene.objects[i].kind == Object::Kind::plane) unbounded.push_back(int(i));
  }

  // An image an MTL names: its errors name the MTL's line and the name as
  // written there ("m.mtl:7: map_Kd 'tex.png': cannot read texture: not an
  // image (a text file)"), not only the resolved path.
  const Texture& load_named(const std::filesystem::path& file, const std::string& named_at) {
    try {
      return textures.load(file);
    } catch (const InputError& e) {
      if (named_at.empty()) throw;
      const std::string what = e.what(), path = file.string();
      throw InputError(named_at + (what.rfind(path, 0) == 0 ? what.substr(path.size()) : ": " + what));
    }
  }

  // moller's 4-lane form answers bit for bit as its scalar one: with the
  // BVH its leaves are tested from tri4 alone, and the per-triangle bytes
  // are not made.
  bool bvh_tri4() const { return opt.accel == Accel::bvh && tri_method->name == "moller"; }
  // exact's 4-lane stage 1 answers as its scalar form (the lanes it does
  // not reject are finished by the scalar code from `pre`).
  bool bvh_exact4() const { return opt.accel == Accel::bvh && tri_method->name == "exact"; }

  // f(begin, end) over [0, n) in chunks on the tracer's threads; on this
  // one below 2 chunks (starting threads would cost more). The results
  // never depend on the split.
  void parallel_chunks(std::size_t n, const std::function<void(std::size_t, std::size_t)>& f) const {
    constexpr std::size_t kChunk = 16384;
    const int threads = opt.threads > 0 ? opt.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    if (threads == 1 || n < 2 * kChunk) {
      f(0, n);
      return;
    }
    std::atomic<std::size_t> next{0};
    run_workers(int(std::min<std::size_t>(std::size_t(threads), (n + kChunk - 1) / kChunk)), [&] {
      for (std::size_t b; (b = next.fetch_add(kChunk)) < n;) f(b, std::min(n, b + kChunk));
    });
  }

  template <class T>
  PreparedMesh<T> prepare(const TriangleSet& set, bool cull_check = true) const {
    PreparedMesh<T> m;
    m.set = &set;
    const auto& k = tri_method->triangle<T>();
    m.stride = k.pre_bytes;
    const bool pre = !bvh_tri4();
    if (pre) m.pre.resize(m.stride * set.triangles.size());
    if (pre)
      parallel_chunks(set.triangles.size(), [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const auto& tri = set.triangles[i];
          k.prepare(Vec3<T>(set.positions[tri.v[0]]), Vec3<T>(set.positions[tri.v[1]]),
                    Vec3<T>(set.positions[tri.v[2]]), m.pre.data() + i * m.stride);
        }
      });
    if (set.shading == Shading::smooth) m.vertex_normal = area_weighted_vertex_normals(set);
    Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (const auto& p : set.positions) {
      lo = vmin(lo, p);
      hi = vmax(hi, p);
    }
    if (opt.cull && cull_check) {
      const std::string why = cull_unsafe_reason(set);
      m.cull = why.empty();
      if (!m.cull)
        std::fprintf(stderr, "warning: %s: --cull not applied to this mesh: %s\n", set.name.c_str(), why.c_str());
    }
    m.bs_center = (lo + hi) * 0.5;
    for (const auto& p : set.positions) m.bs_radius = std::max(m.bs_radius, length(p - m.bs_center));
    // The BVH's boxes and the bounding sphere are widened by it: a float
    // kernel answers for the ray rounded to float, whose origin far out
    // moves by 2^-24 of its distance (at 1e6, 0.06), so its hits can lie
    // outside the mesh's exact sphere (182 pixels lost at 1e6).
    m.scale = std::max(length(hi - lo), std::max(max_component(abs(lo)), max_component(abs(hi))));
    m.pad = 1e-5 * m.scale;
    m.lo = lo - Vec3d{m.pad, m.pad, m.pad};
    m.hi = hi + Vec3d{m.pad, m.pad, m.pad};
    if (opt.accel == Accel::bvh) build_bvh(m, k, lo, hi);
    return m;
  }

  // Builds the mesh's BVH and re-lays the prepared bytes in its slot order.
  // Boxes are padded by a relative 1e-5 of the mesh's size and position, so
  // that rounding in the kernels (float ones too) never puts a hit outside
  // its box.
  template <class T>
  void build_bvh(PreparedMesh<T>& m, const TriangleKernels<T>& k, const Vec3d& mesh_lo, const Vec3d& mesh_hi) const {
    const TriangleSet& set = *m.set;
    const std::size_t n = set.triangles.size();
    const double size =
        std::max(length(mesh_hi - mesh_lo), std::max(max_component(abs(mesh_lo)), max_component(abs(mesh_hi))));
    // A small mesh (a scene's lone triangle) is built on this thread:
    // starting threads for each of 30,000 would cost more than the builds
    // (the tree is the same for every thread count).
    const int build_threads = n < 4096 ? 1 : opt.threads;
    m.bvh = Bvh::build(
        n,
        [&](std::size_t begin, std::size_t end, Vec3d* lo, Vec3d* hi) {
          for (std::size_t i = begin; i < end; ++i) {
            const auto& t = set.triangles[i];
            lo[i - begin] = vmin(set.positions[t.v[0]], vmin(set.positions[t.v[1]], set.positions[t.v[2]]));
            hi[i - begin] = vmax(set.positions[t.v[0]], vmax(set.positions[t.v[1]], set.positions[t.v[2]]));
          }
        },
        1e-5 * size, build_threads);
    if (m.bvh.nodes.size() == 1) {
      int leaves = 0, others = 0;
      for (const std::uint32_t c : m.bvh.nodes[0].child) {
        if (Bvh::is_leaf(c))
          ++leaves, m.one_leaf = c;
        else
          others += c != Bvh::kEmpty;
      }
      if (leaves != 1 || others != 0) m.one_leaf = Bvh::kEmpty;
    }
    const std::size_t slots = m.bvh.order.size();
    if (bvh_tri4()) {
      m.tri4.reserve(slots / 4);
      advise_huge_pages(m.tri4.data(), slots / 4 * sizeof(m.tri4[0]));
      m.tri4.resize(slots / 4);  // not zeroed here: every lane is written once below
      parallel_chunks(slots / 4, [&](std::size_t begin, std::size_t end) {
        // The slots visit the triangles in the tree's order, at random in
        // memory: each lane's triangle record and then its three vertices
        // are asked for ahead (16 and 8 blocks), so that the misses
        // overlap instead of following one another (the dragon's 253k
        // blocks: 75-120 ms before, 20-80 ms after, as the first touch of
        // the blocks' fresh pages varies).
        const std::uint32_t* order = m.bvh.order.data();
        const std::size_t last = slots / 4;
        for (std::size_t l = begin; l < end; ++l) {
          if (l + 16 < last)
            for (int j = 0; j < 4; ++j)
              if (const std::uint32_t t = order[4 * (l + 16) + std::size_t(j)]; t != Bvh::kNoTriangle)
                __builtin_prefetch(&set.triangles[t]);
          if (l + 8 < last)
            for (int j = 0; j < 4; ++j)
              if (const std::uint32_t t = order[4 * (l + 8) + std::size_t(j)]; t != Bvh::kNoTriangle)
                for (int k = 0; k < 3; ++k) __builtin_prefetch(&set.positions[set.triangles[t].v[k]]);
          for (int j = 0; j < 4; ++j) {
            const std::uint32_t t = order[4 * l + std::size_t(j)];
            if (t == Bvh::kNoTriangle) {  // zeros: det = 0, never a hit
              m.tri4[l].set(j, Vec3<T>{0, 0, 0}, Vec3<T>{0, 0, 0}, Vec3<T>{0, 0, 0});
              continue;
            }
            const auto& tri = set.triangles[t];
            m.tri4[l].set(j, Vec3<T>(set.positions[tri.v[0]]), Vec3<T>(set.positions[tri.v[1]]),
                          Vec3<T>(set.positions[tri.v[2]]));
          }
        }
      });
      set_neighbour_prefetch(m, m.tri4.size() * sizeof(m.tri4[0]));
      return;
    }
    std::vector<unsigned char> pre(slots * m.stride);
    parallel_chunks(slots, [&](std::size_t begin, std::size_t end) {
      for (std::size_t s = begin; s < end; ++s) {
        if (m.bvh.order[s] != Bvh::kNoTriangle)
          std::memcpy(pre.data() + s * m.stride, m.pre.data() + std::size_t(m.bvh.order[s]) * m.stride, m.stride);
        else
          std::memset(pre.data() + s * m.stride, 0, m.stride);
      }
    });
    m.pre = std::move(pre);
    if (bvh_exact4()) {
      // Huge pages as for moller's blocks: the dragon's 72 MB of blocks
      // in 4 KiB pages cost a TLB miss on most leaves (0.52x Embree on
      // shadow rays without, 0.84x with, in one session).
      m.xtri4.reserve(slots / 4);
      advise_huge_pages(m.xtri4.data(), slots / 4 * sizeof(m.xtri4[0]));
      m.xtri4.resize(slots / 4);
      parallel_chunks(slots / 4, [&](std::size_t begin, std::size_t end) {
        for (std::size_t l = begin; l < end; ++l)
          for (std::size_t j = 0; j < 4; ++j) {
            const std::size_t s = 4 * l + j;
            if (m.bvh.order[s] == Bvh::kNoTriangle) {  // never looked at: the leaf's count excludes it
              m.xtri4[l].set(int(j), Vec3<T>{0, 0, 0}, Vec3<T>{0, 0, 0}, Vec3<T>{0, 0, 0});
              continue;
            }
            const auto& p = exact_pre(m, s);
            m.xtri4[l].set(int(j), p.a, p.b, p.c);
          }
      });
    }
    set_neighbour_prefetch(m, m.pre.size() + m.xtri4.size() * sizeof(m.xtri4[0]));
  }

  // exact's prepared record of BVH slot s.
  template <class T>
  static const exact::detail::Prepared<T>& exact_pre(const PreparedMesh<T>& m, std::size_t s) {
    return *reinterpret_cast<const exact::detail::Prepared<T>*>(m.pre.data() + s * m.stride);
  }

  // Above this many bytes of nodes and leaves, a mesh's BVH traversal asks
  // for the nodes and leaves beside those it meets (by_size; accel/bvh.h,
  // prefetch_node, says why): about a last-level cache, 32 MiB on the EPYC
  // this was measured on (the dragon's 90 MB gain 8%, the bunny's 7 MB
  // would lose 2-4%). A constant, not the machine's: glibc's sysconf there
  // reports 320 MiB, the whole package's L3.
  static constexpr std::size_t kNeighbourPrefetchBytes = std::size_t(32) << 20;
  template <class T>
  void set_neighbour_prefetch(PreparedMesh<T>& m, std::size_t leaf_bytes) const {
    using P = RenderOptions::NeighbourPrefetch;
    const std::size_t bytes = m.bvh.nodes.size() * sizeof(BvhNode) + leaf_bytes;
    m.bvh.prefetch_neighbours = opt.neighbour_prefetch == P::always ||
                                (opt.neighbour_prefetch == P::by_size && bytes > kNeighbourPrefetchBytes);
  }

  // A mesh whose BVH is one leaf (a scene's lone triangle), reached through
  // the object BVH (`boxed`: its box, the leaf's, just tested), has that
  // leaf tested without a traversal's box tests again, which cost more
  // than the triangle when a scene holds thousands of them. The same hits:
  // the kernels apply the ray's window themselves.
  template <bool kClosest, bool kFma, class T, class P, class Leaf, class Pre>
  [[gnu::always_inline]] static inline void walk_mesh(const PreparedMesh<P>& m, bool boxed, const Vec3<T>& o,
                                                      const Vec3<T>& d, T tmin, const T& tmax, Leaf&& leaf, Pre&& pre) {
    if (boxed && m.one_leaf != Bvh::kEmpty) {
      leaf(Bvh::leaf_first(m.one_leaf), Bvh::leaf_count(m.one_leaf));
      return;
    }
    traverse<kClosest, kFma>(m.bvh, o, d, tmin, tmax, leaf, pre);
  }
  template <bool kClosest, bool kFma, class T, class P, class Leaf>
  [[gnu::always_inline]] static inline void walk_mesh(const PreparedMesh<P>& m, bool boxed, const Vec3<T>& o,
                                                      const Vec3<T>& d, T tmin, const T& tmax, Leaf&& leaf) {
    walk_mesh<kClosest, kFma>(m, boxed, o, d, tmin, tmax, leaf, [](std::uint32_t) {});
  }

  // Where a ray from far out is moved to before the meshes' kernels see it
  // (kReachRoundings): 0 (not moved) for an origin within reach of the
  // padding, else the t a diameter before the meshes' bounding sphere's
  // nearest point to the line (never behind the origin). One t for every
  // mesh of the scene, so that a mesh's triangles see the same ray
  // whichever way they are reached (as meshes of their own with --accel
  // none or sphere, through the object BVH or in the lone triangles' soup).
  Vec3d meshes_center;
  double meshes_radius = 0, meshes_pad = 1e300, meshes_scale = 0;
  template <class T>
  [[gnu::always_inline]] inline double shift(const Ray<double>& r) const {
    if (!(kReachRoundings * unit_roundoff<T>() * (max_component(abs(r.o)) + meshes_scale) > meshes_pad)) return 0;
    const double dd = dot(r.d, r.d);
    const double t = dot(meshes_center - r.o, r.d) / dd - 2 * meshes_radius / std::sqrt(dd);
    return t > 0 && t < 1e300 ? t : 0;
  }
  // The ray r moved by t0 and rounded to T, its window [r.tmin, tmax] in
  // its own t (tmax rounded up: a tie at the best hit so far still counts).
  template <class T>
  static Ray<T> moved(const Ray<double>& r, double t0, double tmax) {
    return {Vec3<T>(r.o + r.d * t0), Vec3<T>(r.d), T(r.tmin - t0), t_above<T>(tmax - t0)};
  }
  // The same for an any-hit ray already in T.
  template <class T>
  [[gnu::always_inline]] inline Ray<T> moved_any(const Ray<T>& r) const {
    const Ray<double> rd(r);
    const double t0 = shift<T>(rd);
    return t0 != 0 ? moved<T>(rd, t0, rd.tmax) : r;
  }

  template <class T>
  const std::vector<PreparedMesh<T>>& meshes() const {
    if constexpr (sizeof(T) == 4)
      return meshes_f;
    else
      return meshes_d;
  }

  // A lane of exact's leaf that its stage 1 did not reject, finished by the
  // scalar code from the lane's U, V, W, with the triangle's stage 1b terms
  // made from the block's vertices (edges(), the very values the prepared
  // record holds): the block's lines are in cache, a record beside it was
  // not (on the dragon, a miss to memory for each lane left, 0.54x Embree
  // on primary rays). Not inlined: most leaves reach it for no lane, and
  // the x87 and exact stages would crowd the traversal.
  template <class T, bool kNeedT>
  [[gnu::noinline]] static std::optional<TriangleHit<T>> exact_lane(exact::detail::Signs sg, double U, double V,
                                                                    double W, int s, const Ray<T>& r,
                                                                    const exact_simd::Tri4<T>& blk, int l, bool cull) {
    const Vec3<T> a{blk.v[0][l], blk.v[1][l], blk.v[2][l]}, b{blk.v[3][l], blk.v[4][l], blk.v[5][l]},
        c{blk.v[6][l], blk.v[7][l], blk.v[8][l]};
    return exact::detail::after_signs(sg, U, V, W, s, r, a, b, c, nullptr, cull, kNeedT);
  }

  // exact's 4-lane leaves through the mesh's BVH (kClosest: nearest first,
  // the window narrowed by the caller through `r`): on_hit(slot, hit) for
  // every lane's hit until it returns true.
  template <bool kClosest, bool kFma, class T, class OnHit>
  [[gnu::always_inline]] static inline void walk_exact(const PreparedMesh<T>& m, bool boxed, const Ray<T>& r, bool cull,
                                                       OnHit&& on_hit) {
    const exact_simd::RayLanes lanes = exact_simd::ray_lanes(r);
    walk_mesh<kClosest, kFma>(
        m, boxed, r.o, r.d, r.tmin, r.tmax,
        [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
          bool stop = false;
          exact_simd::leaf4<kFma>(
              lanes, r.tmax, m.xtri4[first / 4], (1 << count) - 1,
              [&](int l, exact::detail::Signs sg, double U, double V, double W, int s) __attribute__((always_inline)) {
                if (auto h = exact_lane<T, kClosest>(sg, U, V, W, s, r, m.xtri4[first / 4], l, cull))
                  stop = on_hit(first + std::uint32_t(l), *h);
                return stop;
              });
          return stop;
        },
        [&](std::uint32_t first) __attribute__((always_inline)) { prefetch_block(m.xtri4[first / 4]); });
  }

  // The closest hit in a mesh of 4-wide leaves (Möller's tri4 or exact's xtri4) through its
  // BVH: consider(t, object, prim, b1, b2) for every hit in the window,
  // which it narrows.
  template <bool kFma, class T, class Consider>
  [[gnu::always_inline]] static inline void closest_in_tri4(const PreparedMesh<T>& m, bool boxed, const Ray<T>& window,
                                                            int oi, bool cull, Consider&& consider) {
    if (!m.xtri4.empty()) {
      walk_exact<true, kFma>(
          m, boxed, window, cull, [&](std::uint32_t slot, const TriangleHit<T>& h) __attribute__((always_inline)) {
            consider(double(h.t), oi, int(m.bvh.order[slot]), double(h.b1), double(h.b2));
            return false;
          });
      return;
    }
    const moller_simd::RayLanes<T> lanes = moller_simd::ray_lanes(window);
    walk_mesh<true, kFma>(
        m, boxed, window.o, window.d, window.tmin, window.tmax,
        [&](std::uint32_t first, std::uint32_t) __attribute__((always_inline)) {
          moller_simd::Hit4<T> h;
          moller_simd::hit4<kFma>(lanes, window.tmax, m.tri4[first / 4], cull, h);
          for (int hits = h.hits; hits; hits &= hits - 1) {
            const int l = __builtin_ctz(unsigned(hits));
            consider(double(h.t[l]), oi, int(m.bvh.order[first + l]), double(h.b1[l]), double(h.b2[l]));
          }
          return false;
        },
        [&](std::uint32_t first) __attribute__((always_inline)) { prefetch_block(m.tri4[first / 4]); });
  }
  template <bool kFma, class T>
  [[gnu::always_inline]] static inline bool any_in_tri4(const PreparedMesh<T>& m, bool boxed, const Ray<T>& r) {
    bool hit = false;
    if (!m.xtri4.empty()) {
      // never culled: see closest()
      walk_exact<false, kFma>(
          m, boxed, r,
          false, [&](std::uint32_t, const TriangleHit<T>&) __attribute__((always_inline)) { return hit = true; });
      return hit;
    }
    const moller_simd::RayLanes<T> lanes = moller_simd::ray_lanes(r);
    walk_mesh<false, kFma>(
        m, boxed, r.o, r.d, r.tmin, r.tmax,
        [&](std::uint32_t first, std::uint32_t) __attribute__((always_inline)) {
          moller_simd::Hit4<T> h;
          moller_simd::hit4<kFma>(lanes, r.tmax, m.tri4[first / 4], false, h);  // never culled: see closest()
          return hit = h.hits != 0;
        },
        [&](std::uint32_t first) __attribute__((always_inline)) { prefetch_block(m.tri4[first / 4]); });
    return hit;
  }

  // A scene that is one mesh under the BVH with Möller's 4-wide leaves (a
  // bare .obj, the benchmark's rungs) has entry points of its own, without
  // the loop over objects: their set-up (the object loop, the kind switch,
  // the options read per ray, and the registers they take from the box
  // test's set-up) cost about 200 of a primary ray's 560 instructions
  // (callgrind, the bunny), where most rays leave after one node. The same
  // kernels, window and tie rule, so the same hits.
  bool one_mesh_tri4 = false;
  template <class T>
  [[gnu::always_inline]] inline std::optional<SceneHit> closest_one_mesh(const Ray<double>& rd, bool cull) const {
    SceneHit best;
    best.t = std::numeric_limits<double>::infinity();
    const auto& m = meshes<T>()[0];
    const double t0 = shift<T>(rd);  // as closest_impl's
    Ray<T> window = t0 != 0 ? moved<T>(rd, t0, rd.tmax) : Ray<T>(rd);
    closest_in_tri4<true>(
        m, false, window, 0,
        cull && m.cull, [&](double t, int obj, int prim, double b1, double b2) __attribute__((always_inline)) {
          if (nearer(t0 + t, obj, prim, best)) {
            best = {t0 + t, obj, prim, b1, b2};
            window.tmax = T(t);
          }
        });
    if (best.object < 0) return std::nullopt;
    return best;
  }
  template <class T>
  [[gnu::target("avx2,fma"), gnu::noinline]] std::optional<SceneHit> closest_one_mesh_avx2(const Ray<double>& rd,
                                                                                           bool cull) const {
    return closest_one_mesh<T>(rd, cull);
  }
  template <class T>
  [[gnu::target("avx2,fma"), gnu::noinline]] bool occluded_one_mesh_avx2(const Ray<T>& r) const {
    return any_in_tri4<true>(meshes<T>()[0], false, moved_any(r));
  }
  // The same compiled for AVX-512 (F, VL, DQ, BW) where the CPU has it: the
  // same instructions' results, with 32 vector registers (fewer values
  // kept on the stack) and mask compares; 2-6% faster than AVX2 here.
  bool avx512 = false;
  template <class T>
  [[gnu::target("avx2,fma,avx512f,avx512vl,avx512dq,avx512bw"), gnu::noinline]] std::optional<SceneHit>
  closest_one_mesh_avx512(const Ray<double>& rd, bool cull) const {
    return closest_one_mesh<T>(rd, cull);
  }
  template <class T>
  [[gnu::target("avx2,fma,avx512f,avx512vl,avx512dq,avx512bw"), gnu::noinline]] bool occluded_one_mesh_avx512(
      const Ray<T>& r) const {
    return any_in_tri4<true>(meshes<T>()[0], false, moved_any(r));
  }

  // Closest hit at precision T. The ray arrives in double (shading is done in
  // double); the kernels see it converted to T. Inlined into closest() and
  // closest_avx2(), which compile it for baseline x86-64 and for AVX2 and
  // FMA (kFma: the BVH's fused box test).
  // kObjects: the search through the object BVH (3 or more bounded objects),
  // compiled in its own, not inlined, functions so that it does not weigh on
  // the scenes without one (one mesh: every extra traversal inlined here
  // cost 7% on primary rays).
  template <class T, bool kFma, bool kObjects = false>
  [[gnu::always_inline]] inline std::optional<SceneHit> closest_impl(const Ray<double>& rd, int only, bool cull) const {
    const Ray<T> r(rd);
    SceneHit best;
    best.t = std::numeric_limits<double>::infinity();
    Ray<T> window = r;
    auto consider = [&](double t, int obj, int prim, double b1, double b2) __attribute__((always_inline)) {
      if (nearer(t, obj, prim, best)) {
        best = {t, obj, prim, b1, b2};
        window.tmax = t_above<T>(t);
      }
    };
    // boxed: the object BVH has just tested the object's box.
    auto visit = [&](std::size_t oi, bool boxed) __attribute__((always_inline)) {
      const Object& o = scene.objects[oi];
      switch (o.kind) {
        case Object::Kind::sphere: {
          if (auto h = sph_method->sphere<T>().hit(window, Vec3<T>(o.sphere.center), T(o.sphere.radius)))
            consider(double(h->t), int(oi), 0, 0, 0);
          break;
        }
        case Object::Kind::plane: {
          if (auto h = pln_method->plane<T>().hit(window, Vec3<T>(o.plane.normal), T(o.plane.offset)))
            consider(double(h->t), int(oi), 0, 0, 0);
          break;
        }
        case Object::Kind::mesh: {
          const auto& m = meshes<T>()[mesh_index[oi]];
          const auto& k = tri_method->triangle<T>();
          if (opt.pov_mesh_intersect) {
            for (const SceneHit& h : pov_mesh_hits(rd, m))
              if (h.t >= double(window.tmin) && h.t <= double(window.tmax)) consider(h.t, int(oi), h.prim, h.b1, h.b2);
            break;
          }
          // The ray this mesh's kernels see (shift): the window itself, or
          // from far out moved to just before the mesh; hits at t0 + t.
          const double t0 = shift<T>(rd);
          Ray<T> lr = window;
          if (t0 != 0) lr = moved<T>(rd, t0, best.t);
          auto local = [&](double t, int obj, int prim, double b1, double b2) __attribute__((always_inline)) {
            consider(t0 + t, obj, prim, b1, b2);
            lr.tmax = std::min(lr.tmax, T(t));
          };
          if (opt.accel == Accel::bvh) {
            if (m.lanes4()) {
              closest_in_tri4<kFma>(m, boxed, lr, int(oi), cull && m.cull, local);
              break;
            }
            walk_mesh<true, kFma>(
                m, boxed, lr.o, lr.d, lr.tmin,
                lr.tmax, [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
                  for (std::uint32_t slot = first; slot < first + count; ++slot)
                    if (auto h = k.hit_pre(lr, m.pre.data() + slot * m.stride, cull && m.cull))
                      local(double(h->t), int(oi), int(m.bvh.order[slot]), double(h->b1), double(h->b2));
                  return false;
                });
            break;
          }
          if (opt.accel == Accel::sphere && !segment_meets_ball(Ray<double>(lr), m.bs_center, m.bs_radius + m.pad))
            break;
          const std::size_t n = m.set->triangles.size();
          for (std::size_t i = 0; i < n; ++i)
            if (auto h = k.hit_pre(lr, m.pre.data() + i * m.stride, cull && m.cull))
              local(double(h->t), int(oi), int(i), double(h->b1), double(h->b2));
          break;
        }
      }
    };
    if constexpr (!kObjects) {
      if (only >= 0) {
        visit(std::size_t(only), false);
      } else {
        for (std::size_t oi = 0; oi < scene.objects.size(); ++oi) visit(oi, false);
      }
    } else {
      for (const int oi : unbounded) visit(std::size_t(oi), false);
      if (const auto& m = soup<T>(); !m.bvh.nodes.empty()) {
        const double t0 = shift<T>(rd);  // as a mesh's (visit)
        Ray<T> lr = t0 != 0 ? moved<T>(rd, t0, best.t) : window;
        auto local = [&](double t, int obj, int prim, double b1, double b2) __attribute__((always_inline)) {
          consider(t0 + t, obj, prim, b1, b2);
          lr.tmax = std::min(lr.tmax, T(t));
        };
        if (!m.tri4.empty()) {
          const moller_simd::RayLanes<T> lanes = moller_simd::ray_lanes(lr);
          traverse<true, kFma>(
              m.bvh, lr.o, lr.d, lr.tmin, lr.tmax,
              [&](std::uint32_t first, std::uint32_t) __attribute__((always_inline)) {
                moller_simd::Hit4<T> h;
                moller_simd::hit4<kFma>(lanes, lr.tmax, m.tri4[first / 4], false, h);
                for (int hits = h.hits; hits; hits &= hits - 1) {
                  const int l = __builtin_ctz(unsigned(hits));
                  local(double(h.t[l]), soup_object[m.bvh.order[first + l]], 0, double(h.b1[l]), double(h.b2[l]));
                }
                return false;
              },
              [&](std::uint32_t first) __attribute__((always_inline)) { prefetch_block(m.tri4[first / 4]); });
        } else {
          const auto& k = tri_method->triangle<T>();
          traverse<true, kFma>(
              m.bvh, lr.o, lr.d, lr.tmin,
              lr.tmax, [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
                for (std::uint32_t slot = first; slot < first + count; ++slot)
                  if (auto h = k.hit_pre(lr, m.pre.data() + slot * m.stride, false))
                    local(double(h->t), soup_object[m.bvh.order[slot]], 0, double(h->b1), double(h->b2));
                return false;
              });
        }
      }
      traverse<true, kFma, false>(
          object_bvh, window.o, window.d, window.tmin,
          window.tmax, [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
            for (std::uint32_t slot = first; slot < first + count; ++slot) visit(std::size_t(bounded[slot]), true);
            return false;
          });
    }
    if (best.object < 0) return std::nullopt;
    return best;
  }

  // The hits of a mesh that POV-Ray's mesh2 reports for a ray (before any
  // window but its own t >= 1e-6), with POV's barycentrics: each triangle by
  // its own test (pov_mesh_intersect), and only those its bounding-box tree
  // reaches (Mesh::intersect_bbox_tree). That search takes boxes in the
  // order the ray enters them and stops at the first box entered beyond the
  // nearest hit so far, so a triangle whose own box the ray enters after
  // that hit is never tested, whatever the caller then rejects: a
  // neighbouring triangle met at t = 1e-4 from a shadow ray's origin (then
  // refused by the shadow test's t > 1e-3) hides the rest of the mesh. The
  // order does not depend on the tree: a box's children are entered no
  // earlier than it, so the leaves come out by their own entry depth.
  template <class T>
  std::vector<SceneHit> pov_mesh_hits(const Ray<double>& r, const PreparedMesh<T>& m) const {
    const TriangleSet& set = *m.set;
    struct Candidate {
      double entry;
      SceneHit hit;
    };
    std::vector<Candidate> found;
    auto test = [&](int prim) {
      const MeshTriangle3& tri = set.triangles[prim];
      const Vec3d &a = set.positions[tri.v[0]], &b = set.positions[tri.v[1]], &c = set.positions[tri.v[2]];
      const auto t = pov_mesh_intersect(r, a, b, c);
      if (!t) return;
      const PovMeshHit ph = pov_mesh_hit(r, a, b, c);
      found.push_back(
          {box_entry(r, to_float32(a), to_float32(b), to_float32(c)), SceneHit{*t, -1, prim, ph.b1, ph.b2}});
    };
    if (opt.accel == Accel::bvh) {
      const Ray<double> all{r.o, r.d, 0.0, std::numeric_limits<double>::infinity()};
      // Every leaf the ray's boxes reach (any-hit order; sorted below).
      traverse<false>(m.bvh, all.o, all.d, all.tmin, all.tmax, [&](std::uint32_t first, std::uint32_t count) {
        for (std::uint32_t slot = first; slot < first + count; ++slot) test(int(m.bvh.order[slot]));
        return false;
      });
    } else {
      for (std::size_t i = 0; i < set.triangles.size(); ++i) test(int(i));
    }
    std::sort(found.begin(), found.end(), [](const Candidate& x, const Candidate& y) { return x.entry < y.entry; });
    std::vector<SceneHit> out;
    double best = std::numeric_limits<double>::infinity();
    for (const Candidate& c : found) {
      if (c.entry > best) break;
      out.push_back(c.hit);
      best = std::min(best, c.hit.t);
    }
    return out;
  }

  // Where the ray enters the bounding box of a triangle (slabs; negative
  // when it starts inside).
  static double box_entry(const Ray<double>& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d lo = vmin(a, vmin(b, c)), hi = vmax(a, vmax(b, c));
    double entry = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      if (r.d[k] == 0) continue;
      const double t0 = (lo[k] - r.o[k]) / r.d[k], t1 = (hi[k] - r.o[k]) / r.d[k];
      entry = std::max(entry, std::min(t0, t1));
    }
    return entry;
  }

  // Is anything in the ray's window? (shadow rays) Inlined as closest_impl.
  template <class T, bool kFma, bool kObjects = false>
  [[gnu::always_inline]] inline bool occluded_impl(const Ray<T>& r) const {
    // Is object oi in the ray's window?
    auto visit = [&](std::size_t oi, bool boxed) __attribute__((always_inline))->bool {
      const Object& o = scene.objects[oi];
      switch (o.kind) {
        case Object::Kind::sphere:
          if (sph_method->sphere<T>().any(r, Vec3<T>(o.sphere.center), T(o.sphere.radius))) return true;
          break;
        case Object::Kind::plane:
          if (pln_method->plane<T>().any(r, Vec3<T>(o.plane.normal), T(o.plane.offset))) return true;
          break;
        case Object::Kind::mesh: {
          const auto& m = meshes<T>()[mesh_index[oi]];
          const auto& k = tri_method->triangle<T>();
          if (opt.pov_mesh_intersect) {
            for (const SceneHit& h : pov_mesh_hits(Ray<double>(r), m))
              if (h.t >= double(r.tmin) && h.t <= double(r.tmax)) return true;
            break;
          }
          const Ray<T> lr = moved_any(r);  // as closest_impl's
          if (opt.accel == Accel::bvh) {
            bool hit = false;
            if (m.lanes4()) {
              hit = any_in_tri4<kFma>(m, boxed, lr);
            } else {
              walk_mesh<false, kFma>(
                  m, boxed, lr.o, lr.d, lr.tmin,
                  lr.tmax, [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
                    for (std::uint32_t slot = first; slot < first + count; ++slot)
                      if (k.any_pre(lr, m.pre.data() + slot * m.stride, false)) return hit = true;
                    return false;
                  });
            }
            if (hit) return true;
            break;
          }
          if (opt.accel == Accel::sphere &&
              !segment_meets_ball(static_cast<Ray<double>>(lr), m.bs_center, m.bs_radius + m.pad))
            break;
          const std::size_t n = m.set->triangles.size();
          for (std::size_t i = 0; i < n; ++i)
            if (k.any_pre(lr, m.pre.data() + i * m.stride, false)) return true;
          break;
        }
      }
      return false;
    };
    if constexpr (kObjects) {
      for (const int oi : unbounded)
        if (visit(std::size_t(oi), false)) return true;
      bool hit = false;
      if (const auto& m = soup<T>(); !m.bvh.nodes.empty()) {
        const Ray<T> lr = moved_any(r);  // as a mesh's (visit)
        if (!m.tri4.empty()) {
          const moller_simd::RayLanes<T> lanes = moller_simd::ray_lanes(lr);
          traverse<false, kFma>(
              m.bvh, lr.o, lr.d, lr.tmin, lr.tmax,
              [&](std::uint32_t first, std::uint32_t) __attribute__((always_inline)) {
                moller_simd::Hit4<T> h;
                moller_simd::hit4<kFma>(lanes, lr.tmax, m.tri4[first / 4], false, h);
                return hit = h.hits != 0;
              },
              [&](std::uint32_t first) __attribute__((always_inline)) { prefetch_block(m.tri4[first / 4]); });
        } else {
          const auto& k = tri_method->triangle<T>();
          traverse<false, kFma>(
              m.bvh, lr.o, lr.d, lr.tmin,
              lr.tmax, [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
                for (std::uint32_t slot = first; slot < first + count; ++slot)
                  if (k.any_pre(lr, m.pre.data() + slot * m.stride, false)) return hit = true;
                return false;
              });
        }
        if (hit) return true;
      }
      traverse<false, kFma, false>(
          object_bvh, r.o, r.d, r.tmin,
          r.tmax, [&](std::uint32_t first, std::uint32_t count) __attribute__((always_inline)) {
            for (std::uint32_t slot = first; slot < first + count; ++slot)
              if (visit(std::size_t(bounded[slot]), true)) return hit = true;
            return false;
          });
      return hit;
    } else {
      for (std::size_t oi = 0; oi < scene.objects.size(); ++oi)
        if (visit(oi, false)) return true;
      return false;
    }
  }

  // The SIMD paths chosen at run time: the BVH's 8-wide box tests and the
  // double leaves are one AVX register each where the CPU has AVX2 (and
  // FMA, for the fused box test), two SSE registers otherwise; the answers
  // are the same bits either way.
  bool avx2 = false;

  // `only` >= 0 restricts the search to that one object (POV-Ray's shadow
  // cache asks about the object that shadowed the previous pixel).
  template <class T>
  [[gnu::noinline]] std::optional<SceneHit> closest_objects_base(const Ray<double>& rd, bool cull) const {
    return closest_impl<T, false, true>(rd, -1, cull);
  }
  template <class T>
  [[gnu::target("avx2,fma"), gnu::noinline]] std::optional<SceneHit> closest_objects_avx2(const Ray<double>& rd,
                                                                                          bool cull) const {
    return closest_impl<T, true, true>(rd, -1, cull);
  }
  template <class T>
  std::optional<SceneHit> closest_base(const Ray<double>& rd, int only, bool cull) const {
    if (only < 0 && object_bvh_for(rd.o)) return closest_objects_base<T>(rd, cull);
    return closest_impl<T, false>(rd, only, cull);
  }
  template <class T>
  [[gnu::target("avx2,fma")]] std::optional<SceneHit> closest_avx2(const Ray<double>& rd, int only, bool cull) const {
    if (only < 0 && object_bvh_for(rd.o)) return closest_objects_avx2<T>(rd, cull);
    return closest_impl<T, true>(rd, only, cull);
  }
  // `cull`: --cull applies to this ray (a camera ray). Culling a closed,
  // outward-wound mesh changes nothing only for rays from outside it: a
  // shadow or reflected ray leaving a smooth-shaded point near the
  // terminator can run into the mesh (its shading normal faces the light,
  // its geometric normal away), where culled back faces let it through
  // (a lit seam). Secondary rays are never culled.
  template <class T>
  std::optional<SceneHit> closest(const Ray<double>& rd, int only = -1, bool cull = false) const {
    if (one_mesh_tri4 && only <= 0)
      return avx512 ? closest_one_mesh_avx512<T>(rd, cull) : closest_one_mesh_avx2<T>(rd, cull);
    return avx2 ? closest_avx2<T>(rd, only, cull) : closest_base<T>(rd, only, cull);
  }
  template <class T>
  [[gnu::noinline]] bool occluded_objects_base(const Ray<T>& r) const {
    return occluded_impl<T, false, true>(r);
  }
  template <class T>
  [[gnu::target("avx2,fma"), gnu::noinline]] bool occluded_objects_avx2(const Ray<T>& r) const {
    return occluded_impl<T, true, true>(r);
  }
  template <class T>
  bool occluded_base(const Ray<T>& r) const {
    if (object_bvh_for(Vec3d(r.o))) return occluded_objects_base<T>(r);
    return occluded_impl<T, false>(r);
  }
  template <class T>
  [[gnu::target("avx2,fma")]] bool occluded_avx2(const Ray<T>& r) const {
    if (object_bvh_for(Vec3d(r.o))) return occluded_objects_avx2<T>(r);
    return occluded_impl<T, true>(r);
  }
  template <class T>
  bool occluded(const Ray<T>& r) const {
    if (one_mesh_tri4) return avx512 ? occluded_one_mesh_avx512<T>(r) : occluded_one_mesh_avx2<T>(r);
    return avx2 ? occluded_avx2<T>(r) : occluded_base<T>(r);
  }

  std::optional<SceneHit> intersect(const Ray<double>& r, bool camera) const {
    return opt.use_double ? closest<double>(r, -1, camera) : closest<float>(r, -1, camera);
  }

  // The surface at a hit: point, geometric and shading normals, material,
  // and the error bound of the point for the normal-offset strategy.
  struct Surface {
    Vec3d p, ng, n, p_error;
    int object = -1, prim = -1;  // the hit's
    const Material* material;
    bool has_uv = false;
    double u = 0, v = 0;
    std::optional<UvBasis> basis;  // meshes with UVs and a bump map
  };

  Surface surface(const Ray<double>& ray, const SceneHit& h) const {
    Surface s;
    s.object = h.object;
    s.prim = h.prim;
    const Object& o = scene.objects[h.object];
    s.p = ray.at(h.t);
    switch (o.kind) {
      case Object::Kind::sphere:
        // normal-offset's bound (point_error) is pbrt's for a point on the
        // sphere: move it there. The other strategies keep POV-Ray's o + t d.
        if (opt.self_intersection == SelfIntersection::normal_offset)
          s.p = reproject_onto_sphere(s.p, o.sphere.center, o.sphere.radius);
        s.ng = s.n = (s.p - o.sphere.center) / o.sphere.radius;
        s.material = &o.material;
        break;
      case Object::Kind::plane:
        s.ng = s.n = o.plane.normal;
        s.material = &o.material;
        break;
      case Object::Kind::mesh: {
        const TriangleSet& set = *o.mesh;
        const MeshTriangle3& tri = set.triangles[h.prim];
        const Vec3d& a = set.positions[tri.v[0]];
        const Vec3d& b = set.positions[tri.v[1]];
        const Vec3d& c = set.positions[tri.v[2]];
        double b1 = h.b1, b2 = h.b2;
        // The hit point from the barycentrics lies on the triangle's plane
        // (o + t d may not, by t's rounding).
        s.p = a * (1 - b1 - b2) + b * b1 + c * b2;
        if (opt.pov_mesh_hit)
          if (const PovMeshHit ph = pov_mesh_hit(ray, a, b, c); ph.ok) {
            s.p = ph.p;
            b1 = ph.b1;
            b2 = ph.b2;
          }
        const double b0 = 1 - b1 - b2;
        const Vec3d gn = unit_normal(a, b, c);
        s.ng = gn;
        s.n = gn;
        if (opt.pov_flat_normal && set.shading == Shading::flat)
          if (const Vec3d pn = pov_mesh_flat_normal(a, b, c); dot(pn, pn) > 0) s.n = pn;
        if (set.shading == Shading::smooth) {
          Vec3d n;
          if (tri.n[0] >= 0 && tri.n[1] >= 0 && tri.n[2] >= 0) {
            // Document 002: n = normalize(nA + l2 (nB - nA) + l3 (nC - nA)).
            const Vec3d& na = set.normals[tri.n[0]];
            n = na + (set.normals[tri.n[1]] - na) * b1 + (set.normals[tri.n[2]] - na) * b2;
          } else {
            const auto& vn = opt.use_double ? meshes_d[mesh_index[h.object]].vertex_normal
                                            : meshes_f[mesh_index[h.object]].vertex_normal;
            n = vn[tri.v[0]] * b0 + vn[tri.v[1]] * b1 + vn[tri.v[2]] * b2;
          }
          const double len = length(n);
          if (len > 0) s.n = n / len;
        }
        if (tri.t[0] >= 0 && tri.t[1] >= 0 && tri.t[2] >= 0) {
          const auto& ta = set.uvs[tri.t[0]];
          const auto& tb = set.uvs[tri.t[1]];
          const auto& tc = set.uvs[tri.t[2]];
          s.has_uv = true;
          s.u = ta[0] + (tb[0] - ta[0]) * b1 + (tc[0] - ta[0]) * b2;
          s.v = ta[1] + (tb[1] - ta[1]) * b1 + (tc[1] - ta[1]) * b2;
          if (opt.pov_mesh_hit && opt.pov_mesh_uv) {
            const auto uv = pov_mesh_uv(s.p, a, b, c, ta, tb, tc);
            s.u = uv[0];
            s.v = uv[1];
          }
        }
        s.material = &set.materials[std::clamp(tri.material, 0, int(set.materials.size()) - 1)];
        if (s.has_uv && s.material->bump)
          s.basis = uv_basis(a, b, c, set.uvs[tri.t[0]], set.uvs[tri.t[1]], set.uvs[tri.t[2]]);
        break;
      }
    }
    s.p_error = opt.use_double ? point_error<double>(o, h, s.p) : point_error<float>(o, h, s.p);
    return s;
  }

  // A bound on |p - exact hit point| per component (pbrt-v4), in the
  // precision T the secondary ray is spawned in: gamma(n) with T's epsilon.
  // In float the ray starts at Vec3f(p), so p's rounding to float is added;
  // with double's bound normal-offset would move it by far too little.
  template <class T>
  Vec3d point_error(const Object& o, const SceneHit& h, const Vec3d& p) const {
    using detail::gamma;
    Vec3<T> e;
    switch (o.kind) {
      case Object::Kind::sphere:
        e = sphere_point_error(Vec3<T>(p - o.sphere.center)) + abs(Vec3<T>(o.sphere.center)) * gamma<T>(1);
        break;
      case Object::Kind::plane:
        e = abs(Vec3<T>(p)) * gamma<T>(7);
        break;
      case Object::Kind::mesh: {
        const TriangleSet& set = *o.mesh;
        const MeshTriangle3& tri = set.triangles[h.prim];
        e = triangle_point_error(Vec3<T>(set.positions[tri.v[0]]), Vec3<T>(set.positions[tri.v[1]]),
                                 Vec3<T>(set.positions[tri.v[2]]), T(h.b1), T(h.b2));
        break;
      }
    }
    if constexpr (std::is_same_v<T, float>) e = e + abs(Vec3f(p)) * gamma<float>(1);
    return Vec3d(e);
  }

  // The pigment: the texture at (u, v) where the surface has UVs, else the
  // material's colour.
  Color pigment(const Surface& s) const {
    const Material& m = *s.material;
    if (m.texture && s.has_uv)
      if (const Texture* t = textures.find(m.texture->file)) return t->sample(s.u, s.v, m.texture->filter);
    return m.color;
  }

  // Document 002's bump variants act on the surface's own normal, before it
  // is turned to face the ray.
  void bump_document(Surface& s) const {
    const Material& m = *s.material;
    if (!m.bump || !s.has_uv || !s.basis || m.bump->variant == BumpVariant::pov) return;
    const BumpMap& b = *m.bump;
    if (b.variant == BumpVariant::height)
      s.n = bump_height(s.n, derivatives.at(b.file.lexically_normal().string()), b.filter, b.strength, s.u, s.v,
                        *s.basis);
    else if (const Texture* t = textures.find(b.file))
      s.n = bump_normal_map(s.n, *t, b.filter, b.strength, s.u, s.v, *s.basis);
  }

  // POV-Ray's bump_map perturbs the normal after the flip (trace.cpp).
  void bump_pov_after_flip(Surface& s) const {
    const Material& m = *s.material;
    if (!m.bump || !s.has_uv || m.bump->variant != BumpVariant::pov) return;
    if (const Texture* t = textures.find(m.bump->file))
      s.n = ra::bump_pov(s.n, *t, m.bump->filter, m.bump->strength, s.u, s.v);
  }

  // POV-Ray's shadow cache (trace.cpp, TracePointLightShadowRay): per light,
  // the object that last fully shadowed a point, one cache for camera-ray
  // hits (level 1) and one for deeper ones; a level-1 test without a level-1
  // entry uses the other. The cached object is tested first, alone, over
  // [1e-4, dist] instead of (1e-3, dist - 1e-3); the ordinary test's closest
  // blocker becomes the entry. State carried from pixel to pixel, so only
  // render() in POV's order (one thread) reproduces POV.
  mutable std::vector<int> shadow_cache_level1, shadow_cache_other;

  bool shadowed_pov_cache(const Surface& s, const Vec3d& to_light, double dist, int level, std::size_t li) const {
    int& level1 = shadow_cache_level1[li];
    int& other = shadow_cache_other[li];
    const int cached = (level == 1 && level1 >= 0) ? level1 : other;
    if (cached >= 0 && closest<double>(Ray<double>{s.p, to_light, kPovMinIsectDepth, dist}, cached)) return true;
    const auto h = closest<double>(Ray<double>{s.p, to_light, kPovShadowTolerance, dist - kPovShadowTolerance});
    if (!h) return false;
    (level == 1 ? level1 : other) = h->object;
    return true;
  }

  bool shadowed(const Surface& s, const Vec3d& to_light, double dist, int level, std::size_t li) const {
    if (opt.pov_shadow_cache) return shadowed_pov_cache(s, to_light, dist, level, li);
    return shadowed(s, to_light, dist);
  }

  bool shadowed(const Surface& s, const Vec3d& to_light, double dist) const {
    if (opt.use_double) {
      const Ray<double> r = spawn_ray<double>(opt.self_intersection, s.p, s.p_error, s.ng, to_light, true, dist);
      return occluded<double>(r);
    }
    const Ray<float> r = spawn_ray<float>(opt.self_intersection, Vec3f(s.p), Vec3f(s.p_error), Vec3f(s.ng),
                                          Vec3f(to_light), true, float(dist));
    return occluded<float>(r);
  }

  Ray<double> reflected_ray(const Surface& s, const Vec3d& dir) const {
    if (opt.use_double) return spawn_ray<double>(opt.self_intersection, s.p, s.p_error, s.ng, dir, false, 0.0);
    const Ray<float> r =
        spawn_ray<float>(opt.self_intersection, Vec3f(s.p), Vec3f(s.p_error), Vec3f(s.ng), Vec3f(dir), false, 0.f);
    return Ray<double>{Vec3d(r.o), dir, double(r.tmin), std::numeric_limits<double>::infinity()};
  }

  // POV-Ray's trace: level 1 for camera rays; beyond max_depth, black.
  // The closest hit of a ray leaving surface `from` (a reflected ray). With
  // opt.skip_rounding_self_hits, a hit on that same primitive (which a ray
  // leaving a plane, a sphere from outside or a triangle can only meet
  // through the rounding of its origin) is skipped when it is nearer than
  // that rounding allows: the origin's error along the normal (16 ulps of
  // its largest coordinate) over the ray's cosine with the normal.
  std::optional<SceneHit> intersect_from(Ray<double> ray, const Surface* from, bool camera) const {
    auto hit = intersect(ray, camera);
    if (!opt.skip_rounding_self_hits || !from) return hit;
    while (hit && hit->object == from->object && hit->prim == from->prim) {
      const double cos = std::abs(dot(from->ng, normalize(ray.d)));
      const double bound = 16 * std::numeric_limits<double>::epsilon() * max_component(abs(ray.o)) / cos;
      if (!(hit->t < bound)) break;
      ray.tmin = std::nextafter(hit->t, std::numeric_limits<double>::infinity());
      hit = intersect(ray, camera);
    }
    return hit;
  }

  Color trace(const Ray<double>& ray, int level, double weight, const Surface* from = nullptr) const {
    if (glass_mode)
      return opt.float32_colour ? trace_glass<true>(ray, level, false, weight, from, camera_interiors)
                                : trace_glass<false>(ray, level, false, weight, from, camera_interiors);
    if (level > scene.max_depth) return {0, 0, 0};
    const auto hit = intersect_from(ray, from, level == 1 && !from);
    if (!hit) return scene.background;
    Surface s = surface(ray, *hit);
    const Vec3d d = normalize(ray.d);
    bump_document(s);
    if (dot(s.n, d) > 0) s.n = -s.n;  // POV flips the normal to face the ray
    bump_pov_after_flip(s);
    const Material& m = *s.material;
    if (opt.float32_colour) return shade_float32(s, d, level, weight);
    const Color c = pigment(s);
    Color out = mul(mul(c, m.ambient), scene.ambient_light);
    const Vec3d refl_dir = d - s.n * (2 * dot(d, s.n));
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
      const PointLight& light = scene.lights[li];
      const Vec3d lv = light.position - s.p;
      const double dist = length(lv);
      if (!(dist > 0)) continue;
      const Vec3d l = lv / dist;
      const double nl = dot(s.n, l);
      if (nl < kMinCosIncidence) continue;
      if (shadowed(s, l, dist, level, li)) continue;
      out += mul(c, light.color) * (m.diffuse * nl);
      if (m.phong > 0) {
        const double rl = dot(refl_dir, l);
        if (rl > 0) out += light.color * (m.phong * std::pow(rl, m.phong_size));
      }
    }
    const double kr = max_component(m.reflection);
    if (kr > 0 && weight * kr >= scene.adc_bailout) {
      const Color r = trace(reflected_ray(s, refl_dir), level + 1, weight * kr, &s);
      out += mul(m.reflection, r);
    }
    return out;
  }

  // The same shading with POV-Ray 3.7's float32 colours (trace.cpp): its
  // RGBColour is float, so the pigment, the finish's colours and the light
  // colours are stored as float32 and each product or sum of colours is
  // rounded to float32; scalar factors (N.L times diffuse, the phong power)
  // are double until they multiply a colour.
  Color shade_float32(const Surface& s, const Vec3d& d, int level, double weight) const {
    const Material& m = *s.material;
    auto f = [](const Color& x) { return to_float32(x); };
    const Color c = f(pigment(s));
    // tmpCol += layCol * Ambient * ambientLight * att
    Color out = f(f(f(mul(c, f(m.ambient))) * 1.0));
    out = f(mul(out, f(scene.ambient_light)));
    const Vec3d refl_dir = d - s.n * (2 * dot(d, s.n));
    const double diffuse = to_float32(m.diffuse), phong = to_float32(m.phong), phong_size = to_float32(m.phong_size);
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
      const PointLight& light = scene.lights[li];
      const Vec3d lv = light.position - s.p;
      const double dist = length(lv);
      if (!(dist > 0)) continue;
      const Vec3d l = lv / dist;
      const double nl = dot(s.n, l);
      if (nl < kMinCosIncidence) continue;
      if (shadowed(s, l, dist, level, li)) continue;
      const Color lc = f(light.color);
      // colour += intensity * layer_pigment_colour * light_colour
      out = f(out + f(mul(f(c * (nl * diffuse)), lc)));
      if (phong > 0) {
        const double rl = dot(refl_dir, l);
        if (rl > 0) out = f(out + f(lc * (phong * std::pow(rl, phong_size))));
      }
    }
    const Color refl = f(m.reflection);
    const double kr = max_component(refl);
    if (kr > 0 && weight * kr >= scene.adc_bailout) {
      const Color r = f(trace(reflected_ray(s, refl_dir), level + 1, weight * kr, &s));
      out = f(out + f(mul(refl, r)));
    }
    return out;
  }

  // ---- Transparency, refraction and Fresnel (renderer/shading/glass.h) ----
  // A scene with a material that lets light through (filter, transmit) or
  // reflects by Fresnel is shaded by POV-Ray 3.7's ComputeLightedTexture in
  // full (one texture layer); any other scene by the shading above, which
  // gives the same image for it and whose bits the goldens hold.
  bool glass_mode = false;
  std::vector<double> object_ior;   // each object's interior ior (POV: one per object)
  std::vector<char> object_opaque;  // POV's OPAQUE_FLAG: no material lets light through

  // The objects the camera is inside, in object order (POV's
  // InitRayContainerState: Sphere::Inside |P - C|^2 < r^2, Plane::Inside
  // N.P - offset < 1e-10; a mesh2 without an inside_vector is never inside).
  std::vector<int> camera_interiors;

  void init_glass() {
    glass_mode = opt.pov_lighting;
    const Vec3d cam = scene.camera.position;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
      const Object& o = scene.objects[i];
      const Vec3d oc = o.sphere.center - cam;
      if ((o.kind == Object::Kind::sphere && dot(oc, oc) < o.sphere.radius * o.sphere.radius) ||
          (o.kind == Object::Kind::plane && dot(cam, o.plane.normal) - o.plane.offset < glass::kEpsilon))
        camera_interiors.push_back(int(i));
    }
    object_ior.assign(scene.objects.size(), 1.0);
    object_opaque.assign(scene.objects.size(), 1);
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
      auto visit = [&](const Material& m) {
        const bool clear = m.filter > 0 || m.transmit > 0;
        if (clear) object_opaque[i] = 0;
        if (clear || m.fresnel || opt.pov_lighting) glass_mode = true;
        if (m.ior != 1 && object_ior[i] == 1) object_ior[i] = m.ior;
      };
      const Object& o = scene.objects[i];
      if (o.kind == Object::Kind::mesh)
        for (const Material& m : o.mesh->materials) visit(m);
      else
        visit(o.material);
    }
  }

  template <bool F32>
  static Color round_colour(const Color& x) {
    if constexpr (F32)
      return to_float32(x);
    else
      return x;
  }
  template <bool F32>
  static double round_scalar(double x) {
    if constexpr (F32)
      return to_float32(x);
    else
      return x;
  }

  // POV's TraceRay. `level`: the trace level of the surface this ray meets
  // (camera rays 1); a continued ray (through an interface of equal iors)
  // keeps its parent's level, as POV's continuedRay does not count. POV
  // returns black when the parent's level has reached max_trace_level or
  // the ray's weight is below adc_bailout.
  template <bool F32>
  Color trace_glass(const Ray<double>& ray, int level, bool continued, double weight, const Surface* from,
                    const std::vector<int>& interiors) const {
    if ((continued ? level : level - 1) >= scene.max_depth || weight < scene.adc_bailout) return {0, 0, 0};
    const auto hit = intersect_from(ray, from, level == 1 && !from);
    if (!hit) return scene.background;
    Surface s = surface(ray, *hit);
    // POV's camera rays are unit; its refracted ones are left as Heckbert's
    // formula makes them.
    const Vec3d D = from ? ray.d : normalize(ray.d);
    bump_document(s);
    if (dot(s.n, D) > 0) s.n = -s.n;
    bump_pov_after_flip(s);
    return shade_glass<F32>(ray, s, D, level, weight, interiors);
  }

  // VNormalizeEq: times the reciprocal of the length.
  static Vec3d pov_normalize(const Vec3d& v) { return v * (1.0 / length(v)); }

  template <bool F32>
  Color shade_glass(const Ray<double>& ray, const Surface& s, const Vec3d& D, int level, double weight,
                    const std::vector<int>& interiors) const {
    auto f = [](const Color& x) { return round_colour<F32>(x); };
    auto fs = [](double x) { return round_scalar<F32>(x); };
    auto ior_of = [&](int o) { return object_ior[std::size_t(o)]; };
    const Material& m = *s.material;
    const Color c = f(pigment(s));
    const double fil = fs(m.filter), tr = fs(m.transmit);
    const double att = fs(glass::opacity(fil, tr));
    // ComputeReflectivity: standard (min = max) or Fresnel (min 0).
    const double cos_i = -dot(D, s.n);
    const Color rmax = f(m.reflection);
    Color reflec = rmax;
    if (m.fresnel)
      if (const auto F = glass::fresnel(glass::relative_ior(interiors, s.object, ior_of), cos_i)) reflec = f(rmax * *F);
    const double rweight = weight * max_component(reflec);
    // Ambient, then each light's diffuse and phong, as POV sums them.
    Color out = f(f(mul(f(mul(c, f(m.ambient))), f(scene.ambient_light))) * att);
    const Vec3d refl = D - s.n * (2 * dot(D, s.n));
    const double diffuse = fs(m.diffuse), phong = fs(m.phong), phong_size = fs(m.phong_size);
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
      const PointLight& light = scene.lights[li];
      const Vec3d lv = light.position - s.p;
      const double dist = length(lv);
      if (!(dist > 0)) continue;
      const Vec3d l = lv * (1.0 / dist);  // VInverseScaleEq
      const double nl = dot(s.n, l);
      if (nl < kMinCosIncidence) continue;
      const Color lc = shadow_glass<F32>(s, l, dist, level, li, f(light.color));
      if (!(std::abs(lc.x) > glass::kEpsilon || std::abs(lc.y) > glass::kEpsilon || std::abs(lc.z) > glass::kEpsilon))
        continue;
      Color tl{0, 0, 0};
      if (diffuse > 0) tl = f(mul(f(c * (nl * (diffuse * att))), lc));
      if (phong > 0) {
        const double rl = dot(refl, l);
        if (rl > 0) {
          // ComputePhongColour drops the highlight below 0.0008 from size 60 on.
          const double in = (phong_size < 60 || rl > 0.0008) ? phong * std::pow(rl, phong_size) : 0.0;
          tl = f(tl + f(lc * in));
        }
      }
      out = f(out + tl);
    }
    // What passes (filCol), less what Fresnel reflects (conserve_energy).
    Color filcol = glass::rgb_transm(c, fil, tr);
    if constexpr (F32) filcol = f(Color{fs(fs(c.x * fil) + tr), fs(fs(c.y * fil) + tr), fs(fs(c.z * fil) + tr)});
    if (m.fresnel)
      filcol =
          f(mul(filcol,
                f(Color{std::min(1.0, 1.0 - reflec.x), std::min(1.0, 1.0 - reflec.y), std::min(1.0, 1.0 - reflec.z)})));
    const double trans = std::min(1.0, std::abs(fs(glass::greyscale(filcol))));
    const Vec3d refl_dir = pov_normalize(refl);
    bool tir = false;
    if (trans > scene.adc_bailout) {
      const double nw = weight * max_component(abs(filcol));
      const glass::RefractionStep step = glass::refraction_step(interiors, s.object, ior_of);
      Color rfr;
      if (std::abs(step.ior - 1.0) < glass::kEpsilon) {
        rfr = trace_glass<F32>(reflected_ray(s, D), level, true, nw, &s, step.interiors);
      } else if (const auto dir = glass::refract(D, s.n, step.ior)) {
        rfr = trace_glass<F32>(reflected_ray(s, *dir), level + 1, false, nw, &s, step.interiors);
      } else {
        // Total internal reflection: the reflected ray, unfiltered, in the
        // ray's own interiors; the finish's reflection is then not added.
        tir = true;
        rfr = trace_glass<F32>(reflected_ray(s, refl_dir), level + 1, false, nw, &s, interiors);
      }
      out = tir ? f(out + rfr) : f(out + f(mul(rfr, filcol)));
    }
    if (!tir && (reflec.x != 0 || reflec.y != 0 || reflec.z != 0)) {
      const Color r = trace_glass<F32>(reflected_ray(s, refl_dir), level + 1, false, rweight, &s, interiors);
      out = f(out + f(mul(reflec, r)));
    }
    (void)ray;
    return out;
  }

  // TracePointLightShadowRay with ComputeShadowColour: the light's colour
  // times C filter + transmit of every transparent surface the shadow ray
  // crosses (entering and leaving alike, unbent); an opaque object blocks.
  template <bool F32>
  Color shadow_glass(const Surface& s, const Vec3d& l, double dist, int level, std::size_t li, Color lc) const {
    auto f = [](const Color& x) { return round_colour<F32>(x); };
    auto fs = [](double x) { return round_scalar<F32>(x); };
    int* cache = nullptr;
    if (opt.pov_shadow_cache) {
      int& level1 = shadow_cache_level1[li];
      int& other = shadow_cache_other[li];
      const int cached = (level == 1 && level1 >= 0) ? level1 : other;
      if (cached >= 0 && closest<double>(Ray<double>{s.p, l, kPovMinIsectDepth, dist}, cached)) return {0, 0, 0};
      cache = level == 1 ? &level1 : &other;
    }
    bool through = false;
    Ray<double> r = shadow_ray(s, l, dist);
    double depth = dist;
    for (;;) {
      const auto h = intersect(r, false);
      if (!h) return lc;
      if (object_opaque[std::size_t(h->object)]) {
        if (cache && !through) *cache = h->object;
        return {0, 0, 0};
      }
      const Surface hs = surface(r, *h);
      const Material& hm = *hs.material;
      const Color c = f(pigment(hs));
      const double fil = fs(hm.filter), tr = fs(hm.transmit);
      Color pass = glass::rgb_transm(c, fil, tr);
      if constexpr (F32) pass = Color{fs(fs(c.x * fil) + tr), fs(fs(c.y * fil) + tr), fs(fs(c.z * fil) + tr)};
      lc = f(mul(lc, pass));
      if (!(std::abs(lc.x) >= glass::kEpsilon || std::abs(lc.y) >= glass::kEpsilon ||
            std::abs(lc.z) >= glass::kEpsilon))
        return {0, 0, 0};
      through = true;
      depth -= h->t;
      r = shadow_ray(hs, l, depth);
    }
  }

  // A shadow ray from s toward the light at distance dist, in the tracer's
  // precision, as a double ray.
  Ray<double> shadow_ray(const Surface& s, const Vec3d& l, double dist) const {
    if (opt.use_double) return spawn_ray<double>(opt.self_intersection, s.p, s.p_error, s.ng, l, true, dist);
    const Ray<float> r =
        spawn_ray<float>(opt.self_intersection, Vec3f(s.p), Vec3f(s.p_error), Vec3f(s.ng), Vec3f(l), true, float(dist));
    return Ray<double>{Vec3d(r.o), l, double(r.tmin), double(r.tmax)};
  }

  Color pixel(int i, int j) const {
    const int n = opt.samples_per_axis;
    Color sum{0, 0, 0};
    for (int sy = 0; sy < n; ++sy)
      for (int sx = 0; sx < n; ++sx) {
        Ray<double> r = camera.ray(i + (sx + 0.5) / n, j + (sy + 0.5) / n);
        if (opt.self_intersection == SelfIntersection::pov) r.tmin = kPovMinIsectDepth;
        sum += trace(r, 1, 1.0);
      }
    return sum / double(n * n);
  }
};

Tracer::Tracer(const Scene& scene, const RenderOptions& options) : impl_(std::make_unique<Impl>(scene, options)) {}
Tracer::~Tracer() = default;

Color Tracer::trace(const Ray<double>& ray) const { return impl_->trace(ray, 1, 1.0); }
std::optional<SceneHit> Tracer::intersect(const Ray<double>& ray) const { return impl_->intersect(ray, true); }
bool Tracer::occluded(const Ray<double>& ray) const {
  return impl_->opt.use_double ? impl_->occluded<double>(ray) : impl_->occluded<float>(static_cast<Ray<float>>(ray));
}
Color Tracer::pixel(int i, int j) const { return impl_->pixel(i, j); }
std::optional<Tracer::ShadingPoint> Tracer::shading_point(const Ray<double>& ray) const {
  const auto hit = impl_->intersect(ray, true);
  if (!hit) return std::nullopt;
  Impl::Surface s = impl_->surface(ray, *hit);
  impl_->bump_document(s);
  return ShadingPoint{s.p, s.ng, s.n, s.has_uv, s.u, s.v};
}

Image Tracer::render() const {
  const Scene& s = impl_->scene;
  Image img(s.width, s.height);
  constexpr int kTile = 32;
  const int tiles_x = (s.width + kTile - 1) / kTile, tiles_y = (s.height + kTile - 1) / kTile;
  const int tiles = tiles_x * tiles_y;
  int threads = impl_->opt.threads > 0 ? impl_->opt.threads : int(std::thread::hardware_concurrency());
  if (impl_->opt.pov_shadow_cache) {
    // POV's order with +WT1: 32 x 32 blocks row by row, each row by row,
    // all on one thread, the caches starting empty.
    threads = 1;
    impl_->shadow_cache_level1.assign(s.lights.size(), -1);
    impl_->shadow_cache_other.assign(s.lights.size(), -1);
  }
  threads = std::clamp(threads, 1, std::max(1, tiles));
  std::atomic<int> next{0}, done{0};
  // Each pixel depends only on its own rays, so any thread may take any
  // tile: the image is the same for every thread count.
  auto worker = [&] {
    for (int t; (t = next.fetch_add(1)) < tiles;) {
      const int x0 = (t % tiles_x) * kTile, y0 = (t / tiles_x) * kTile;
      for (int y = y0; y < std::min(y0 + kTile, s.height); ++y)
        for (int x = x0; x < std::min(x0 + kTile, s.width); ++x) {
          const Color c = impl_->pixel(x, y);
          float* px = img.at(x, y);
          px[0] = float(c.x);
          px[1] = float(c.y);
          px[2] = float(c.z);
        }
      done.fetch_add(1);
    }
  };
  const bool show = impl_->opt.progress && isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  // A reporter thread shows progress once the render has taken more than a
  // moment; without one (the system refusing the thread) the render goes on.
  std::atomic<bool> finished{false};
  std::thread reporter;
  if (show) try {
      reporter = std::thread([&] {
        bool printed = false;
        while (!finished.load() && done.load() < tiles) {
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (secs > 0.5 && !finished.load()) {
            std::fprintf(stderr, "\rrendering %dx%d: %3d%% (%.1f s)", s.width, s.height, 100 * done.load() / tiles,
                         secs);
            printed = true;
          }
        }
        if (printed) std::fprintf(stderr, "\r\033[K");
      });
    } catch (const std::system_error&) {
    }
  run_workers(threads, worker);
  finished = true;
  if (reporter.joinable()) reporter.join();
  return img;
}

}  // namespace ra
