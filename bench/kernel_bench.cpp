// Group kernel/METHOD/PRECISION/cull|nocull/hit=P/back=B: every method of
// the registry (renderer/registry.h) on seeded batches whose hit rate and
// share of back-face rays are set exactly, so culling's early exit shows.
#include <cmath>
#include <map>
#include <optional>
#include <random>

#include "bench.h"
#include "registry.h"

namespace rb {
namespace {

using ra::Vec3d;

constexpr int kPairs = 4096;
constexpr int kHitRates[] = {0, 10, 50, 90, 100};
constexpr int kBackShares[] = {0, 50, 100};

// Exactly round(n * percent / 100) true flags, shuffled.
std::vector<bool> flags(std::mt19937& rng, int percent) {
  std::vector<bool> f(kPairs);
  const int k = int(std::lround(kPairs * percent / 100.0));
  for (int i = 0; i < kPairs; ++i) f[i] = i < k;
  std::shuffle(f.begin(), f.end(), rng);
  return f;
}

// The batch in double; each precision converts it once. `hit` says what a
// correct method answers without culling.
struct BatchD {
  std::vector<Vec3d> a, b, c;  // triangles; spheres: a = centre, b.x = radius; planes: a = normal, b.x = offset
  std::vector<ra::Rayd> rays;
  std::vector<bool> hit, back;
};

// Triangles with vertices in [-1, 1]^3 and |(B-A)x(C-A)| >= 0.1: P% of the
// rays aim inside (barycentrics >= 0.01), the others outside (one < -0.01),
// and B% of all rays come from the back side (the winding is chosen so), the
// same rays hit or not in either precision (margins far above rounding).
BatchD triangle_batch(int hit_pct, int back_pct) {
  BatchD bd;
  std::mt19937 rng(42u + unsigned(hit_pct) * 7u + unsigned(back_pct) * 1009u);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  bd.hit = flags(rng, hit_pct);
  bd.back = flags(rng, back_pct);
  for (int i = 0; i < kPairs; ++i) {
    Vec3d a, b, c;
    do {
      a = {u(rng), u(rng), u(rng)};
      b = {u(rng), u(rng), u(rng)};
      c = {u(rng), u(rng), u(rng)};
    } while (ra::length(ra::cross(b - a, c - a)) < 0.1);
    const bool inside = bd.hit[i];
    double b0, b1, b2;
    do {
      b1 = inside ? u01(rng) : 3 * u01(rng) - 1;
      b2 = inside ? u01(rng) : 3 * u01(rng) - 1;
      b0 = 1 - b1 - b2;
    } while (inside ? std::min({b0, b1, b2}) < 0.01 : std::min({b0, b1, b2}) > -0.01);
    const Vec3d p = a * b0 + b * b1 + c * b2;
    Vec3d o;
    do o = p + Vec3d{u(rng), u(rng), u(rng)} * 3.0;
    while (std::abs(ra::dot(ra::normalize(p - o), ra::normalize(ra::cross(b - a, c - a)))) < 0.05);
    const Vec3d d = p - o;
    // Back: the ray travels along the normal (B-A)x(C-A), seeing its back.
    const bool along = ra::dot(d, ra::cross(b - a, c - a)) > 0;
    if (along != bool(bd.back[i])) std::swap(b, c);
    bd.a.push_back(a);
    bd.b.push_back(b);
    bd.c.push_back(c);
    bd.rays.push_back(ra::Rayd{o, d});
  }
  return bd;
}

// Spheres: centre in [-1, 1]^3, radius in [0.2, 1]. Hitting rays start
// 3-5 radii away aiming within 0.9 r of the centre, or, for B% of them,
// inside the sphere (they meet its back, inner face); missing rays pass at
// least 1.1 r from the centre. So B is the back share of the hits.
BatchD sphere_batch(int hit_pct, int back_pct) {
  BatchD bd;
  std::mt19937 rng(77u + unsigned(hit_pct) * 7u + unsigned(back_pct) * 1009u);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  bd.hit = flags(rng, hit_pct);
  bd.back = flags(rng, back_pct);
  auto unit = [&] {
    Vec3d v;
    do v = {u(rng), u(rng), u(rng)};
    while (ra::length(v) < 0.1 || ra::length(v) > 1);
    return ra::normalize(v);
  };
  for (int i = 0; i < kPairs; ++i) {
    const Vec3d c{u(rng), u(rng), u(rng)};
    const double r = 0.2 + 0.8 * u01(rng);
    Vec3d o, d;
    if (bd.hit[i] && bd.back[i]) {
      o = c + unit() * (0.5 * r * u01(rng));
      d = unit();
    } else {
      const Vec3d w = unit();
      o = c + w * (r * (3 + 2 * u01(rng)));
      Vec3d side;
      do side = ra::cross(w, unit());
      while (ra::length(side) < 0.1);
      side = ra::normalize(side);
      const double off = bd.hit[i] ? 0.9 * r * u01(rng) : r * (1.2 + 0.8 * u01(rng));
      d = (c + side * off) - o;
      bd.back[i] = false;  // the share counts hits from inside only
    }
    bd.a.push_back(c);
    bd.b.push_back({r, 0, 0});
    bd.c.push_back({0, 0, 0});
    bd.rays.push_back(ra::Rayd{o, d});
  }
  return bd;
}

// Planes through points of [-1, 1]^3: P% of the rays head towards the plane
// (the others away from it), B% start behind it (on the side opposite the
// normal).
BatchD plane_batch(int hit_pct, int back_pct) {
  BatchD bd;
  std::mt19937 rng(99u + unsigned(hit_pct) * 7u + unsigned(back_pct) * 1009u);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  bd.hit = flags(rng, hit_pct);
  bd.back = flags(rng, back_pct);
  for (int i = 0; i < kPairs; ++i) {
    Vec3d n;
    do n = {u(rng), u(rng), u(rng)};
    while (ra::length(n) < 0.1);
    n = ra::normalize(n);
    const Vec3d p{u(rng), u(rng), u(rng)};
    const double side = bd.back[i] ? -1 : 1;
    const Vec3d o = p + n * (side * (0.5 + u01(rng)));
    Vec3d tangent = ra::normalize(ra::cross(n, std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}));
    // Towards the plane: the normal component points back across it.
    const double along = (bd.hit[i] ? -side : side) * (0.2 + u01(rng));
    const Vec3d d = n * along + tangent * u(rng);
    bd.a.push_back(n);
    bd.b.push_back({ra::dot(n, p), 0, 0});
    bd.c.push_back({0, 0, 0});
    bd.rays.push_back(ra::Rayd{o, d});
  }
  return bd;
}

template <class T>
struct Batch {
  std::vector<ra::Vec3<T>> a, b, c;
  std::vector<ra::Ray<T>> rays;
  std::vector<bool> hit, back;
};

template <class T>
const Batch<T>& batch(ra::Kind kind, int hit_pct, int back_pct) {
  static std::map<std::tuple<int, int, int>, Batch<T>> cache;
  auto key = std::make_tuple(int(kind), hit_pct, back_pct);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  const BatchD bd = kind == ra::Kind::triangle ? triangle_batch(hit_pct, back_pct)
                    : kind == ra::Kind::sphere ? sphere_batch(hit_pct, back_pct)
                                               : plane_batch(hit_pct, back_pct);
  Batch<T> bt;
  for (int i = 0; i < kPairs; ++i) {
    bt.a.emplace_back(bd.a[i]);
    bt.b.emplace_back(bd.b[i]);
    bt.c.emplace_back(bd.c[i]);
    bt.rays.push_back(static_cast<ra::Ray<T>>(bd.rays[i]));
  }
  bt.hit = bd.hit;
  bt.back = bd.back;
  return cache.emplace(key, std::move(bt)).first->second;
}

// Each test's answer reduced to a scalar at the call: merging or copying
// whole optionals made GCC store float's 16-byte optional as two halves and
// reload it as one (a failed store forwarding, ~5 ns per float test).
template <class H>
auto t_of(const std::optional<H>& h) {
  return h ? h->t : decltype(h->t)(-1);
}

// Times `test(i)` over the batch; checks first that the answers match the
// batch's design (up to 0.5% of the pairs may differ; the documents'
// wrong-on-purpose variants are not checked: their `hit_rate` says it).
template <class T, class Test>
void time_batch(benchmark::State& state, const Batch<T>& bt, bool cull, bool allow_wrong, Test test) {
  int hits = 0, expected = 0, wrong = 0;
  for (int i = 0; i < kPairs; ++i) {
    const bool want = bt.hit[i] && !(cull && bt.back[i]);
    const bool got = test(i) >= T(0);
    hits += got;
    expected += want;
    wrong += got != want;
  }
  if (!allow_wrong && wrong > kPairs / 200) {
    state.SkipWithError(
        (std::to_string(wrong) + " of " + std::to_string(kPairs) + " answers differ from the batch's design").c_str());
    return;
  }
  // The thread's CPU time: steadier than the wall clock on a shared machine.
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state)
    for (int i = 0; i < kPairs; ++i) {
      const T t = test(i);
      benchmark::DoNotOptimize(t);
    }
  const double elapsed_ns = (thread_cpu_seconds() - cpu0) * 1e9;
  state.counters["hit_rate"] = double(hits) / kPairs;
  state.counters["expected_hit_rate"] = double(expected) / kPairs;
  // CPU ns per test over all iterations, including the registry's indirect
  // call (a plain number: a rate counter would print an "s").
  state.counters["ns_per_test"] = elapsed_ns / (double(state.iterations()) * kPairs);
}

