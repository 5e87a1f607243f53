// OBJ parsing: ours (serial and parallel) against tinyobjloader on the corpus
// dragon (871,414 triangles) and glmark2 bunny (69,666), from the cache that
// ci/fetch-corpus.sh fills. Reports bytes/s, peak heap bytes per triangle
// (global operator new/delete below count live and peak bytes) and, after
// all runs, a summary: per parse the median wall and process-CPU time of
// every iteration (repetitions included), MB/s, and ours/tinyobj speedups
// from those medians, all measured in this one process. The machine may be
// shared: CPU time is the steadier figure for the serial parses. "parallel"
// is the default a user gets with threads = 0: files under
// ObjOptions::parallel_min_bytes (8 MB; the bunny is 2.4 MB) parse serially.
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <vector>

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

// Per parse ("dragon tinyobj", "dragon ours x1", ...): every iteration's
// wall and process-CPU seconds, and the largest peak bytes per triangle.
struct Samples {
  std::vector<double> wall, cpu;
  double peak_per_tri = 0;
  std::string file;
};
std::map<std::string, Samples> g_samples;
std::vector<std::string> g_order;

Samples& samples(const std::string& key, const char* file) {
  if (!g_samples.count(key)) g_order.push_back(key);
  Samples& s = g_samples[key];
  s.file = file;
  return s;
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Resets the peak to the current live bytes and returns the baseline.
long reset_peak() {
  g_peak = g_live.load();
  return g_live.load();
}

// Times one parse (steady clock and process CPU; the result is destroyed
// outside the timed part, for both parsers alike).
template <class Parse>
void run(benchmark::State& state, const std::string& key, const char* name, Parse&& parse) {
  const auto file = corpus_file(name);
  if (!std::filesystem::exists(file))
    return state.SkipWithError(("no " + file.string() + ": run ci/fetch-corpus.sh").c_str());
  Samples& smp = samples(key, name);
  size_t tris = 0;
  long peak = 0;
  for (auto _ : state) {
    const long base = reset_peak();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_seconds();
    auto result = parse(file, tris);
    smp.cpu.push_back(process_cpu_seconds() - c0);
    smp.wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    peak = std::max(peak, g_peak.load() - base);
    benchmark::DoNotOptimize(result);
  }
  const double per_tri = tris ? double(peak) / double(tris) : 0;
  smp.peak_per_tri = std::max(smp.peak_per_tri, per_tri);
  state.SetBytesProcessed(long(state.iterations()) * long(std::filesystem::file_size(file)));
  state.counters["triangles"] = double(tris);
  state.counters["peak_bytes_per_tri"] = per_tri;
}

void BM_TinyObj(benchmark::State& state, const char* name) {
  run(state, std::string(name) + " tinyobj", name, [&](const std::filesystem::path& file, size_t& tris) {
    struct Tiny {
      tinyobj::attrib_t attrib;
      std::vector<tinyobj::shape_t> shapes;
      std::vector<tinyobj::material_t> materials;
    };
    auto r = std::make_unique<Tiny>();
    std::string warn, err;
    if (!tinyobj::LoadObj(&r->attrib, &r->shapes, &r->materials, &warn, &err, file.c_str(),
                          file.parent_path().c_str(), true))
      state.SkipWithError(err.c_str());
    tris = 0;
    for (auto& s : r->shapes) tris += s.mesh.num_face_vertices.size();
    return r;
  });
}

void BM_Ours(benchmark::State& state, const char* name, int threads) {
  const std::string key = std::string(name) + (threads == 1 ? " ours serial" : " ours parallel");
  ra::ObjOptions opt;
  opt.threads = threads;
  state.counters["threads"] = threads;
  run(state, key, name, [&](const std::filesystem::path& file, size_t& tris) {
    auto m = std::make_unique<ra::Mesh>(ra::load_obj(file, opt));
    tris = m->triangles.size();
    return m;
  });
}

// Median over every iteration of every repetition, per parse; speedups are
// tinyobj's median / ours, wall and CPU, from this process's runs only.
void print_summary() {
  if (g_order.empty()) return;
  std::printf("\nSummary (medians of all iterations; CPU = process CPU time, all threads)\n");
  std::printf("%-28s %5s %9s %9s %9s %9s %10s %10s %11s\n", "parse", "n", "wall ms", "cpu ms", "MB/s wall",
              "MB/s cpu", "x tiny wall", "x tiny cpu", "peak B/tri");
  for (const auto& key : g_order) {
    const Samples& s = g_samples[key];
    const double mb = double(std::filesystem::file_size(corpus_file(s.file.c_str()))) / 1e6;
    const double w = median(s.wall), c = median(s.cpu);
    const std::string tkey = s.file + " tinyobj";
    double xw = 0, xc = 0;
    if (g_samples.count(tkey) && key != tkey) {
      xw = median(g_samples[tkey].wall) / w;
      xc = median(g_samples[tkey].cpu) / c;
    }
    std::printf("%-28s %5zu %9.1f %9.1f %9.1f %9.1f %10.2f %10.2f %11.1f\n", key.c_str(), s.wall.size(), w * 1e3,
                c * 1e3, mb / w, mb / c, xw, xc, s.peak_per_tri);
  }
  for (const auto& key : g_order)
    if (key.find(" ours ") != std::string::npos) {
      const Samples& s = g_samples[key];
      const std::string tkey = s.file + " tinyobj";
      if (!g_samples.count(tkey)) continue;
      std::printf("speedup_vs_tinyobj %-24s wall %.2fx  cpu %.2fx  peak bytes/tri %.1f vs %.1f\n", key.c_str(),
                  median(g_samples[tkey].wall) / median(s.wall), median(g_samples[tkey].cpu) / median(s.cpu),
                  s.peak_per_tri, g_samples[tkey].peak_per_tri);
    }
  std::printf("(ours maps the file read-only instead of copying it to the heap; tinyobj streams it:\n"
              " neither holds the file on the heap.)\n");
}

// UseRealTime because the parallel parse uses threads.
BENCHMARK_CAPTURE(BM_TinyObj, dragon, "dragon.obj")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, dragon_serial, "dragon.obj", 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, dragon_parallel, "dragon.obj", 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_TinyObj, bunny, "bunny_glmark2.obj")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, bunny_serial, "bunny_glmark2.obj", 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Ours, bunny_parallel, "bunny_glmark2.obj", 0)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  print_summary();
  return 0;
}
