// Group peer/cgal/MESH/...: CGAL's AABB_tree (the exact-geometry peer users
// reach for) on the same mesh and rays as our BVH: first_intersection for
// primary rays, do_intersect on the segment [tmin, tmax] for shadow rays,
// each iteration timing ours right before CGAL on the same rays.
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <map>

#include "bench.h"

namespace rb {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

struct CgalScene {
  Triangles tris;
  std::unique_ptr<Tree> tree;
  double build_s = 0;
};

K::Point_3 pt(const ra::Vec3d& v) { return {v.x, v.y, v.z}; }

std::unique_ptr<CgalScene> build(const ra::TriangleSet& mesh) {
  auto s = std::make_unique<CgalScene>();
  const auto t0 = now();
  s->tris.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    s->tris.emplace_back(pt(mesh.positions[t.v[0]]), pt(mesh.positions[t.v[1]]), pt(mesh.positions[t.v[2]]));
  s->tree = std::make_unique<Tree>(s->tris.begin(), s->tris.end());
  s->tree->build();  // built now, not lazily by the first (concurrent) query
  s->build_s = seconds_since(t0);
  return s;
}

CgalScene& scene_for(const Rung& r) {
  static const Rung* kept = nullptr;
  static std::unique_ptr<CgalScene> scene;
  if (kept != &r || !scene) {
    scene = build(*rung_rays(r).mesh);
    kept = &r;
  }
  return *scene;
}

bool cgal_hit(const Tree& tree, const ra::Rayd& r, bool shadow) {
  if (shadow) return tree.do_intersect(K::Segment_3(pt(r.at(r.tmin)), pt(r.at(r.tmax))));
  // Primary rays start at the camera with tmin = 0: CGAL's ray is the same.
  return bool(tree.first_intersection(K::Ray_3(pt(r.o), K::Vector_3(r.d.x, r.d.y, r.d.z))));
}

// CGAL is far slower than a BVH tracer: an evenly spread subset of the rays.
std::size_t max_rays() { return config().quick ? 4096 : 32768; }

void bm_trace(benchmark::State& state, const Rung* rung, bool shadow, int threads) {
  RungRays& rr = rung_rays(*rung);
  const std::vector<ra::Rayd> rays = subset(shadow ? rr.shadow : rr.primary, max_rays());
  const ra::Tracer& ours = *our_tracer(*rung, ra::Accel::bvh, false).tracer;
  const CgalScene& cs = scene_for(*rung);
  double ours_s = 0, theirs_s = 0;
  std::size_t hits = 0, ours_hits = 0;
  std::vector<unsigned char> ours_flags, flags(rays.size());
  for (auto _ : state) {
    auto t0 = now();
    ours_hits = trace_ours(ours, rays, shadow, threads, &ours_flags);
    ours_s += seconds_since(t0);
    t0 = now();
    std::atomic<std::size_t> h{0};
    parallel_for(threads, rays.size(), [&](std::size_t b, std::size_t e) {
      std::size_t n = 0;
      for (std::size_t i = b; i < e; ++i) n += flags[i] = cgal_hit(*cs.tree, rays[i], shadow);
      h += n;
    });
    hits = h;
    theirs_s += seconds_since(t0);
  }
  std::size_t differ = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) differ += flags[i] != ours_flags[i];
  const double n = double(state.iterations()) * double(rays.size());
  state.counters["Mrays_per_s"] = n / theirs_s / 1e6;
  state.counters["ours_Mrays_per_s"] = n / ours_s / 1e6;
  state.counters["ratio"] = theirs_s / ours_s;
  state.counters["hits"] = double(hits);
  state.counters["ours_hits"] = double(ours_hits);
  state.counters["differ"] = double(differ);
  state.counters["rays"] = double(rays.size());
  state.counters["build_s"] = cs.build_s;
  state.counters["ours_build_s"] = our_tracer(*rung, ra::Accel::bvh, false).build_s;
  state.counters["triangles"] = double(rung->triangles);
  note("cgal " + rung->name + " " + (shadow ? "shadow" : "primary") + ": CGAL hits " + std::to_string(hits) +
       ", ours " + std::to_string(ours_hits) + ", " + std::to_string(differ) + " of " + std::to_string(rays.size()) +
       " rays differ");
}

}  // namespace

void register_cgal() {
  for (const char* name : {"bunny", "dragon"}) {
    const Rung* r = find_rung(name);
    if (config().quick && !r->quick) continue;
    for (bool shadow : {false, true})
      for (int t : thread_counts())
        add("peer/cgal/" + r->name + (shadow ? "/shadow" : "/primary") + "/threads=" + std::to_string(t),
            {rung_obj(*r), rung_scene_file(*r)}, [=](benchmark::State& s) { bm_trace(s, r, shadow, t); });
  }
}

}  // namespace rb
