// Group scene/MESH/ACCEL/cull|nocull/primary|shadow/threads=T: our tracer
// (renderer/render.h, Möller in double) on the mesh ladder, with document
// 002's optimisations (bounding sphere, backface culling) and the BVH.
#include <time.h>

#include "bench.h"

namespace rb {
namespace {

// Brute force (none, sphere) tests every triangle per ray: it traces an
// evenly spread subset of the rays, about `budget` ray/triangle tests per
// pass; rates stay comparable because every subset spans the whole image.
std::size_t max_rays(ra::Accel accel, std::size_t triangles) {
  const bool quick = config().quick;
  const std::size_t all = std::size_t(kWidth) * kHeight, most = quick ? std::size_t(1) << 17 : all;
  if (accel == ra::Accel::bvh) return most;
  const double budget = quick ? 5e6 : 5e7;
  return std::clamp<std::size_t>(std::size_t(budget / double(triangles)), 64, most);
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void bm_scene(benchmark::State& state, const Rung* rung, ra::Accel accel, bool cull, bool shadow, int threads) {
  RungRays& rr = rung_rays(*rung);
  BuiltTracer& bt = our_tracer(*rung, accel, cull);
  const std::vector<ra::Rayd> rays = subset(shadow ? rr.shadow : rr.primary, max_rays(accel, rung->triangles));
  std::size_t hits = 0;
  const auto t0 = now();
  const double c0 = process_cpu_seconds();
  for (auto _ : state) hits = trace_ours(*bt.tracer, rays, shadow, threads);
  const double secs = seconds_since(t0), cpu = process_cpu_seconds() - c0;
  const double traced = double(rays.size()) * double(state.iterations());
  state.counters["Mrays_per_s"] = traced / secs / 1e6;
  // Per second of CPU (all threads): steadier on a shared machine.
  state.counters["Mrays_per_cpu_s"] = traced / cpu / 1e6;
  state.counters["triangles"] = double(rung->triangles);
  state.counters["rays"] = double(rays.size());
  state.counters["hits"] = double(hits);
  state.counters["build_s"] = bt.build_s;
  state.counters["bytes_per_triangle"] = bt.bytes_per_triangle;
}

}  // namespace

void register_scene() {
  for (const Rung& r : ladder()) {
    if (config().quick && !r.quick) continue;
    for (ra::Accel accel : {ra::Accel::none, ra::Accel::sphere, ra::Accel::bvh}) {
      if (accel == ra::Accel::none && r.triangles > 10000) continue;
      // Document 002 culls closed meshes only (the tracer would refuse).
      for (bool cull : r.closed ? std::vector<bool>{false, true} : std::vector<bool>{false})
        for (bool shadow : {false, true})
          for (int t : thread_counts()) {
            const std::string name = "scene/" + r.name + "/" + ra::accel_name(accel) + (cull ? "/cull" : "/nocull") +
                                     (shadow ? "/shadow" : "/primary") + "/threads=" + std::to_string(t);
            const Rung* rp = &r;
            add(name, {rung_obj(r), rung_scene_file(r)},
                [=](benchmark::State& s) { bm_scene(s, rp, accel, cull, shadow, t); });
          }
    }
  }
}

}  // namespace rb
