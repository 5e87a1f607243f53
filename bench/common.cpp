// rayaudit-bench's shared pieces (bench.h): registration, threads, the heap
// counter, the mesh ladder and the one set of rays every tracer traces.
#include <time.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>
#include <mutex>

#include "bench.h"
#include "scene/camera.h"
#include "errors.h"
#include "huge_pages.h"
#include "scene/scene_mesh.h"

namespace rb {

Config& config() {
  static Config c;
  return c;
}

std::vector<int> thread_counts() {
  std::vector<int> t{1};
  if (config().threads_all > 1) t.push_back(config().threads_all);
  return t;
}

int repetitions() { return config().quick ? 3 : 5; }
double min_time() { return config().quick ? 0.005 : 0.02; }

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::vector<Registered>& registered() {
  static std::vector<Registered> r;
  return r;
}

benchmark::internal::Benchmark* add(const std::string& name, std::vector<fs::path> needs,
                                    std::function<void(benchmark::State&)> fn) {
  registered().push_back({name, std::move(needs)});
  // An exception (a peer failing, a file gone) fails the row, not the run.
  return benchmark::RegisterBenchmark(name.c_str(), [fn](benchmark::State& s) {
    try {
      fn(s);
    } catch (const std::exception& e) {
      s.SkipWithError(e.what());
    }
  });
}

namespace {
std::mutex g_notes_mu;
std::vector<std::string> g_notes;
}  // namespace

void note(const std::string& line) {
  std::lock_guard<std::mutex> lock(g_notes_mu);
  if (std::find(g_notes.begin(), g_notes.end(), line) == g_notes.end()) g_notes.push_back(line);
}
const std::vector<std::string>& notes() { return g_notes; }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(now() - t0).count();
}

void parallel_for(int threads, std::size_t n, const std::function<void(std::size_t, std::size_t)>& f) {
  constexpr std::size_t kBlock = 1024;
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t b; (b = next.fetch_add(kBlock, std::memory_order_relaxed)) < n;) f(b, std::min(n, b + kBlock));
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

// ---- The ladder ----

const std::vector<Rung>& ladder() {
  // The rungs of scenes/corpus (the CMake scene tests use the same five).
  static const std::vector<Rung> rungs = {
      {"box", "ladder-10-box", "box.obj", 12, true, true},
      {"teapot", "ladder-1k-teapot-npm", "teapot.obj", 992, false, true},
      {"cheese-ball", "ladder-10k-cheese-ball", "cheese-ball.obj", 9334, false, true},
      {"bunny", "ladder-100k-bunny", "bunny_glmark2.obj", 69666, true, true},
      {"dragon", "ladder-1M-dragon", "dragon.obj", 871414, false, false},
  };
  return rungs;
}

const Rung* find_rung(const std::string& name) {
  for (const Rung& r : ladder())
    if (r.name == name) return &r;
  return nullptr;
}

fs::path rung_obj(const Rung& r) { return ra::cache_dir() / "corpus" / "ladder" / r.obj; }
fs::path rung_scene_file(const Rung& r) {
  return fs::path(RAYAUDIT_SOURCE_DIR) / "scenes" / "corpus" / (r.scene + ".json");
}

namespace {

struct Kept {
  const Rung* rung = nullptr;
  RungRays rays;
  std::map<std::tuple<int, bool, std::string>, BuiltTracer> tracers;
};
Kept& kept() {
  static Kept k;
  return k;
}

void keep_rung(const Rung& r) {
  Kept& k = kept();
  if (k.rung == &r) return;
  k.tracers.clear();
  k.rays = RungRays{};
  k.rung = &r;
}

}  // namespace

