// Group peer/embree/MESH/...: Embree 3 (rtcIntersect1, rtcOccluded1; default
// and RTC_SCENE_FLAG_ROBUST scenes) against our BVH on the same rays, the
// two measured back to back in every iteration of the same process.
#include <embree3/rtcore.h>

#include <cmath>
#include <map>

#include "bench.h"
#include "errors.h"

namespace rb {
namespace {

void release_kept_scenes();

// One device alive at a time, made for the thread count in use ("threads=1"
// makes Embree build on one thread). Embree's task scheduler applies the
// thread count of the last device made to every device (one TBB limit for
// the process): with a threads=2 device alive, the threads=1 rows that
// followed built on 2 threads (the dragon in 0.19-0.28 s instead of
// 0.34-0.43 s). The scenes kept are released first, so the old device
// (which they hold) goes with its handle.
RTCDevice device(int threads) {
  static RTCDevice current = nullptr;
  static int current_threads = -1;
  if (current && current_threads == threads) return current;
  release_kept_scenes();
  if (current) rtcReleaseDevice(current);
  current = nullptr;
  const std::string cfg = "threads=" + std::to_string(threads);
  RTCDevice d = rtcNewDevice(cfg.c_str());
  if (!d) throw std::runtime_error("Embree: rtcNewDevice(\"" + cfg + "\") failed (libembree3)");
  current = d;
  current_threads = threads;
  return d;
}

// Bytes Embree allocates while a scene is built (its memory monitor).
std::atomic<long> g_embree_bytes{0};
bool monitor(void*, ssize_t bytes, bool) {
  g_embree_bytes += long(bytes);
  return true;
}

struct EmbreeScene {
  RTCScene scene = nullptr;
  double build_s = 0;
  double bytes_per_triangle = 0;
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
  }
};

// The mesh as Embree sees it: float vertices (ours are double), the same
// triangles in the same order.
std::unique_ptr<EmbreeScene> build(const ra::TriangleSet& mesh, bool robust, int threads) {
  RTCDevice dev = device(threads);
  rtcSetDeviceMemoryMonitorFunction(dev, monitor, nullptr);
  auto es = std::make_unique<EmbreeScene>();
  const long before = g_embree_bytes.load();
  const auto t0 = now();
  es->scene = rtcNewScene(dev);
  if (robust) rtcSetSceneFlags(es->scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.positions.size()));
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    v[3 * i] = float(mesh.positions[i].x);
    v[3 * i + 1] = float(mesh.positions[i].y);
    v[3 * i + 2] = float(mesh.positions[i].z);
  }
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = unsigned(mesh.triangles[i].v[k]);
  rtcCommitGeometry(g);
  rtcAttachGeometry(es->scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(es->scene);
  es->build_s = seconds_since(t0);
  es->bytes_per_triangle = double(g_embree_bytes.load() - before) / double(mesh.triangles.size());
  if (rtcGetDeviceError(dev) != RTC_ERROR_NONE) throw std::runtime_error("Embree: scene build failed");
  return es;
}

RTCRay to_embree(const ra::Rayd& r) {
  RTCRay e{};
  e.org_x = float(r.o.x), e.org_y = float(r.o.y), e.org_z = float(r.o.z);
  e.dir_x = float(r.d.x), e.dir_y = float(r.d.y), e.dir_z = float(r.d.z);
  e.tnear = float(r.tmin);
  e.tfar = std::isinf(r.tmax) ? std::numeric_limits<float>::infinity() : float(r.tmax);
  e.mask = ~0u;
  return e;
}

std::size_t trace_embree(RTCScene scene, const std::vector<ra::Rayd>& rays, bool shadow, int threads,
                         std::vector<unsigned char>& flags) {
  flags.assign(rays.size(), 0);
  std::atomic<std::size_t> hits{0};
  parallel_for(threads, rays.size(), [&](std::size_t b, std::size_t e) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    std::size_t n = 0;
    for (std::size_t i = b; i < e; ++i) {
      bool h;
      if (shadow) {
        RTCRay r = to_embree(rays[i]);
        rtcOccluded1(scene, &ctx, &r);
        h = r.tfar < 0;  // Embree sets tfar to -inf on an occlusion
      } else {
        RTCRayHit rh{};
        rh.ray = to_embree(rays[i]);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &ctx, &rh);
        h = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      }
      n += h;
      flags[i] = h;
    }
    hits.fetch_add(n, std::memory_order_relaxed);
  });
  return hits.load();
}

// Embree scenes of the rung in use, per (robust, threads).
struct Kept {
  const Rung* rung = nullptr;
  std::map<std::pair<bool, int>, std::unique_ptr<EmbreeScene>> scenes;
};
Kept& kept() {
  static Kept k;
  return k;
}
void release_kept_scenes() { kept().scenes.clear(); }
EmbreeScene& scene_for(const Rung& r, bool robust, int threads) {
  Kept& k = kept();
  if (k.rung != &r) {
    k.scenes.clear();
    k.rung = &r;
  }
  device(threads);  // first: making another device releases the scenes kept
  auto& s = k.scenes[{robust, threads}];
  if (!s) s = build(*rung_rays(r).mesh, robust, threads);
  return *s;
}

