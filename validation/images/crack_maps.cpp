// Crack maps: renders through the tracer (renderer/render.h) with
// each registered triangle method in float and judges every pixel with the oracle.
#include "crack_maps.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <thread>

#include "scene/camera.h"
#include "errors.h"
#include "exact/families.h"
#include "exact/oracle.h"
#include "registry.h"
#include "render.h"
#include "scene/scene_mesh.h"

namespace ra::crack {

namespace {

// Centre on the bounding box and scale to radius 2 about it.
void normalise(ClosedMesh& m) {
  Vec3d lo = m.positions.front(), hi = lo;
  for (const Vec3d& p : m.positions) lo = vmin(lo, p), hi = vmax(hi, p);
  const Vec3d c = (lo + hi) * 0.5;
  double r = 0;
  for (const Vec3d& p : m.positions) r = std::max(r, length(p - c));
  for (Vec3d& p : m.positions) p = (p - c) * (2.0 / r);
}

// The scene the tracer renders: the mesh moved to c = (o, o, o) and seen
// along the diagonal from the origin's side: from the origin itself once the
// mesh is farther than 6.5 (so every ray starts at the origin and travels |c|
// to the mesh, the far-from-the-origin case where rounding grows with the
// distance), from 6.5 away when it is nearer.
Scene placed_scene(const ClosedMesh& m, double offset, int size) {
  auto set = std::make_shared<TriangleSet>();
  set->name = m.name;
  const Vec3d shift{offset, offset, offset};
  for (const Vec3d& p : m.positions) set->positions.push_back(p + shift);
  for (const auto& f : m.faces) {
    MeshTriangle3 t;
    t.v = f;
    set->triangles.push_back(t);
  }
  set->materials.push_back(Material{});
  Scene s;
  s.width = s.height = size;
  const double dist = std::max(6.5, length(shift));
  s.camera.position = dist == length(shift) ? Vec3d{0, 0, 0} : shift - normalize(Vec3d{1, 1, 1}) * dist;
  s.camera.look_at = shift;
  s.camera.up = {0, 1, 0};
  s.camera.vfov = 2 * std::atan(2.3 / dist) * 180 / 3.14159265358979323846;
  s.camera_given = true;
  s.lights.push_back({s.camera.position, {1, 1, 1}});
  s.lights_given = true;
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  s.objects.push_back(o);
  return s;
}

// What the float methods see: every vertex rounded to float, in double.
std::vector<Vec3d> float_positions(const Scene& s) {
  std::vector<Vec3d> out;
  // to_float32, not Vec3d(Vec3f(p)): GCC 12 folds the vectorised round trip
  // to p unrounded (vec.h), and the oracle then judged the double mesh
  // (the exact method, deciding the float mesh exactly, showed 1,472 "leaks"
  // on the sphere at 1e7 where the float mesh has no surface).
  for (const Vec3d& p : s.objects[0].mesh->positions) out.push_back(to_float32(p));
  return out;
}

// Each triangle's box, widened by far more than a double slab test's rounding,
// so the box test only skips triangles the ray clearly misses.
struct Box {
  Vec3d lo, hi;
};
std::vector<Box> boxes(const std::vector<Vec3d>& v, const std::vector<std::array<int, 3>>& faces) {
  std::vector<Box> out;
  for (const auto& f : faces) {
    Box b{v[std::size_t(f[0])], v[std::size_t(f[0])]};
    for (int k = 1; k < 3; ++k)
      b.lo = vmin(b.lo, v[std::size_t(f[std::size_t(k)])]), b.hi = vmax(b.hi, v[std::size_t(f[std::size_t(k)])]);
    const double pad = 1e-9 * std::max(max_component(abs(b.lo)), max_component(abs(b.hi))) + 1e-300;
    b.lo = b.lo - Vec3d{pad, pad, pad};
    b.hi = b.hi + Vec3d{pad, pad, pad};
    out.push_back(b);
  }
  return out;
}
bool may_meet(const Rayd& r, const Box& b) {
  double t0 = 0, t1 = r.tmax;
  const double o[3] = {r.o.x, r.o.y, r.o.z}, d[3] = {r.d.x, r.d.y, r.d.z}, lo[3] = {b.lo.x, b.lo.y, b.lo.z},
               hi[3] = {b.hi.x, b.hi.y, b.hi.z};
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - o[k]) / d[k], c = (hi[k] - o[k]) / d[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
  }
  return t0 <= t1;
}

// Does the ray meet the closed surface exactly (inside a triangle, or on an
// edge or vertex, which for a closed mesh means it crosses there)?
bool oracle_meets(const Rayd& r, const std::vector<Vec3d>& v, const std::vector<std::array<int, 3>>& faces,
                  const std::vector<Box>& bx) {
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (!may_meet(r, bx[i])) continue;
    const auto& f = faces[i];
    const auto a = oracle::triangle(r, v[std::size_t(f[0])], v[std::size_t(f[1])], v[std::size_t(f[2])]);
    if (a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) return true;
  }
  return false;
}

void paint(float* px, double r, double g, double b) { px[0] = float(r), px[1] = float(g), px[2] = float(b); }

// Runs body(row) for every row on `threads` threads.
void parallel_rows(int rows, int threads, const std::function<void(int)>& body) {
  const int n = std::max(1, std::min(rows, threads > 0 ? threads : int(std::thread::hardware_concurrency())));
  std::atomic<int> next{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < n; ++t)
    pool.emplace_back([&] {
      for (int y; (y = next++) < rows;) body(y);
    });
  for (auto& th : pool) th.join();
}