RungRays& rung_rays(const Rung& r) {
  keep_rung(r);
  RungRays& rr = kept().rays;
  if (rr.scene) return rr;
  auto scene = std::make_unique<ra::Scene>(ra::load_scene(rung_scene_file(r)));
  scene->width = kWidth;
  scene->height = kHeight;
  ra::apply_content_defaults(*scene);
  rr.mesh = scene->objects.at(0).mesh.get();
  if (rr.mesh->triangles.size() != r.triangles)
    throw ra::InputError(rung_obj(r).string() + ": " + std::to_string(rr.mesh->triangles.size()) +
                         " triangles, expected " + std::to_string(r.triangles) + " (run ci/fetch-corpus.sh)");
  // The cull rows are registered from `closed` (before any mesh is read).
  if (ra::cull_unsafe_reason(*rr.mesh).empty() != r.closed)
    throw std::runtime_error(rung_obj(r).string() + (r.closed ? " is not closed" : " is closed") +
                             ": fix the ladder in bench/common.cpp");
  const ra::Camera cam(scene->camera, kWidth, kHeight);
  rr.primary.reserve(std::size_t(kWidth) * kHeight);
  for (int j = 0; j < kHeight; ++j)
    for (int i = 0; i < kWidth; ++i) rr.primary.push_back(cam.ray(i + 0.5, j + 0.5));
  const ra::BoundingSphere bs = ra::scene_bounds(*scene);
  rr.light = scene->camera.position + (normalize(cam.right()) + normalize(cam.up())) * (2 * bs.radius);
  // Shadow rays start where our reference tracer (BVH, double, Möller) hits.
  ra::RenderOptions opt;
  opt.progress = false;
  const ra::Tracer ref(*scene, opt);
  std::vector<ra::Rayd> shadow(rr.primary.size());
  std::vector<unsigned char> used(rr.primary.size(), 0);
  const double tmin = 1e-4 * bs.radius;  // clear of the surface the ray leaves
  parallel_for(config().threads_all, rr.primary.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const auto sp = ref.shading_point(rr.primary[i]);
      if (!sp) continue;
      ra::Vec3d n = sp->ng;
      if (dot(n, rr.primary[i].d) > 0) n = -n;  // the seen side
      const ra::Vec3d to_light = rr.light - sp->p;
      const double dist = length(to_light);
      if (!(dist > 0) || dot(n, to_light) <= 0) continue;
      shadow[i] = ra::Rayd{sp->p, to_light / dist, tmin, dist};
      used[i] = 1;
    }
  });
  for (std::size_t i = 0; i < shadow.size(); ++i)
    if (used[i]) rr.shadow.push_back(shadow[i]);
  rr.scene = std::move(scene);
  return rr;
}

BuiltTracer& our_tracer(const Rung& r, ra::Accel accel, bool cull, const std::string& method) {
  RungRays& rr = rung_rays(r);
  auto& slot = kept().tracers[{int(accel), cull, method}];
  if (slot.tracer) return slot;
  ra::RenderOptions opt;
  opt.progress = false;
  opt.accel = accel;
  opt.cull = cull;
  opt.triangle_method = method;
  const long before = heap_live();
  const auto t0 = now();
  slot.tracer = std::make_unique<ra::Tracer>(*rr.scene, opt);
  slot.build_s = seconds_since(t0);
  slot.bytes_per_triangle = double(heap_live() - before) / double(r.triangles);
  return slot;
}

std::vector<ra::Rayd> subset(const std::vector<ra::Rayd>& rays, std::size_t max_rays) {
  // The copies on huge pages, as the tracers' own arrays: with 4 KiB pages
  // the dragon's 78 MB of primary rays made both tracers' rates bimodal
  // (runs at half speed), ours more than Embree's (exact 0.70x against
  // 0.87-0.91x, in alternate runs of one session).
  if (rays.size() <= max_rays) {
    std::vector<ra::Rayd> all;
    all.reserve(rays.size());
    ra::advise_huge_pages(all.data(), rays.size() * sizeof(ra::Rayd));
    all.insert(all.end(), rays.begin(), rays.end());
    return all;
  }
  // Indices frac(0.5 + k phi) N (the golden-ratio sequence), sorted: evenly
  // spread over the set, so over the image's rows AND columns (a fixed
  // stride near a multiple of the width samples a few columns only: the
  // dragon's 64 brute-force rays once all lay in its left margin).
  const double phi = 0.6180339887498949;
  std::vector<std::size_t> idx;
  idx.reserve(max_rays);
  for (std::size_t k = 0; k < max_rays; ++k) {
    const double f = 0.5 + double(k) * phi;
    idx.push_back(std::min(rays.size() - 1, std::size_t((f - std::floor(f)) * double(rays.size()))));
  }
  std::sort(idx.begin(), idx.end());
  idx.erase(std::unique(idx.begin(), idx.end()), idx.end());
  std::vector<ra::Rayd> out;
  out.reserve(idx.size());
  ra::advise_huge_pages(out.data(), idx.size() * sizeof(ra::Rayd));
  for (std::size_t i : idx) out.push_back(rays[i]);
  return out;
}

std::size_t trace_ours(const ra::Tracer& t, const std::vector<ra::Rayd>& rays, bool shadow, int threads,
                       std::vector<unsigned char>* hit_flags) {
  std::atomic<std::size_t> hits{0};
  if (hit_flags) hit_flags->assign(rays.size(), 0);
  parallel_for(threads, rays.size(), [&](std::size_t b, std::size_t e) {
    std::size_t n = 0;
    for (std::size_t i = b; i < e; ++i) {
      const bool h = shadow ? t.occluded(rays[i]) : t.intersect(rays[i]).has_value();
      n += h;
      if (h && hit_flags) (*hit_flags)[i] = 1;
    }
    hits.fetch_add(n, std::memory_order_relaxed);
  });
  return hits.load();
}

}  // namespace rb