const char* flag_name(bool robust) { return robust ? "robust" : "default"; }

// Build: ours (the BVH tracer: kernel data, boxes, BVH) and Embree's (vertex
// and index buffers, rtcCommitScene), back to back, on the same number of
// threads.
void bm_build(benchmark::State& state, const Rung* rung, bool robust, int threads) {
  const ra::TriangleSet& mesh = *rung_rays(*rung).mesh;
  double ours = 0, theirs = 0, bpt = 0, ours_bpt = 0;
  for (auto _ : state) {
    ra::RenderOptions opt;
    opt.progress = false;
    opt.threads = threads;
    const long before = heap_live();
    const auto t0 = now();
    {
      ra::Tracer t(*rung_rays(*rung).scene, opt);
      ours += seconds_since(t0);
      ours_bpt = double(heap_live() - before) / double(mesh.triangles.size());
    }
    auto es = build(mesh, robust, threads);
    theirs += es->build_s;
    bpt = es->bytes_per_triangle;
  }
  const double n = double(state.iterations());
  state.counters["build_s"] = theirs / n;
  state.counters["ours_build_s"] = ours / n;
  state.counters["bytes_per_triangle"] = bpt;
  state.counters["ours_bytes_per_triangle"] = ours_bpt;
  state.counters["triangles"] = double(mesh.triangles.size());
  state.counters["ratio"] = theirs / ours;  // builds per second, ours / Embree's
}

void bm_trace(benchmark::State& state, const Rung* rung, bool robust, bool shadow, int threads,
              const std::string& method = "moller") {
  RungRays& rr = rung_rays(*rung);
  // --quick: an evenly spread subset, at most 2^18 rays.
  const std::vector<ra::Rayd> rays =
      subset(shadow ? rr.shadow : rr.primary, config().quick ? std::size_t(1) << 18 : std::size_t(kWidth) * kHeight);
  const ra::Tracer& ours = *our_tracer(*rung, ra::Accel::bvh, false, method).tracer;
  EmbreeScene& es = scene_for(*rung, robust, threads);
  double ours_s = 0, theirs_s = 0;
  std::size_t hits = 0, ours_hits = 0, differ = 0;
  std::vector<unsigned char> ours_flags, flags;
  for (auto _ : state) {
    auto t0 = now();
    ours_hits = trace_ours(ours, rays, shadow, threads, &ours_flags);
    ours_s += seconds_since(t0);
    t0 = now();
    hits = trace_embree(es.scene, rays, shadow, threads, flags);
    const double s = seconds_since(t0);
    theirs_s += s;
  }
  differ = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) differ += flags[i] != ours_flags[i];
  const double n = double(state.iterations()) * double(rays.size());
  state.counters["Mrays_per_s"] = n / theirs_s / 1e6;
  state.counters["ours_Mrays_per_s"] = n / ours_s / 1e6;
  state.counters["ratio"] = theirs_s / ours_s;  // our rate / Embree's
  state.counters["hits"] = double(hits);
  state.counters["ours_hits"] = double(ours_hits);
  state.counters["differ"] = double(differ);
  state.counters["rays"] = double(rays.size());
  state.counters["triangles"] = double(rung->triangles);
  note("embree " + rung->name + " " + (shadow ? "shadow" : "primary") + " " + flag_name(robust) + ": Embree hits " +
       std::to_string(hits) + ", ours " + std::to_string(ours_hits) + ", " + std::to_string(differ) + " of " +
       std::to_string(rays.size()) + " rays differ");
}

}  // namespace

void register_embree() {
  for (const char* name : {"bunny", "dragon"}) {
    const Rung* r = find_rung(name);
    if (config().quick && !r->quick) continue;
    const std::vector<fs::path> needs{rung_obj(*r), rung_scene_file(*r)};
    for (bool robust : {false, true})
      for (int t : thread_counts()) {
        const std::string tail = std::string("/") + flag_name(robust) + "/threads=" + std::to_string(t);
        add("peer/embree/" + r->name + "/build" + tail, needs, [=](benchmark::State& s) { bm_build(s, r, robust, t); });
        for (bool shadow : {false, true})
          add("peer/embree/" + r->name + (shadow ? "/shadow" : "/primary") + tail, needs,
              [=](benchmark::State& s) { bm_trace(s, r, robust, shadow, t); });
      }
    // Our tracer on the exact method (exact decisions), against Embree's
    // default build on one thread: the rows its ratio target is set for.
    for (bool shadow : {false, true})
      add("peer/embree/" + r->name + (shadow ? "/shadow" : "/primary") + "/exact/default/threads=1", needs,
          [=](benchmark::State& s) { bm_trace(s, r, false, shadow, 1, "exact"); });
  }
}

}  // namespace rb
