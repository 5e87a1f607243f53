// Timing a subject on the kernel bench's batch (see timing.h).
#include "timing.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "io/atomic_file.h"

namespace ra::audit {

namespace {

constexpr int kPairs = 4096;

// bench/kernel_bench.cpp's triangle_batch(50, 0), draw for draw: exactly
// half the rays aim inside (barycentrics >= 0.01), all from the front.
struct Pairs {
  std::vector<Vec3d> a, b, c;
  std::vector<Rayd> rays;
};
Pairs kernel_batch() {
  const int hit_pct = 50, back_pct = 0;
  std::mt19937 rng(42u + unsigned(hit_pct) * 7u + unsigned(back_pct) * 1009u);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  auto flags = [&](int percent) {
    std::vector<bool> f(kPairs);
    const int k = int(std::lround(kPairs * percent / 100.0));
    for (int i = 0; i < kPairs; ++i) f[std::size_t(i)] = i < k;
    std::shuffle(f.begin(), f.end(), rng);
    return f;
  };
  const std::vector<bool> hit = flags(hit_pct), back = flags(back_pct);
  Pairs p;
  for (int i = 0; i < kPairs; ++i) {
    Vec3d a, b, c;
    do {
      a = {u(rng), u(rng), u(rng)};
      b = {u(rng), u(rng), u(rng)};
      c = {u(rng), u(rng), u(rng)};
    } while (length(cross(b - a, c - a)) < 0.1);
    const bool inside = hit[std::size_t(i)];
    double b0, b1, b2;
    do {
      b1 = inside ? u01(rng) : 3 * u01(rng) - 1;
      b2 = inside ? u01(rng) : 3 * u01(rng) - 1;
      b0 = 1 - b1 - b2;
    } while (inside ? std::min({b0, b1, b2}) < 0.01 : std::min({b0, b1, b2}) > -0.01);
    const Vec3d q = a * b0 + b * b1 + c * b2;
    Vec3d o;
    do o = q + Vec3d{u(rng), u(rng), u(rng)} * 3.0;
    while (std::abs(dot(normalize(q - o), normalize(cross(b - a, c - a)))) < 0.05);
    const Vec3d d = q - o;
    const bool along = dot(d, cross(b - a, c - a)) > 0;
    if (along != bool(back[std::size_t(i)])) std::swap(b, c);
    p.a.push_back(a), p.b.push_back(b), p.c.push_back(c), p.rays.push_back(Rayd{o, d});
  }
  return p;
}

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

template <class T, class F>
double time_batch(const Pairs& p, const F& f, int repetitions, double min_seconds) {
  std::vector<Vec3<T>> a, b, c;
  std::vector<Ray<T>> rays;
  for (int i = 0; i < kPairs; ++i) {
    a.emplace_back(p.a[std::size_t(i)]), b.emplace_back(p.b[std::size_t(i)]), c.emplace_back(p.c[std::size_t(i)]);
    rays.push_back(static_cast<Ray<T>>(p.rays[std::size_t(i)]));
  }
  std::vector<double> ns;
  volatile T sink = 0;
  for (int r = 0; r < std::max(1, repetitions); ++r) {
    long long tests = 0;
    const double t0 = cpu_seconds();
    double t1 = t0;
    do {
      for (int i = 0; i < kPairs; ++i) {
        const auto h = f(rays[std::size_t(i)], a[std::size_t(i)], b[std::size_t(i)], c[std::size_t(i)]);
        sink = h ? h->t : T(-1);
      }
      tests += kPairs;
      t1 = cpu_seconds();
    } while (t1 - t0 < min_seconds);
    ns.push_back((t1 - t0) * 1e9 / double(tests));
  }
  (void)sink;
  std::sort(ns.begin(), ns.end());
  return ns[ns.size() / 2];
}

}  // namespace

Timing time_subject(const TriangleSubject& s, int repetitions, double min_seconds) {
  static const Pairs p = kernel_batch();
  const double ns = s.precision == Precision::f32 ? time_batch<float>(p, s.f32, repetitions, min_seconds)
                                                  : time_batch<double>(p, s.f64, repetitions, min_seconds);
  return {s.name(), ns};
}

void write_timings_csv(const std::string& path, const std::vector<Timing>& rows) {
  std::string text = "subject,ns_per_test\n";
  for (const Timing& t : rows) {
    char buf[64];
    std::snprintf(buf, sizeof buf, ",%.6g\n", t.ns_per_test);
    text += t.subject + buf;
  }
  write_text_atomically(path, text);
}

}  // namespace ra::audit
