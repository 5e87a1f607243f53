// Group oracle/FAMILY/threads=T: throughput of the exact oracle
// (validation/exact/oracle.h) on every case family of the audit
// (validation/exact/families.h), in double: cases per second as a rate counter
// (the audit's target: 2 million cases/s with 2 threads) and the share of cases
// that needed exact arithmetic.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "bench.h"
#include "exact/families.h"
#include "exact/oracle.h"

namespace rb {
namespace {

using namespace ra::audit;

constexpr int kCasesPerFamily = 65536;
constexpr std::uint64_t kSeed = 7;

struct TriCases {
  std::vector<ra::Rayd> rays;
  std::vector<Tri> tris;
};

// About 64k ray/triangle pairs of a family, spread over its sweep values.
TriCases make_triangle_cases(const Family& f) {
  TriCases out;
  const int sweeps = int(f.sweep.size());
  for (int s = 0; s < sweeps; ++s) {
    const int probes = std::max(1, kCasesPerFamily / sweeps / f.tris_per_probe(s));
    TriangleBatch b;
    // closed-mesh makes all its probes in one call (they share the mesh).
    generate(f, s, Precision::f64, stream_seed(kSeed, f.name, s, 0), probes, b);
    for (const Probe& p : b.probes)
      for (int k = p.first; k < p.first + p.count; ++k) {
        out.rays.push_back(p.ray);
        out.tris.push_back(b.tris[std::size_t(k)]);
      }
  }
  return out;
}

std::vector<SphereCase> make_sphere_cases(const Family& f) {
  std::vector<SphereCase> out;
  const int sweeps = int(f.sweep.size());
  for (int s = 0; s < sweeps; ++s)
    generate(f, s, Precision::f64, stream_seed(kSeed, f.name, s, 0), kCasesPerFamily / sweeps, out);
  return out;
}

// Cases are built once per family, outside the timed loop, shared by threads.
std::mutex g_mu;
std::map<std::string, TriCases> g_tri;
std::map<std::string, std::vector<SphereCase>> g_sph;

const TriCases& tri_cases(const Family& f) {
  std::lock_guard<std::mutex> lock(g_mu);
  auto it = g_tri.find(f.name);
  if (it == g_tri.end()) it = g_tri.emplace(f.name, make_triangle_cases(f)).first;
  return it->second;
}
const std::vector<SphereCase>& sph_cases(const Family& f) {
  std::lock_guard<std::mutex> lock(g_mu);
  auto it = g_sph.find(f.name);
  if (it == g_sph.end()) it = g_sph.emplace(f.name, make_sphere_cases(f)).first;
  return it->second;
}

// One iteration: kChunk consecutive cases (wrapping around), on `threads`
// threads; cases/s from the wall clock over all iterations.
constexpr std::size_t kChunk = 16384;

template <class Test>
void run_oracle(benchmark::State& state, std::size_t size, int threads, Test test) {
  std::size_t start = 0, n = 0;
  const auto f0 = ra::oracle::exact_fallbacks();
  const auto t0 = now();
  for (auto _ : state) {
    parallel_for(threads, kChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) test((start + k) % size);
    });
    start = (start + kChunk) % size;
    n += kChunk;
  }
  state.counters["cases/s"] = double(n) / seconds_since(t0);
  state.counters["exact%"] = 100.0 * double(ra::oracle::exact_fallbacks() - f0) / double(std::max<std::size_t>(n, 1));
}

void BM_Triangle(benchmark::State& state, const Family* f, int threads) {
  const TriCases& c = tri_cases(*f);
  run_oracle(state, c.rays.size(), threads, [&](std::size_t i) {
    const Tri& t = c.tris[i];
    benchmark::DoNotOptimize(ra::oracle::triangle(c.rays[i], t.a, t.b, t.c));
  });
}

void BM_Sphere(benchmark::State& state, const Family* f, int threads) {
  const std::vector<SphereCase>& c = sph_cases(*f);
  run_oracle(state, c.size(), threads,
             [&](std::size_t i) { benchmark::DoNotOptimize(ra::oracle::sphere(c[i].ray, c[i].center, c[i].radius)); });
}

}  // namespace

void register_oracle() {
  for (const Family& f : families())
    for (int t : thread_counts()) {
      // A name two families share (refracted) names the sphere one apart.
      const std::string family = find_family(f.name) == &f ? f.name : f.name + "-sphere";
      const std::string name = "oracle/" + family + "/threads=" + std::to_string(t);
      const Family* fp = &f;
      std::function<void(benchmark::State&)> fn;
      if (f.kind == ra::Kind::sphere)
        fn = [fp, t](benchmark::State& s) { BM_Sphere(s, fp, t); };
      else
        fn = [fp, t](benchmark::State& s) { BM_Triangle(s, fp, t); };
      add(name, {}, fn);
    }
}

}  // namespace rb
