// Throughput of the exact oracle (validation/oracle.h) on every case family of
// the audit (validation/families.h), in double, on 1 and 2 threads: cases per
// second as a rate counter, three repetitions each, and at the end one summary
// line per family with the median cases/s and whether it meets the issue's
// 2 million cases per second (issue 6).
//
//   oracle_bench [--benchmark_filter=REGEX] [--benchmark_repetitions=N]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "families.h"
#include "oracle.h"

namespace {

using namespace ra::audit;

constexpr double kTarget = 2e6;    // cases per second, from issue 6
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

void BM_Triangle(benchmark::State& state, const Family* f) {
  const TriCases& c = tri_cases(*f);
  const std::size_t size = c.rays.size();
  // Threads start at different places so they do not walk the same cases.
  std::size_t i = (size / 2) * std::size_t(state.thread_index()) % size, n = 0;
  const auto f0 = ra::oracle::exact_fallbacks();
  for (auto _ : state) {
    const Tri& t = c.tris[i];
    benchmark::DoNotOptimize(ra::oracle::triangle(c.rays[i], t.a, t.b, t.c));
    if (++i == size) i = 0;
    ++n;
  }
  state.counters["cases/s"] = benchmark::Counter(double(n), benchmark::Counter::kIsRate);
  state.counters["exact%"] = benchmark::Counter(
      100.0 * double(ra::oracle::exact_fallbacks() - f0) / double(std::max<std::size_t>(n, 1)),
      benchmark::Counter::kAvgThreads);
}

void BM_Sphere(benchmark::State& state, const Family* f) {
  const std::vector<SphereCase>& c = sph_cases(*f);
  const std::size_t size = c.size();
  std::size_t i = (size / 2) * std::size_t(state.thread_index()) % size, n = 0;
  const auto f0 = ra::oracle::exact_fallbacks();
  for (auto _ : state) {
    benchmark::DoNotOptimize(ra::oracle::sphere(c[i].ray, c[i].center, c[i].radius));
    if (++i == size) i = 0;
    ++n;
  }
  state.counters["cases/s"] = benchmark::Counter(double(n), benchmark::Counter::kIsRate);
  state.counters["exact%"] = benchmark::Counter(
      100.0 * double(ra::oracle::exact_fallbacks() - f0) / double(std::max<std::size_t>(n, 1)),
      benchmark::Counter::kAvgThreads);
}

// Console output as usual, plus the median cases/s of every (family, threads)
// collected for the summary printed at the end.
class SummaryReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      const auto it = r.counters.find("cases/s");
      if (it == r.counters.end() || r.error_occurred) continue;
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      const bool single = r.run_type == Run::RT_Iteration && r.repetitions <= 1;
      if (median || single) rates_[r.run_name.function_name][int(r.threads)] = it->second.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nSummary: median cases/s per family (target %.0fM/s with 2 threads)\n", kTarget / 1e6);
    std::printf("%-26s %14s %14s  %s\n", "family", "1 thread", "2 threads", "meets 2M/s (2 threads)");
    for (const Family& f : families()) {
      const std::string key = std::string(f.kind == ra::Kind::sphere ? "sphere/" : "triangle/") + f.name;
      const auto it = rates_.find(key);
      if (it == rates_.end()) continue;
      auto get = [&](int t) { auto j = it->second.find(t); return j == it->second.end() ? -1.0 : j->second; };
      const double r1 = get(1), r2 = get(2);
      auto fmt = [](double v) {
        char buf[32];
        if (v < 0) return std::string("-");
        std::snprintf(buf, sizeof buf, "%.2fM/s", v / 1e6);
        return std::string(buf);
      };
      std::printf("%-26s %14s %14s  %s\n", key.c_str(), fmt(r1).c_str(), fmt(r2).c_str(),
                  r2 < 0 ? "-" : (r2 >= kTarget ? "yes" : "NO"));
    }
  }

 private:
  std::map<std::string, std::map<int, double>> rates_;
};

}  // namespace

int main(int argc, char** argv) {
  for (const Family& f : families()) {
    for (int threads : {1, 2}) {
      benchmark::internal::Benchmark* b;
      if (f.kind == ra::Kind::sphere)
        b = benchmark::RegisterBenchmark(("sphere/" + f.name).c_str(), BM_Sphere, &f);
      else
        b = benchmark::RegisterBenchmark(("triangle/" + f.name).c_str(), BM_Triangle, &f);
      b->Threads(threads)->UseRealTime()->MinTime(0.2)->Repetitions(3)->DisplayAggregatesOnly(true);
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  SummaryReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
