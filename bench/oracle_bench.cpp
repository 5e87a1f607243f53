// Throughput of the exact oracle (validation/oracle.h) on the audit's own
// case families: cases per second, single-threaded and on two threads.
#include <benchmark/benchmark.h>

#include "audit.h"
#include "oracle.h"

#include <map>
#include <mutex>

namespace {

struct Flat {
  std::vector<ra::Rayd> rays;
  std::vector<ra::audit::Tri> tris;
};

// About 64k ray/triangle cases of a family, over all its sweep values, in double.
Flat cases(const std::string& family) {
  Flat f;
  const ra::audit::Family* fam = ra::audit::find_family(family);
  for (int s = 0; s < int(fam->sweep.size()); ++s)
    for (const auto& pc : ra::audit::probe_cases(*fam, s, ra::audit::Precision::f64, 7, 65536))
      for (const auto& t : pc.tris) f.rays.push_back(pc.ray), f.tris.push_back(t);
  return f;
}

void BM_OracleTriangle(benchmark::State& state, const std::string& family) {
  static std::map<std::string, Flat> cache;
  static std::mutex mu;
  const Flat* f;
  {
    std::lock_guard<std::mutex> lock(mu);
    if (!cache.count(family)) cache[family] = cases(family);
    f = &cache[family];
  }
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    const auto& t = f->tris[i];
    benchmark::DoNotOptimize(ra::oracle::triangle(f->rays[i], t.a, t.b, t.c));
    if (++i == f->rays.size()) i = 0;
    ++n;
  }
  state.counters["cases/s"] = benchmark::Counter(double(n), benchmark::Counter::kIsRate);
}

void BM_OracleSphere(benchmark::State& state) {
  const auto* fam = ra::audit::find_family("huge");
  std::vector<ra::audit::SphereCase> cs;
  for (int s = 0; s < int(fam->sweep.size()); ++s) {
    auto v = ra::audit::sphere_cases(*fam, s, ra::audit::Precision::f64, 7, 16384);
    cs.insert(cs.end(), v.begin(), v.end());
  }
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ra::oracle::sphere(cs[i].ray, cs[i].center, cs[i].radius));
    if (++i == cs.size()) i = 0;
    ++n;
  }
  state.counters["cases/s"] = benchmark::Counter(double(n), benchmark::Counter::kIsRate);
}

}  // namespace


BENCHMARK_CAPTURE(BM_OracleTriangle, random, std::string("random"))->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, random, std::string("random"))->Threads(2)->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, edge, std::string("edge"))->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, edge, std::string("edge"))->Threads(2)->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, closed_mesh, std::string("closed-mesh"))->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, closed_mesh, std::string("closed-mesh"))->Threads(2)->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, grazing, std::string("grazing"))->UseRealTime();
BENCHMARK_CAPTURE(BM_OracleTriangle, vertex, std::string("vertex"))->UseRealTime();
BENCHMARK(BM_OracleSphere)->UseRealTime();

BENCHMARK_MAIN();