// Triangles through the prepared entry point, as meshes call them.
template <class T>
void bm_triangle(benchmark::State& state, const ra::Method* m, bool cull, int hit_pct, int back_pct) {
  const Batch<T>& bt = batch<T>(ra::Kind::triangle, hit_pct, back_pct);
  const ra::TriangleKernels<T>& k = m->triangle<T>();
  const std::size_t stride = (k.pre_bytes + sizeof(double) - 1) / sizeof(double);
  std::vector<double> pre(stride * kPairs);
  for (int i = 0; i < kPairs; ++i) k.prepare(bt.a[i], bt.b[i], bt.c[i], &pre[stride * i]);
  time_batch(state, bt, cull, m->wrong_on_purpose,
             [&](int i) { return t_of(k.hit_pre(bt.rays[i], &pre[stride * i], cull)); });
}

template <class T>
void bm_sphere(benchmark::State& state, const ra::Method* m, int hit_pct, int back_pct) {
  const Batch<T>& bt = batch<T>(ra::Kind::sphere, hit_pct, back_pct);
  const auto& k = m->sphere<T>();
  time_batch(state, bt, false, m->wrong_on_purpose, [&](int i) { return t_of(k.hit(bt.rays[i], bt.a[i], bt.b[i].x)); });
}

template <class T>
void bm_plane(benchmark::State& state, const ra::Method* m, int hit_pct, int back_pct) {
  const Batch<T>& bt = batch<T>(ra::Kind::plane, hit_pct, back_pct);
  const auto& k = m->plane<T>();
  time_batch(state, bt, false, m->wrong_on_purpose, [&](int i) { return t_of(k.hit(bt.rays[i], bt.a[i], bt.b[i].x)); });
}

}  // namespace