std::vector<const Method*> chosen(const std::vector<std::string>& names) {
  std::vector<const Method*> out;
  for (const Method& m : methods())
    if (m.kind == Kind::triangle && (names.empty() || std::find(names.begin(), names.end(), m.name) != names.end()))
      out.push_back(&m);
  for (const auto& n : names)
    if (const Method* m = find_method(n); !m || m->kind != Kind::triangle)
      throw InputError("crack-maps: unknown triangle method '" + n + "' (" + method_names(Kind::triangle) + ")");
  return out;
}

}  // namespace

ClosedMesh audit_sphere() {
  ClosedMesh m;
  m.name = "sphere";
  m.source = "the audit's closed-mesh sphere (icosahedron subdivided once, 80 triangles)";
  // Shared corners are equal doubles; weld them so the faces share indices.
  for (const auto& t : audit::closed_mesh_triangles(0)) {
    std::array<int, 3> f{};
    const Vec3d* c[3] = {&t.a, &t.b, &t.c};
    for (int k = 0; k < 3; ++k) {
      auto it = std::find_if(m.positions.begin(), m.positions.end(),
                             [&](const Vec3d& p) { return p.x == c[k]->x && p.y == c[k]->y && p.z == c[k]->z; });
      f[std::size_t(k)] = int(it - m.positions.begin());
      if (it == m.positions.end()) m.positions.push_back(*c[k]);
    }
    m.faces.push_back(f);
  }
  return m;
}

ClosedMesh closed_obj(const std::filesystem::path& file) {
  MeshPlacement place;
  place.file = file;
  const auto set = load_placed_mesh(place);
  if (set->triangles.empty()) throw InputError(file.string() + ": no triangles");
  if (const std::string why = cull_unsafe_reason(*set); !why.empty())
    throw InputError(file.string() + ": not a closed outward mesh, so it has no cracks to find: " + why);
  ClosedMesh m;
  m.name = file.stem().string();
  m.source = file.string();
  m.positions = set->positions;
  for (const auto& t : set->triangles) m.faces.push_back(t.v);
  normalise(m);
  return m;
}

std::vector<std::string> map_methods(const Options& opt) {
  std::vector<std::string> out;
  for (const Method* m : chosen(opt.methods)) out.emplace_back(m->name);
  return out;
}

std::vector<Map> render_maps(const std::vector<ClosedMesh>& meshes, const Options& opt) {
  const auto ms = chosen(opt.methods);
  const std::size_t total = meshes.size() * opt.offsets.size();
  std::size_t done = 0;
  std::vector<Map> out;
  for (const ClosedMesh& mesh : meshes)
    for (const double offset : opt.offsets) {
      const Scene scene = placed_scene(mesh, offset, opt.size);
      const auto fv = float_positions(scene);
      const auto bx = boxes(fv, mesh.faces);
      const Camera cam(scene.camera, opt.size, opt.size);
      RenderOptions ro;
      ro.use_double = false;
      ro.accel = Accel::none;  // the kernels alone: no bounding volume to blame
      ro.progress = false;
      // The reference per pixel: the oracle's crossing of the float mesh by
      // the float ray, which is what every method is given (no shift here:
      // the camera is within a few scales of the mesh). An inexact method's
      // crossing is no reference: the watertight method's, once counted
      // too, made its 2 false pixels on the sphere at 1e5 (96 pixels a
      // side) "leaks" of every method that rightly missed there.
      const int n = opt.size;
      std::vector<char> exact(std::size_t(n) * n);
      std::vector<Rayd> rays(std::size_t(n) * n);
      parallel_rows(n, opt.threads, [&](int y) {
        for (int x = 0; x < n; ++x) {
          const std::size_t i = std::size_t(y) * n + x;
          rays[i] = cam.ray(x + 0.5, y + 0.5);
          const Rayd seen{to_float32(rays[i].o), to_float32(rays[i].d), to_float32(rays[i].tmin),
                          to_float32(rays[i].tmax)};
          exact[i] = oracle_meets(seen, fv, mesh.faces, bx);
        }
      });
      for (const Method* m : ms) {
        ro.triangle_method = m->name;
        const Tracer tracer(scene, ro);
        Map map;
        map.mesh = mesh.name;
        map.method = m->name;
        map.offset = offset;
        map.image = Image(n, n);
        map.pixels = (long long)n * n;
        std::vector<char> hit(std::size_t(n) * n);
        parallel_rows(n, opt.threads, [&](int y) {
          for (int x = 0; x < n; ++x) {
            const std::size_t i = std::size_t(y) * n + x;
            const auto h = tracer.intersect(rays[i]);
            hit[i] = h.has_value();
            float* px = map.image.at(x, y);
            if (!h) {
              if (exact[i])
                paint(px, 0.9, 0.0, 0.0);
              else
                paint(px, 1, 1, 1);
              continue;
            }
            if (!exact[i]) {
              paint(px, 0.1, 0.3, 1.0);
              continue;
            }
            // Grey by the angle to the face (float-rounded triangle's normal).
            const auto& f = mesh.faces[std::size_t(h->prim)];
            const Vec3d ng =
                cross(fv[std::size_t(f[1])] - fv[std::size_t(f[0])], fv[std::size_t(f[2])] - fv[std::size_t(f[0])]);
            const double len = length(ng);
            const double c = len > 0 ? std::abs(dot(ng / len, normalize(rays[i].d))) : 0;
            const double g = 0.3 + 0.55 * c;
            paint(px, g, g, g);
          }
        });
        for (std::size_t i = 0; i < hit.size(); ++i) {
          map.surface += exact[i];
          map.leaks += exact[i] && !hit[i];
          map.false_hits += hit[i] && !exact[i];
        }
        out.push_back(std::move(map));
      }
      if (opt.progress) opt.progress(++done, total);
    }
  return out;
}

}  // namespace ra::crack
