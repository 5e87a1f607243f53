// OBJ parsing: ours (serial and parallel) against tinyobjloader on the corpus
// dragon (871,414 triangles) and glmark2 bunny (69,666), from the cache that
// ci/fetch-corpus.sh fills. Reports bytes/s, peak heap bytes per triangle
// (global operator new/delete below count live and peak bytes), and for ours
// the ratio speedup_vs_tinyobj (tinyobj's mean time / ours, from the runs
// made earlier in the same process: run the tinyobj benchmark first, as
// registered).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <tiny_obj_loader.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <new>
#include <string>

#include "mesh.h"

namespace {

std::atomic<long> g_live{0}, g_peak{0};

void* counted_alloc(std::size_t n) {
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  const long now = g_live += long(malloc_usable_size(p));
  long peak = g_peak.load();
  while (now > peak && !g_peak.compare_exchange_weak(peak, now)) {
  }
  return p;
}
void counted_free(void* p) {
  if (!p) return;
  g_live -= long(malloc_usable_size(p));
  std::free(p);
}

}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }

namespace {

std::filesystem::path corpus_file(const char* name) {
  const char* c = std::getenv("RAYAUDIT_CACHE");
  const char* h = std::getenv("HOME");
  std::filesystem::path root = c ? std::filesystem::path(c) : std::filesystem::path(h ? h : ".") / ".cache/rayaudit";
  return root / "corpus/ladder" / name;
}

std::map<std::string, double> g_tiny_seconds;  // file -> tinyobj's mean seconds per parse

// Resets the peak to the current live bytes and returns the baseline.
long reset_peak() {
  g_peak = g_live.load();
  return g_live.load();
}

void BM_TinyObj(benchmark::State& state, const char* name) {
  const auto file = corpus_file(name);
  if (!std::filesystem::exists(file)) return state.SkipWithError(("no " + file.string() + ": run ci/fetch-corpus.sh").c_str());
  size_t tris = 0;
  long peak = 0;
  double seconds = 0;
  for (auto _ : state) {
    const long base = reset_peak();
    const auto t0 = std::chrono::steady_clock::now();
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, file.c_str(),
                                     file.parent_path().c_str(), true);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!ok) return state.SkipWithError(err.c_str());
    tris = 0;
    for (auto& s : shapes) tris += s.mesh.num_face_vertices.size();
    peak = std::max(peak, g_peak.load() - base);
    benchmark::DoNotOptimize(attrib.vertices.data());
  }
  g_tiny_seconds[name] = seconds / double(state.iterations());
  state.SetBytesProcessed(long(state.iterations()) * long(std::filesystem::file_size(file)));
  state.counters["triangles"] = double(tris);
  state.counters["peak_bytes_per_tri"] = double(peak) / double(tris);
}

void BM_Ours(benchmark::State& state, const char* name, int threads) {
  const auto file = corpus_file(name);
  if (!std::filesystem::exists(file)) return state.SkipWithError(("no " + file.string() + ": run ci/fetch-corpus.sh").c_str());
  ra::ObjOptions opt;
  opt.threads = threads;
  size_t tris = 0;
  long peak = 0;
  double seconds = 0;
  for (auto _ : state) {
    const long base = reset_peak();
    const auto t0 = std::chrono::steady_clock::now();
    ra::Mesh m = ra::load_obj(file, opt);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    tris = m.triangles.size();
    peak = std::max(peak, g_peak.load() - base);
    benchmark::DoNotOptimize(m.triangles.data());
  }
  seconds /= double(state.iterations());
  state.SetBytesProcessed(long(state.iterations()) * long(std::filesystem::file_size(file)));
  state.counters["triangles"] = double(tris);
  state.counters["peak_bytes_per_tri"] = double(peak) / double(tris);
  state.counters["threads"] = threads;
  if (g_tiny_seconds.count(name)) state.counters["speedup_vs_tinyobj"] = g_tiny_seconds[name] / seconds;
}

// Timed with steady_clock inside the loop as well, so the ratio uses the
// same clock for both; UseRealTime because the parallel parse uses threads.
BENCHMARK_CAPTURE(BM_TinyObj, dragon, "dragon.obj")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, dragon_serial, "dragon.obj", 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, dragon_parallel, "dragon.obj", 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_TinyObj, bunny, "bunny_glmark2.obj")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, bunny_serial, "bunny_glmark2.obj", 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, bunny_parallel, "bunny_glmark2.obj", 0)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