void register_kernel() {
  for (const ra::Method& m : ra::methods()) {
    // Culling is a triangle option; spheres and planes have one row.
    const std::vector<bool> culls =
        m.kind == ra::Kind::triangle ? std::vector<bool>{false, true} : std::vector<bool>{false};
    for (const char* prec : {"float", "double"})
      for (bool cull : culls)
        for (int p : kHitRates)
          for (int b : kBackShares) {
            const std::string name = "kernel/" + m.name + "/" + prec + (cull ? "/cull" : "/nocull") +
                                     "/hit=" + std::to_string(p) + "/back=" + std::to_string(b);
            const bool f = prec[0] == 'f';
            const ra::Method* mp = &m;
            std::function<void(benchmark::State&)> fn;
            switch (m.kind) {
              case ra::Kind::triangle:
                fn = [=](benchmark::State& s) {
                  f ? bm_triangle<float>(s, mp, cull, p, b) : bm_triangle<double>(s, mp, cull, p, b);
                };
                break;
              case ra::Kind::sphere:
                fn = [=](benchmark::State& s) { f ? bm_sphere<float>(s, mp, p, b) : bm_sphere<double>(s, mp, p, b); };
                break;
              case ra::Kind::plane:
                fn = [=](benchmark::State& s) { f ? bm_plane<float>(s, mp, p, b) : bm_plane<double>(s, mp, p, b); };
                break;
            }
            add(name, {}, fn);
          }
  }
}

}  // namespace rb
