// Every registered triangle method x precision x culling on one fixed, seeded
// batch of 4096 ray/triangle pairs at a 50% hit rate; reports ns per test.
// Methods come from the registry, so new ones appear here without edits.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "registry.h"

namespace {

using ra::Vec3d;

constexpr int kPairs = 4096;
constexpr unsigned kSeed = 42;

// The batch in double; each precision converts it once.
struct BatchD {
  std::vector<Vec3d> a, b, c;
  std::vector<ra::Rayd> rays;
};

// Triangles with vertices in [-1, 1]^3 and area >= 0.05; exactly half the
// rays aim inside (barycentrics >= 0.01) and half outside (one < -0.01), in
// shuffled order. Every ray meets the front face (the winding is flipped
// where needed), so culling changes the work, not the hit rate.
const BatchD& batch_d() {
  static const BatchD batch = [] {
    BatchD bd;
    std::mt19937 rng(kSeed);
    std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
    std::vector<bool> inside(kPairs);
    for (int i = 0; i < kPairs; ++i) inside[i] = i < kPairs / 2;
    std::shuffle(inside.begin(), inside.end(), rng);
    for (int i = 0; i < kPairs; ++i) {
      Vec3d a, b, c;
      do {
        a = {u(rng), u(rng), u(rng)};
        b = {u(rng), u(rng), u(rng)};
        c = {u(rng), u(rng), u(rng)};
      } while (ra::length(ra::cross(b - a, c - a)) < 0.1);
      double b0, b1, b2;
      do {
        b1 = inside[i] ? u01(rng) : 3 * u01(rng) - 1;
        b2 = inside[i] ? u01(rng) : 3 * u01(rng) - 1;
        b0 = 1 - b1 - b2;
      } while (inside[i] ? std::min({b0, b1, b2}) < 0.01 : std::min({b0, b1, b2}) > -0.01);
      const Vec3d p = a * b0 + b * b1 + c * b2;
      const Vec3d o = p + Vec3d{u(rng), u(rng), u(rng)} * 3.0;
      const Vec3d d = p - o;
      if (ra::dot(d, ra::cross(b - a, c - a)) > 0) std::swap(b, c);
      bd.a.push_back(a);
      bd.b.push_back(b);
      bd.c.push_back(c);
      bd.rays.push_back(ra::Rayd{o, d});
    }
    return bd;
  }();
  return batch;
}

template <class T>
struct Batch {
  std::vector<ra::Vec3<T>> a, b, c;
  std::vector<ra::Ray<T>> rays;
};

template <class T>
const Batch<T>& batch() {
  static const Batch<T> batch = [] {
    const BatchD& bd = batch_d();
    Batch<T> bt;
    for (int i = 0; i < kPairs; ++i) {
      bt.a.emplace_back(bd.a[i]);
      bt.b.emplace_back(bd.b[i]);
      bt.c.emplace_back(bd.c[i]);
      bt.rays.push_back(static_cast<ra::Ray<T>>(bd.rays[i]));
    }
    return bt;
  }();
  return batch;
}

// prepared = true: the triangles are prepared before timing (hit_pre);
// false: the direct entry point (hit), precomputation included.
template <class T>
void bm_triangle(benchmark::State& state, const ra::Method* m, bool cull, bool prepared) {
  const Batch<T>& bt = batch<T>();
  const ra::TriangleKernels<T>& k = m->triangle<T>();
  // Prepared records, each on a double-aligned stride.
  const std::size_t stride = (k.pre_bytes + sizeof(double) - 1) / sizeof(double);
  std::vector<double> pre(stride * kPairs);
  for (int i = 0; i < kPairs; ++i) k.prepare(bt.a[i], bt.b[i], bt.c[i], &pre[stride * i]);
  // Each test yields the hit's t, or -1 for a miss (t >= tmin = 0 on a hit).
  // The optional is reduced to a scalar right at each call: merging or
  // copying whole optionals made GCC store float's 16-byte one (returned in
  // xmm0 + rax) as two halves and reload it as one 16-byte value, a failed
  // store forwarding that cost ~5 ns per float test (double's optional is
  // returned in memory and was not affected).
  const auto t_of = [](const std::optional<ra::TriangleHit<T>>& h) { return h ? h->t : T(-1); };
  auto test = [&](int i) {
    return prepared ? t_of(k.hit_pre(bt.rays[i], &pre[stride * i], cull))
                    : t_of(k.hit(bt.rays[i], bt.a[i], bt.b[i], bt.c[i], cull));
  };
  int hits = 0;
  for (int i = 0; i < kPairs; ++i) hits += test(i) >= T(0);
  const double rate = double(hits) / kPairs;
  if (std::abs(rate - 0.5) > 0.05) {
    state.SkipWithError(("hit rate " + std::to_string(rate) + " is not ~50%").c_str());
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    for (int i = 0; i < kPairs; ++i) {
      const T t = test(i);
      benchmark::DoNotOptimize(t);
    }
  }
  const std::chrono::duration<double, std::nano> elapsed = std::chrono::steady_clock::now() - start;
  state.counters["hit_rate"] = rate;
  // Wall-clock nanoseconds per ray/triangle test over all iterations, as a
  // plain number (an inverted rate counter would print it with an "s"
  // suffix). Includes the registry's indirect call.
  state.counters["ns_per_test"] = elapsed.count() / (double(state.iterations()) * kPairs);
}

void register_all() {
  for (const ra::Method& m : ra::methods()) {
    if (m.kind != ra::Kind::triangle) continue;
    // The prepared path for every method; the direct one too where the
    // prepared record is a real precomputation (baldwin's transform).
    for (bool prepared : {true, false}) {
      if (!prepared && m.precompute_bytes_float == 0) continue;
      for (bool cull : {false, true}) {
        const std::string tail =
            std::string(cull ? "/cull" : "/nocull") + (prepared ? "/prepared" : "/direct");
        benchmark::RegisterBenchmark(("tri/" + m.name + "/float" + tail).c_str(),
                                     [&m, cull, prepared](benchmark::State& s) {
                                       bm_triangle<float>(s, &m, cull, prepared);
                                     })
            ->MinTime(0.2);
        benchmark::RegisterBenchmark(("tri/" + m.name + "/double" + tail).c_str(),
                                     [&m, cull, prepared](benchmark::State& s) {
                                       bm_triangle<double>(s, &m, cull, prepared);
                                     })
            ->MinTime(0.2);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
