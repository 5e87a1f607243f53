// The audit engine: every subject x precision x family x sweep value,
// graded against the exact oracle; statistics merge commutatively, so results never depend on threads.
#include "audit.h"

#include <set>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "shading/glass.h"
#include "spawn.h"
#include "workers.h"

namespace ra::audit {

// ---------------------------------------------------------- subjects ---
TriangleSubject registry_triangle(const Method& m, Precision p) {
  if (p == Precision::f32) {
    auto k = m.tri_f.hit;
    return triangle_subject<float>(
        m.name, [k](const Rayf& r, const Vec3f& a, const Vec3f& b, const Vec3f& c) { return k(r, a, b, c, false); });
  }
  auto k = m.tri_d.hit;
  return triangle_subject<double>(
      m.name, [k](const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) { return k(r, a, b, c, false); });
}

SphereSubject registry_sphere(const Method& m, Precision p) {
  if (p == Precision::f32) {
    auto k = m.sph_f.hit;
    return sphere_subject<float>(m.name, [k](const Rayf& r, const Vec3f& c, float rad) { return k(r, c, rad); });
  }
  auto k = m.sph_d.hit;
  return sphere_subject<double>(m.name, [k](const Rayd& r, const Vec3d& c, double rad) { return k(r, c, rad); });
}

// ------------------------------------------------------------- stats ---
namespace {

// Distance in representable values of T between x and y (saturating).
template <class T>
std::uint64_t ulp_distance(T x, T y) {
  using I = std::conditional_t<sizeof(T) == 4, std::int32_t, std::int64_t>;
  I ix, iy;
  std::memcpy(&ix, &x, sizeof x);
  std::memcpy(&iy, &y, sizeof y);
  // Map the sign-magnitude bit patterns to a monotonic signed line.
  auto line = [](I i) -> long double {
    return i < 0 ? -static_cast<long double>(i & std::numeric_limits<I>::max()) : static_cast<long double>(i);
  };
  const long double d = std::fabs(line(ix) - line(iy));
  return d >= 1.8e19L ? std::numeric_limits<std::uint64_t>::max() : static_cast<std::uint64_t>(d);
}

int ulp_bin(std::uint64_t v) {
  if (v < 64) return int(v);
  const int e = 63 - __builtin_clzll(v);    // >= 6
  const int sub = int((v >> (e - 2)) & 3);  // next two bits
  return std::min(Stats::kUlpBins - 1, 64 + (e - 6) * 4 + sub);
}
std::uint64_t ulp_bin_low(int bin) {
  if (bin < 64) return std::uint64_t(bin);
  const int e = (bin - 64) / 4 + 6, sub = (bin - 64) % 4;
  return (std::uint64_t(1) << e) + (std::uint64_t(sub) << (e - 2));
}
// Relative errors: bin 0 is exact; then 8 bins per octave from 2^kRelMinExp.
int rel_bin(double r) {
  if (r <= 0) return 0;
  const double l = std::log2(r);  // +inf for r = inf: the last bin
  const double b = 1 + std::floor((l - Stats::kRelMinExp) * 8);
  return int(std::clamp(b, 1.0, double(Stats::kRelBins - 1)));
}
double rel_bin_low(int bin) { return bin == 0 ? 0 : std::exp2(Stats::kRelMinExp + (bin - 1) / 8.0); }

template <std::size_t N>
int median_bin(const std::array<std::uint64_t, N>& h, std::uint64_t n) {
  std::uint64_t acc = 0;
  for (std::size_t i = 0; i < N; ++i)
    if ((acc += h[i]) * 2 >= n) return int(i);
  return int(N) - 1;
}

}  // namespace

void Stats::merge(const Stats& o) {
  // Checked: counts read from shard files could wrap (2^64-1 + 20 became 19).
  auto add = [](std::uint64_t& a, std::uint64_t b) {
    if (__builtin_add_overflow(a, b, &a)) throw std::overflow_error("a count overflows 2^64-1 when merged");
  };
  add(tests, o.tests), add(true_hits, o.true_hits), add(false_hits, o.false_hits);
  add(true_misses, o.true_misses), add(false_misses, o.false_misses);
  add(boundary_hits, o.boundary_hits), add(boundary_misses, o.boundary_misses);
  add(coplanar_hits, o.coplanar_hits), add(coplanar_misses, o.coplanar_misses);
  add(degenerate_hits, o.degenerate_hits), add(degenerate_misses, o.degenerate_misses);
  add(nan_inf, o.nan_inf), add(wrong_t, o.wrong_t);
  add(groups, o.groups), add(leaks, o.leaks), add(double_hits, o.double_hits);
  add(spawned, o.spawned), add(self_hits, o.self_hits), add(skipped_walls, o.skipped_walls);
  add(t_samples, o.t_samples);
  max_ulps = std::max(max_ulps, o.max_ulps);
  max_rel = std::max(max_rel, o.max_rel);
  for (int i = 0; i < kUlpBins; ++i) add(ulp_hist[i], o.ulp_hist[i]);
  for (int i = 0; i < kRelBins; ++i) add(rel_hist[i], o.rel_hist[i]);
  add(back_hits, o.back_hits), add(back_false_misses, o.back_false_misses);
  for (std::uint64_t e : o.examples) note_example(e);
}

// Keeps the kExamples lowest: the same set in any merge order.
void Stats::note_example(std::uint64_t probe) {
  const auto at = std::lower_bound(examples.begin(), examples.end(), probe);
  if (at != examples.end() && *at == probe) return;
  if (examples.size() >= kExamples && at == examples.end()) return;
  examples.insert(at, probe);
  if (examples.size() > kExamples) examples.pop_back();
}

std::uint64_t Stats::median_ulps() const { return t_samples ? ulp_bin_low(median_bin(ulp_hist, t_samples)) : 0; }
double Stats::median_rel() const { return t_samples ? rel_bin_low(median_bin(rel_hist, t_samples)) : 0; }

// At most 1: a hit at NaN t is both wrong and NaN, so the sum can pass the
// number of tests (a cell of NaN answers read 216%).
double Stats::badness() const {
  return tests ? std::min(1.0, double(wrong() + leaks + double_hits + nan_inf) / double(tests)) : 0;
}

nlohmann::json Stats::to_json() const {
  nlohmann::json j = {{"tests", tests},
                      {"wrong", wrong()},
                      {"wrong_pct", tests ? 100.0 * double(wrong()) / double(tests) : 0.0},
                      {"true_hits", true_hits},
                      {"false_hits", false_hits},
                      {"true_misses", true_misses},
                      {"false_misses", false_misses},
                      {"boundary_hits", boundary_hits},
                      {"boundary_misses", boundary_misses},
                      {"coplanar_hits", coplanar_hits},
                      {"coplanar_misses", coplanar_misses},
                      {"degenerate_hits", degenerate_hits},
                      {"degenerate_misses", degenerate_misses},
                      {"nan_inf", nan_inf},
                      {"wrong_t", wrong_t},
                      {"groups", groups},
                      {"leaks", leaks},
                      {"double_hits", double_hits},
                      {"spawned", spawned},
                      {"self_hits", self_hits},
                      {"skipped_walls", skipped_walls},
                      {"t_samples", t_samples},
                      {"t_ulps_median", median_ulps()},
                      {"t_ulps_max", max_ulps},
                      {"t_rel_median", median_rel()},
                      {"t_rel_max", max_rel},
                      {"back_hits", back_hits},
                      {"back_false_misses", back_false_misses}};
  return j;
}

nlohmann::json Stats::histograms_json() const {
  auto sparse = [](const auto& h) {
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t i = 0; i < h.size(); ++i)
      if (h[i]) out.push_back({i, h[i]});
    return out;
  };
  return {{"t_ulps", sparse(ulp_hist)}, {"t_rel", sparse(rel_hist)}};
}

namespace {
// What a shard's stats can hold (unknown keys and counts no
// run can give, false_hits 1000 of 10 tests, were merged as given). The
// invariants are those book() keeps: each test counted under exactly one
// verdict, and every part no larger than its whole.
void check_merged_stats(const nlohmann::json& j, const nlohmann::json& h, const Stats& s) {
  static const std::set<std::string> stats_keys = {
      "tests",           "wrong",           "wrong_pct",         "true_hits",       "false_hits",
      "true_misses",     "false_misses",    "boundary_hits",     "boundary_misses", "coplanar_hits",
      "coplanar_misses", "degenerate_hits", "degenerate_misses", "nan_inf",         "wrong_t",
      "groups",          "leaks",           "double_hits",       "spawned",         "self_hits",
      "skipped_walls",   "t_samples",       "t_ulps_median",     "t_ulps_max",      "t_rel_median",
      "t_rel_max",       "back_hits",       "back_false_misses"};
  for (const auto& [key, value] : j.items())
    if (!stats_keys.count(key)) throw std::runtime_error("stats: '" + key + "': unknown key");
  for (const auto& [key, value] : h.items())
    if (key != "t_ulps" && key != "t_rel") throw std::runtime_error("histograms: '" + key + "': unknown key");
  const std::uint64_t verdicts = s.true_hits + s.false_hits + s.true_misses + s.false_misses + s.boundary_hits +
                                 s.boundary_misses + s.coplanar_hits + s.coplanar_misses + s.degenerate_hits +
                                 s.degenerate_misses;
  auto too_many = [&](const char* part, std::uint64_t n, const char* whole, std::uint64_t of) {
    if (n > of)
      throw std::runtime_error("stats: " + std::string(part) + " " + std::to_string(n) + " exceeds " + whole + " " +
                               std::to_string(of));
  };
  if (verdicts != s.tests)
    throw std::runtime_error("stats: the verdict counts add up to " + std::to_string(verdicts) + ", not tests " +
                             std::to_string(s.tests));
  too_many("nan_inf", s.nan_inf, "tests", s.tests);
  too_many("wrong_t", s.wrong_t, "true_hits + boundary_hits", s.true_hits + s.boundary_hits);
  too_many("t_samples", s.t_samples, "tests", s.tests);
  too_many("leaks", s.leaks, "groups", s.groups);
  too_many("double_hits", s.double_hits, "groups", s.groups);
  too_many("self_hits", s.self_hits, "spawned", s.spawned);
  too_many("skipped_walls", s.skipped_walls, "spawned - self_hits", s.spawned - s.self_hits);
  too_many("back_false_misses", s.back_false_misses, "back_hits", s.back_hits);
  too_many("back_hits", s.back_hits, "true_hits + false_misses", s.true_hits + s.false_misses);
  if (j.contains("wrong") && (!j["wrong"].is_number_unsigned() || j["wrong"].get<std::uint64_t>() != s.wrong()))
    throw std::runtime_error("stats: 'wrong' is not false_hits + false_misses + wrong_t (" + std::to_string(s.wrong()) +
                             ")");
}
}  // namespace

Stats Stats::from_json(const nlohmann::json& j, const nlohmann::json& h) {
  auto u = [&](const char* key) -> std::uint64_t {
    if (!j.is_object() || !j.contains(key) || !j[key].is_number_unsigned())
      throw std::runtime_error(std::string("stats: '") + key + "' is missing or not a count");
    return j[key].get<std::uint64_t>();
  };
  Stats s;
  s.tests = u("tests"), s.true_hits = u("true_hits"), s.false_hits = u("false_hits");
  s.true_misses = u("true_misses"), s.false_misses = u("false_misses");
  s.boundary_hits = u("boundary_hits"), s.boundary_misses = u("boundary_misses");
  s.coplanar_hits = u("coplanar_hits"), s.coplanar_misses = u("coplanar_misses");
  s.degenerate_hits = u("degenerate_hits"), s.degenerate_misses = u("degenerate_misses");
  s.nan_inf = u("nan_inf"), s.wrong_t = u("wrong_t");
  s.groups = u("groups"), s.leaks = u("leaks"), s.double_hits = u("double_hits");
  s.spawned = u("spawned"), s.self_hits = u("self_hits");
  s.t_samples = u("t_samples"), s.max_ulps = u("t_ulps_max");
  // Written since the one-sided hint; absent from older files.
  if (j.contains("back_hits")) s.back_hits = u("back_hits");
  if (j.contains("back_false_misses")) s.back_false_misses = u("back_false_misses");
  if (j.contains("skipped_walls")) s.skipped_walls = u("skipped_walls");  // since the refracted family
  if (!j.contains("t_rel_max") || !j["t_rel_max"].is_number())
    throw std::runtime_error("stats: 't_rel_max' is missing or not a number");
  s.max_rel = j["t_rel_max"].get<double>();
  auto read = [&](const char* key, auto& hist) {
    std::uint64_t sum = 0;
    if (!h.is_object() || !h.contains(key) || !h[key].is_array())
      throw std::runtime_error(std::string("histograms: '") + key + "' is missing (not a shard's output?)");
    for (const auto& e : h[key]) {
      if (!e.is_array() || e.size() != 2 || !e[0].is_number_unsigned() || !e[1].is_number_unsigned() ||
          e[0].get<std::uint64_t>() >= hist.size())
        throw std::runtime_error(std::string("histograms: '") + key + "' holds a bad [bin, count] pair");
      hist[e[0].get<std::size_t>()] += e[1].get<std::uint64_t>();
      sum += e[1].get<std::uint64_t>();
    }
    if (sum != s.t_samples)
      throw std::runtime_error(std::string("histograms: '") + key + "' does not add up to t_samples");
  };
  read("t_ulps", s.ulp_hist);
  read("t_rel", s.rel_hist);
  // Each maximum lies in the highest bin its histogram fills (0 without samples).
  auto top = [](const auto& hist) {
    int t = -1;
    for (int i = 0; i < int(hist.size()); ++i)
      if (hist[std::size_t(i)]) t = i;
    return t;
  };
  if (s.t_samples == 0 ? s.max_ulps != 0 : ulp_bin(s.max_ulps) != top(s.ulp_hist))
    throw std::runtime_error("stats: 't_ulps_max' " + std::to_string(s.max_ulps) +
                             " is not in the highest bin of the 't_ulps' histogram");
  if (s.t_samples == 0 ? s.max_rel != 0 : !(s.max_rel >= 0) || rel_bin(s.max_rel) != top(s.rel_hist))
    throw std::runtime_error("stats: 't_rel_max' is not in the highest bin of the 't_rel' histogram");
  check_merged_stats(j, h, s);
  return s;
}

// -------------------------------------------------------- evaluation ---
namespace {

template <class T>
bool finite_hit(const TriangleHit<T>& h) {
  return std::isfinite(h.t) && std::isfinite(h.b1) && std::isfinite(h.b2);
}
template <class T>
bool finite_hit(const SurfaceHit<T>& h) {
  return std::isfinite(h.t);
}

// Books one test: the exact answer against the subject's (hit, t).
template <class T>
void book(Stats& s, const oracle::Answer& a, bool hit, bool finite, T t) {
  using oracle::Verdict;
  ++s.tests;
  if (hit && !finite) ++s.nan_inf;
  switch (a.verdict) {
    case Verdict::hit:
      ++(hit ? s.true_hits : s.false_misses);
      break;
    case Verdict::miss:
      ++(hit ? s.false_hits : s.true_misses);
      break;
    case Verdict::boundary:
      ++(hit ? s.boundary_hits : s.boundary_misses);
      break;
    case Verdict::coplanar:
      ++(hit ? s.coplanar_hits : s.coplanar_misses);
      break;
    case Verdict::degenerate:
      ++(hit ? s.degenerate_hits : s.degenerate_misses);
      break;
  }
  if (!hit || !(a.verdict == Verdict::hit || a.verdict == Verdict::boundary)) return;
  // A hit at t = NaN or +-inf is off by more than any bound: wrong, and no
  // sample of the t error (it has no finite size).
  if (!std::isfinite(t)) {
    ++s.wrong_t;
    return;
  }
  const std::uint64_t ulps = ulp_distance<T>(t, T(a.t));
  const double rel = a.t != 0 ? std::abs(double(t) - a.t) / std::abs(a.t) : (t == 0 ? 0.0 : 1.0);
  ++s.t_samples;
  s.max_ulps = std::max(s.max_ulps, ulps);
  s.max_rel = std::max(s.max_rel, rel);
  ++s.ulp_hist[std::size_t(ulp_bin(ulps))];
  ++s.rel_hist[std::size_t(rel_bin(rel))];
  // The far root: the roots are told apart only when they differ in T.
  const bool far_root =
      std::isfinite(a.t_far) && T(a.t_far) != T(a.t) && std::abs(double(t) - a.t_far) < std::abs(double(t) - a.t);
  if (rel > kWrongTRelative || far_root) ++s.wrong_t;
}

template <class T>
Vec3<T> cv(const Vec3d& v) {
  return Vec3<T>(v);
}
template <class T>
Ray<T> cr(const Rayd& r) {
  return Ray<T>(r);
}

template <class T>
const TriangleFn<T>& fn(const TriangleSubject& s) {
  if constexpr (sizeof(T) == 4)
    return s.f32;
  else
    return s.f64;
}
template <class T>
const SphereFn<T>& fn(const SphereSubject& s) {
  if constexpr (sizeof(T) == 4)
    return s.f32;
  else
    return s.f64;
}

// The exact crossings of a group ahead of the origin (t > 0), counted as
// GroupHits counts a subject's: a crossing strictly inside a triangle is
// one of its own, and the crossings through a shared edge or vertex (a
// boundary answer, which every closed triangle there gives at one exact t)
// count once. Interior crossings are not merged by t: on a vertex fan that
// is not flat, a ray beside the shared vertex can cross two triangles at
// points whose t round to the same double. Merging them by rounded t made
// `exact` show 4 double hits in 1e8 rays of the vertex family, with every
// one of its verdicts equal to the oracle's.
int crossings(const oracle::Answer* a, int n) {
  int interior = 0;
  std::vector<double> boundary_t;
  for (int i = 0; i < n; ++i) {
    if (!(a[i].t > 0)) continue;  // NaN for misses
    if (a[i].verdict == oracle::Verdict::hit)
      ++interior;
    else if (a[i].verdict == oracle::Verdict::boundary)
      boundary_t.push_back(a[i].t);
  }
  std::sort(boundary_t.begin(), boundary_t.end());
  return interior + int(std::unique(boundary_t.begin(), boundary_t.end()) - boundary_t.begin());
}

// The hits of a group as crossings: hits on boundary cases at one exact t
// (a ray through a shared edge or vertex, which the closed triangles of the
// oracle's rule each contain) count once; any other hit counts itself. An
// exact intersector that answered both triangles of an edge it crossed
// exactly had 2,103 double hits and ranked below moller. A false hit (the
// oracle's miss) counts itself too: two hits where the ray crosses the
// group once are the double hit this catches.
struct GroupHits {
  int hits = 0, crossings_hit = 0;
  std::vector<double> boundary_t;
  void add(bool hit, const oracle::Answer& a) {
    if (!hit) return;
    ++hits;
    if (a.verdict == oracle::Verdict::boundary) {
      if (std::find(boundary_t.begin(), boundary_t.end(), a.t) != boundary_t.end()) return;
      boundary_t.push_back(a.t);
    }
    ++crossings_hit;
  }
};

// Books a group's verdicts once its members are booked: `g.hits` of `count`.
void book_group(Stats& st, int count, const GroupHits& g, int cross, bool proper) {
  if (count <= 1) return;
  const int hits = g.hits;
  if (cross > 0 && g.crossings_hit > cross) ++st.double_hits;
  // Leaks are judged on proper groups only (see group_is_proper), and
  // only for crossings ahead of the origin: an origin on the surface
  // (t = 0) is the secondary family's subject, and pbrt-style methods
  // reject t <= their error bound on purpose.
  if (proper) {
    ++st.groups;
    if (cross > 0 && hits == 0) ++st.leaks;
  }
}

// Books which side a hit case is met from (see Stats::back_hits).
void book_side(Stats& st, const oracle::Answer& a, bool hit, const Tri& t, const Rayd& r) {
  if (a.verdict != oracle::Verdict::hit || !(dot(cross(t.b - t.a, t.c - t.a), r.d) > 0)) return;
  ++st.back_hits;
  st.back_false_misses += !hit;
}

// Probe number `i` of a chunk in the family's sweep value: probes are
// numbered first, first + stride, ... (stride = the shard count when a
// chunk is dealt by probe).
struct ProbeNumbers {
  std::uint64_t first = 0, stride = 1;
  std::uint64_t operator()(std::size_t i) const { return first + stride * i; }
};

template <class T>
void eval_probes(const TriangleSubject& s, const TriangleBatch& b, const std::vector<oracle::Answer>& ans,
                 const std::vector<int>& cross, const std::vector<char>& proper, Stats& st, ProbeNumbers number) {
  const auto& f = fn<T>(s);
  std::size_t pair = 0;  // index into ans, see judge()
  for (std::size_t pi = 0; pi < b.probes.size(); ++pi) {
    const Probe& p = b.probes[pi];
    const Ray<T> r = cr<T>(p.ray);
    const std::uint64_t bad = st.bad();
    GroupHits g;
    for (int k = p.first; k < p.first + p.count; ++k, ++pair) {
      const Tri& t = b.tris[std::size_t(k)];
      const auto h = f(r, cv<T>(t.a), cv<T>(t.b), cv<T>(t.c));
      g.add(h.has_value(), ans[pair]);
      book<T>(st, ans[pair], h.has_value(), h && finite_hit(*h), h ? h->t : T(0));
      book_side(st, ans[pair], h.has_value(), t, p.ray);
    }
    book_group(st, p.count, g, cross[pi], proper[pi]);
    if (st.bad() != bad) st.note_example(number(pi));
  }
}

// Secondary rays from the subject's own hit point: a mirror reflection and a
// shadow ray back toward the primary ray's origin (a light at the camera).
template <class T>
void eval_secondary(const TriangleSubject& s, SelfIntersection strategy, const TriangleBatch& b, Stats& st,
                    ProbeNumbers number) {
  const auto& f = fn<T>(s);
  for (std::size_t pi = 0; pi < b.probes.size(); ++pi) {
    const Probe& p = b.probes[pi];
    const std::uint64_t bad = st.bad();
    struct Note {  // at every exit of this probe's body
      Stats& st;
      std::uint64_t bad, n;
      ~Note() {
        if (st.bad() != bad) st.note_example(n);
      }
    } note{st, bad, number(pi)};
    const Tri& tri = b.tris[std::size_t(p.first)];
    const Vec3<T> A = cv<T>(tri.a), B = cv<T>(tri.b), C = cv<T>(tri.c);
    const Ray<T> primary = cr<T>(p.ray);
    const auto h = f(primary, A, B, C);
    if (!h || !finite_hit(*h)) continue;
    const Vec3<T> P = A * (T(1) - h->b1 - h->b2) + B * h->b1 + C * h->b2;
    const Vec3<T> err = triangle_point_error(A, B, C, h->b1, h->b2);
    const Vec3<T> n = normalize(cross(B - A, C - A));
    const Vec3<T> d = normalize(primary.d);
    const Vec3<T> refl = normalize(d - n * (T(2) * dot(d, n)));
    const Vec3<T> to_light = primary.o - P;
    const T light_dist = length(to_light);
    const Ray<T> rays[2] = {spawn_ray(strategy, P, err, n, refl, false, T(0)),
                            spawn_ray(strategy, P, err, n, to_light / light_dist, true, light_dist)};
    for (const Ray<T>& r : rays) {
      const oracle::Answer a = oracle::triangle(Rayd(r), Vec3d(A), Vec3d(B), Vec3d(C));
      const auto h2 = f(r, A, B, C);
      ++st.spawned;
      st.self_hits += h2.has_value();
      book<T>(st, a, h2.has_value(), h2 && finite_hit(*h2), h2 ? h2->t : T(0));
    }
  }
}

// A refracted probe as every subject of precision T spawns it: the
// direction (Snell from air into glass, glass::refract as the renderer
// computes it, in double, rounded to T as spawn_ray takes it), the
// geometric normal handed to spawn_ray, and the answer the ray must find:
// the far wall, as the ray from the exact entry point in that direction
// first meets it. The same for every subject of T: only the spawned origin
// is the subject's (its hit point and the strategy).
template <class T>
struct Refraction {
  bool ok = false;
  Vec3d entry;           // the exact entry point, rounded to double
  Vec3<T> dir, n;        // n: outward
  double t_far = 0;      // exact t of the far wall along {entry, dir}
  std::vector<int> far;  // triangles met there (two or more at an edge or vertex)
  double split = 0;      // spheres: the chord's midpoint; the entry root is below it
};

template <class T>
bool refract_inward(const Vec3d& D, const Vec3d& outward, Refraction<T>& out) {
  const auto r = glass::refract(D, dot(D, outward) < 0 ? outward : -outward, 1.0 / kRefractedIor);
  if (!r) return false;
  out.dir = Vec3<T>(normalize(*r));
  out.n = Vec3<T>(outward);
  return dot(Vec3d(out.dir), outward) < 0;
}

bool crosses(const oracle::Answer& a) {
  return (a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) && a.t > 0;
}

// The far wall of the ray from out.entry along out.dir: the exact first
// crossing of triangles [first, first + count) other than the entry.
template <class T>
void find_far_wall(const Tri* tris, int first, int count, int entry, Refraction<T>& out) {
  const Rayd ideal{out.entry, Vec3d(out.dir)};
  for (int k = first; k < first + count; ++k) {
    if (k == entry) continue;
    const Tri& t = tris[std::size_t(k)];
    const oracle::Answer x = oracle::triangle(ideal, t.a, t.b, t.c);
    if (!crosses(x) || (!out.far.empty() && x.t > out.t_far)) continue;
    if (!out.far.empty() && x.t < out.t_far) out.far.clear();
    out.t_far = x.t;
    out.far.push_back(k);
  }
  out.ok = !out.far.empty();
}

template <class T>
Refraction<T> refraction(const TriangleBatch& b, const Probe& p) {
  Refraction<T> out;
  const Tri& e = b.tris[std::size_t(p.entry)];
  const oracle::Answer a = oracle::triangle(p.ray, e.a, e.b, e.c);
  if (a.verdict != oracle::Verdict::hit) return out;
  out.entry = p.ray.o + p.ray.d * a.t;
  if (!refract_inward(normalize(p.ray.d), normalize(cross(e.b - e.a, e.c - e.a)), out)) return out;
  find_far_wall(b.tris.data(), p.first, p.count, p.entry, out);
  return out;
}

template <class T>
Refraction<T> refraction(const SphereCase& c) {
  Refraction<T> out;
  const oracle::Answer a = oracle::sphere(c.ray, c.center, c.radius);
  if (a.verdict != oracle::Verdict::hit) return out;
  out.entry = c.ray.o + c.ray.d * a.t;
  if (!refract_inward(normalize(c.ray.d), normalize(out.entry - c.center), out)) return out;
  const Vec3d D(out.dir);
  out.split = -dot(D, out.entry - c.center) / dot(D, D);
  const oracle::Answer x =
      oracle::sphere(Rayd{out.entry, D, out.split, std::numeric_limits<double>::infinity()}, c.center, c.radius);
  out.ok = out.split > 0 && crosses(x);
  out.t_far = x.t;
  return out;
}

// Counts a refracted ray by where it went (the strategy's doing); its test
// is booked apart, against the exact answer for the ray as spawned (the
// method's doing), so a self-hit the exact ray also makes is not wrong.
void count_refracted(Stats& st, bool self_hit, bool reached) {
  ++st.spawned;
  st.self_hits += self_hit;
  st.skipped_walls += !self_hit && !reached;
}

// The nearest hit of spawned ray r over the mesh: the far wall (or a
// neighbour of it that r, moved off the exact entry point by the strategy,
// does cross: exactly judged), the entry triangle, or neither.
template <class T>
void grade_spawned(const TriangleFn<T>& f, const Tri* tris, int first, int count, int entry, const Refraction<T>& rf,
                   const Ray<T>& r, Stats& st) {
  int nearest = -1;
  T t = 0;
  for (int k = first; k < first + count; ++k) {
    const Tri& w = tris[std::size_t(k)];
    const auto h = f(r, cv<T>(w.a), cv<T>(w.b), cv<T>(w.c));
    if (h && finite_hit(*h) && (nearest < 0 || h->t < t)) nearest = k, t = h->t;
  }
  const Rayd exact(r);
  if (nearest >= 0) {
    const Tri& w = tris[std::size_t(nearest)];
    const oracle::Answer a = oracle::triangle(exact, w.a, w.b, w.c);
    const bool far = std::find(rf.far.begin(), rf.far.end(), nearest) != rf.far.end();
    count_refracted(st, nearest == entry, far || (nearest != entry && crosses(a)));
    book<T>(st, a, true, true, t);
    return;
  }
  // No hit: wrong if the ray as spawned does cross the far wall or the
  // entry triangle in its window (the triangles it can meet first).
  oracle::Answer a{};
  for (int k : rf.far) {
    const Tri& w = tris[std::size_t(k)];
    if (const oracle::Answer x = oracle::triangle(exact, w.a, w.b, w.c); crosses(x)) a = x;
  }
  if (!crosses(a)) {
    const Tri& w = tris[std::size_t(entry)];
    a = oracle::triangle(exact, w.a, w.b, w.c);
  }
  count_refracted(st, false, false);
  book<T>(st, a, false, false, T(0));
}

template <class T>
void grade_refracted_in(Stats& st, const TriangleSubject& s, const std::vector<Tri>& tris, int entry,
                        const Vec3d& entry_point, const Rayd& spawned) {
  Refraction<T> rf;
  rf.entry = entry_point;
  rf.dir = Vec3<T>(spawned.d);
  find_far_wall(tris.data(), 0, int(tris.size()), entry, rf);
  if (!rf.ok) throw std::invalid_argument("grade_refracted: the ray from the entry point meets no other triangle");
  grade_spawned<T>(fn<T>(s), tris.data(), 0, int(tris.size()), entry, rf, Ray<T>(spawned), st);
}

// Refracted rays from the subject's own hit on the entry triangle, spawned
// inward under the strategy, tested against the whole closed mesh: the
// nearest hit must be on the far wall.
template <class T>
void eval_refracted(const TriangleSubject& s, SelfIntersection strategy, const TriangleBatch& b,
                    const std::vector<Refraction<T>>& rfs, Stats& st, ProbeNumbers number) {
  const auto& f = fn<T>(s);
  for (std::size_t pi = 0; pi < b.probes.size(); ++pi) {
    const Probe& p = b.probes[pi];
    const Refraction<T>& rf = rfs[pi];
    if (!rf.ok) continue;
    const std::uint64_t bad = st.bad();
    const Tri& tri = b.tris[std::size_t(p.entry)];
    const Vec3<T> A = cv<T>(tri.a), B = cv<T>(tri.b), C = cv<T>(tri.c);
    const auto h = f(cr<T>(p.ray), A, B, C);
    if (!h || !finite_hit(*h)) continue;
    const Vec3<T> P = A * (T(1) - h->b1 - h->b2) + B * h->b1 + C * h->b2;
    const Ray<T> r = spawn_ray(strategy, P, triangle_point_error(A, B, C, h->b1, h->b2), rf.n, rf.dir, false, T(0));
    grade_spawned<T>(f, b.tris.data(), p.first, p.count, p.entry, rf, r, st);
    if (st.bad() != bad) st.note_example(number(pi));
  }
}

// Spheres: the refracted ray from the subject's own hit o + t d; its hit
// must be the far root (beyond the chord's midpoint along the exact ray).
template <class T>
void eval_refracted_spheres(const SphereSubject& s, SelfIntersection strategy, const std::vector<SphereCase>& cs,
                            const std::vector<Refraction<T>>& rfs, Stats& st, ProbeNumbers number) {
  const auto& f = fn<T>(s);
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const Refraction<T>& rf = rfs[i];
    if (!rf.ok) continue;
    const std::uint64_t bad = st.bad();
    const Ray<T> primary = cr<T>(cs[i].ray);
    const Vec3<T> C = cv<T>(cs[i].center);
    const T R = T(cs[i].radius);
    const auto h = f(primary, C, R);
    if (!h || !finite_hit(*h)) continue;
    // The renderer's point and bound for a sphere hit (render.cpp, surface
    // and point_error): normal-offset's bound holds for the point moved onto
    // the sphere, so that strategy spawns from there.
    const Vec3<T> at = primary.o + primary.d * h->t;
    const Vec3<T> P = strategy == SelfIntersection::normal_offset ? reproject_onto_sphere(at, C, R) : at;
    const Vec3<T> err = sphere_point_error(Vec3<T>(P - C)) + abs(C) * ra::detail::gamma<T>(1);
    const Ray<T> r = spawn_ray(strategy, P, err, rf.n, rf.dir, false, T(0));
    const auto h2 = f(r, C, R);
    const bool hit = h2 && finite_hit(*h2);
    // Where the hit is along the exact ray: before the midpoint is the entry side.
    const Vec3d D(rf.dir);
    const double along = hit ? double(h2->t) + dot(Vec3d(r.o) - rf.entry, D) / dot(D, D) : 0;
    const bool self_hit = hit && along < rf.split;
    count_refracted(st, self_hit, hit && !self_hit);
    book<T>(st, oracle::sphere(Rayd(r), cs[i].center, cs[i].radius), h2.has_value(), hit, h2 ? h2->t : T(0));
    if (st.bad() != bad) st.note_example(number(i));
  }
}

template <class T>
void eval_spheres(const SphereSubject& s, const std::vector<SphereCase>& cs, const std::vector<oracle::Answer>& ans,
                  Stats& st, ProbeNumbers number) {
  const auto& f = fn<T>(s);
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const std::uint64_t bad = st.bad();
    const auto h = f(cr<T>(cs[i].ray), cv<T>(cs[i].center), T(cs[i].radius));
    book<T>(st, ans[i], h.has_value(), h && finite_hit(*h), h ? h->t : T(0));
    if (st.bad() != bad) st.note_example(number(i));
  }
}

constexpr int kChunk = 256;  // probes per chunk: fixed, so cases never depend on threads or shards

// The work of a run without a task list (which grew with --rays): per
// (family, sweep value) its chunk count, and the first global task number of
// it, so a task number maps to (family, sweep, chunk) by a binary search in
// a table of one row per sweep value.
struct SweepPlan {
  const Family* family;
  std::size_t fam_index;
  int sweep;
  long long probes;          // of the unsharded run
  std::uint64_t first_task;  // tasks of earlier sweep values (this shard's)
  std::uint64_t tasks;       // this shard's chunks of this sweep value
  std::uint64_t per_probe;   // tests per probe, as --rays counts them
  // Sharded, a sweep value of fewer than 4 n chunks is split by probe (every
  // shard generates each chunk and keeps probes j with j % n == k - 1), so
  // small runs split evenly too; larger ones are dealt whole chunks, so no
  // shard generates what it does not judge.
  bool by_probe;
};

struct Chunk {
  const SweepPlan* sweep;
  std::uint64_t index;  // chunk number within the sweep value
  int count;            // probes in it
};

// This shard's probes of a sweep value dealt by probe: j < probes, j % n == k - 1.
std::uint64_t dealt(std::uint64_t probes, Shard s) {
  return probes > s.k - 1 ? (probes - (s.k - 1) + s.n - 1) / s.n : 0;
}

struct Plan {
  std::vector<SweepPlan> sweeps;
  std::uint64_t tasks = 0, tests = 0;
  Shard shard;

  Chunk chunk(std::uint64_t task) const {
    auto it = std::upper_bound(sweeps.begin(), sweeps.end(), task,
                               [](std::uint64_t t, const SweepPlan& s) { return t < s.first_task; });
    const SweepPlan& sp = *(it - 1);
    const std::uint64_t c = sp.by_probe ? task - sp.first_task : (task - sp.first_task) * shard.n + (shard.k - 1);
    return {&sp, c, int(std::min<long long>(kChunk, sp.probes - (long long)c * kChunk))};
  }
};

// The probes of chunk c (global index c * kChunk + i) dealt to this shard.
template <class V>
V keep_dealt(const V& all, std::uint64_t c, Shard s) {
  V out;
  for (std::size_t i = 0; i < all.size(); ++i)
    if ((c * kChunk + i) % s.n == s.k - 1) out.push_back(all[i]);
  return out;
}
std::uint64_t dealt_in_chunk(const Chunk& ch, Shard s) {
  const std::uint64_t first = ch.index * kChunk;
  return dealt(first + std::uint64_t(ch.count), s) - dealt(first, s);
}

Plan plan(const std::vector<const Family*>& fams, long long rays, Shard shard) {
  Plan pl;
  pl.shard = shard;
  for (std::size_t fi = 0; fi < fams.size(); ++fi) {
    const Family& f = *fams[fi];
    for (int s = 0; s < int(f.sweep.size()); ++s) {
      SweepPlan sp{&f, fi, s, probes_per_sweep(f, s, rays), pl.tasks, 0, std::uint64_t(f.tests_per_probe(s)), false};
      const auto chunks = std::uint64_t((sp.probes + kChunk - 1) / kChunk);
      sp.by_probe = shard.n > 1 && chunks < 4 * shard.n;
      std::uint64_t probes;
      if (sp.by_probe) {
        probes = dealt(std::uint64_t(sp.probes), shard);
        sp.tasks = probes ? chunks : 0;
      } else {
        sp.tasks = dealt(chunks, shard);
        // This shard's probes: whole chunks, less what the last chunk lacks if it is ours.
        probes = sp.tasks * kChunk;
        if (sp.tasks && (chunks - 1) % shard.n == shard.k - 1) probes -= chunks * kChunk - std::uint64_t(sp.probes);
      }
      if (sp.tasks == 0) continue;
      pl.tests += probes * sp.per_probe;
      pl.tasks += sp.tasks;
      pl.sweeps.push_back(sp);
    }
  }
  return pl;
}

// Exact answers per (probe, triangle) pair, probe after probe: probes may
// share triangles (a closed mesh), so answers are indexed by pair, not triangle.
std::vector<oracle::Answer> judge(const TriangleBatch& b) {
  std::vector<oracle::Answer> ans;
  for (const Probe& p : b.probes)
    for (int k = p.first; k < p.first + p.count; ++k) {
      const Tri& t = b.tris[std::size_t(k)];
      ans.push_back(oracle::triangle(p.ray, t.a, t.b, t.c));
    }
  return ans;
}

}  // namespace

void grade_refracted(Stats& st, const TriangleSubject& s, const std::vector<Tri>& tris, int entry,
                     const Vec3d& entry_point, const Rayd& spawned) {
  if (entry < 0 || entry >= int(tris.size())) throw std::invalid_argument("grade_refracted: no such entry triangle");
  s.precision == Precision::f32 ? grade_refracted_in<float>(st, s, tris, entry, entry_point, spawned)
                                : grade_refracted_in<double>(st, s, tris, entry, entry_point, spawned);
}

void grade_probe(Stats& st, Precision p, const Rayd& ray, const Tri* tris, const GivenAnswer* given, int count,
                 bool closed) {
  // Float answers are judged on the inputs rounded to float, as the audit's
  // own float cases are (a no-op for cases exported in float).
  const bool f32 = p == Precision::f32;
  auto in_p = [f32](const Vec3d& v) { return f32 ? Vec3d(Vec3f(v)) : v; };
  Rayd r = ray;
  if (f32) r = Rayd(Rayf(ray));
  std::vector<Tri> in(tris, tris + count);
  for (Tri& t : in) t = {in_p(t.a), in_p(t.b), in_p(t.c)};
  std::vector<oracle::Answer> ans;
  ans.reserve(std::size_t(count));
  for (int k = 0; k < count; ++k)
    ans.push_back(oracle::triangle(r, in[std::size_t(k)].a, in[std::size_t(k)].b, in[std::size_t(k)].c));
  GroupHits group;
  for (int k = 0; k < count; ++k) {
    const GivenAnswer& g = given[k];
    group.add(g.hit, ans[std::size_t(k)]);
    book_side(st, ans[std::size_t(k)], g.hit, in[std::size_t(k)], r);
    if (p == Precision::f32)
      book<float>(st, ans[std::size_t(k)], g.hit, finite_hit(TriangleHit<float>{float(g.t), float(g.u), float(g.v)}),
                  float(g.t));
    else
      book<double>(st, ans[std::size_t(k)], g.hit, finite_hit(TriangleHit<double>{g.t, g.u, g.v}), g.t);
  }
  const bool proper = closed || (count > 1 && group_is_proper(in.data(), count, r.d));
  book_group(st, count, group, count > 1 ? crossings(ans.data(), count) : 0, proper);
}

long long probes_per_sweep(const Family& f, int sweep, long long rays) {
  const long long per = rays / (long long)f.sweep.size() / f.tests_per_probe(sweep);
  return std::max(1LL, per);
}

void for_each_probe_case(const Family& f, int sweep, Precision p, std::uint64_t seed, long long rays,
                         const std::function<void(const ProbeCase&)>& visit) {
  const long long n = probes_per_sweep(f, sweep, rays);
  for (long long c = 0; c * kChunk < n; ++c) {
    TriangleBatch b;
    generate(f, sweep, p, stream_seed(seed, f.name, sweep, std::uint64_t(c)),
             int(std::min<long long>(kChunk, n - c * kChunk)), b);
    for (const Probe& pr : b.probes) {
      ProbeCase pc{pr.ray, {}, {}};
      for (int k = pr.first; k < pr.first + pr.count; ++k) {
        const Tri& t = b.tris[std::size_t(k)];
        pc.tris.push_back(t);
        pc.answers.push_back(oracle::triangle(pr.ray, t.a, t.b, t.c));
      }
      visit(pc);
    }
  }
}

std::vector<ProbeCase> probe_cases(const Family& f, int sweep, Precision p, std::uint64_t seed, long long rays) {
  std::vector<ProbeCase> out;
  for_each_probe_case(f, sweep, p, seed, rays, [&](const ProbeCase& pc) { out.push_back(pc); });
  return out;
}

std::vector<SphereCase> sphere_cases(const Family& f, int sweep, Precision p, std::uint64_t seed, long long rays) {
  std::vector<SphereCase> out;
  const long long n = probes_per_sweep(f, sweep, rays);
  for (long long c = 0; c * kChunk < n; ++c)
    generate(f, sweep, p, stream_seed(seed, f.name, sweep, std::uint64_t(c)),
             int(std::min<long long>(kChunk, n - c * kChunk)), out);
  return out;
}

Report run(const std::vector<TriangleSubject>& tris, const std::vector<SphereSubject>& spheres, const Options& opt) {
  // The CLI checks these with its own messages; the library's users (the
  // GoogleTest checks) get the same refusals.
  for (const std::string& name : opt.families) {
    const auto named = families_named(name);
    if (named.empty()) throw std::invalid_argument("audit: unknown family '" + name + "' (" + family_names() + ")");
    // A name of both kinds (refracted) grades whichever subjects are given.
    const bool graded = std::any_of(named.begin(), named.end(), [&](const Family* f) {
      return f->kind == Kind::triangle ? !tris.empty() : !spheres.empty();
    });
    if (!graded)
      throw std::invalid_argument("audit: family '" + name + "' grades " +
                                  (named[0]->kind == Kind::triangle ? "triangles" : "spheres") +
                                  ", and no such subject is given");
  }
  if (opt.rays < 1 || opt.rays > 10000000000LL)
    throw std::invalid_argument("audit: rays must be 1 to 1e10 per family, got " + std::to_string(opt.rays));
  if (opt.threads < 0)
    throw std::invalid_argument("audit: threads must be 0 (all) or more, got " + std::to_string(opt.threads));
  Report rep;
  rep.seed = opt.seed;
  rep.rays = opt.rays;
  for (const auto& s : tris)
    rep.subjects.push_back(s.name()), rep.kinds.push_back("triangle"), rep.peers.push_back(s.peer);
  for (const auto& s : spheres)
    rep.subjects.push_back(s.name()), rep.kinds.push_back("sphere"), rep.peers.emplace_back();

  std::vector<const Family*> fams;
  for (const Family& f : families()) {
    const bool wanted =
        opt.families.empty() || std::find(opt.families.begin(), opt.families.end(), f.name) != opt.families.end();
    const bool has_subjects = f.kind == Kind::triangle ? !tris.empty() : !spheres.empty();
    if (wanted && has_subjects) fams.push_back(&f);
  }
  // Cells: subject-major; index of (subject, family, sweep) computed below.
  std::vector<std::size_t> fam_base;  // first cell offset of each family within a subject
  std::size_t per_subject_tri = 0, per_subject_sph = 0;
  for (const Family* f : fams) {
    std::size_t& n = f->kind == Kind::triangle ? per_subject_tri : per_subject_sph;
    fam_base.push_back(n);
    n += f->sweep.size();
  }
  auto cell_index = [&](std::size_t subject, std::size_t fam, int sweep) {
    if (subject < tris.size()) return subject * per_subject_tri + fam_base[fam] + std::size_t(sweep);
    return tris.size() * per_subject_tri + (subject - tris.size()) * per_subject_sph + fam_base[fam] +
           std::size_t(sweep);
  };
  rep.cells.resize(tris.size() * per_subject_tri + spheres.size() * per_subject_sph);
  for (std::size_t s = 0; s < rep.subjects.size(); ++s)
    for (std::size_t fi = 0; fi < fams.size(); ++fi) {
      const bool tri_family = fams[fi]->kind == Kind::triangle;
      if (tri_family != (s < tris.size())) continue;
      for (int w = 0; w < int(fams[fi]->sweep.size()); ++w)
        rep.cells[cell_index(s, fi, w)] = {s, fams[fi]->name, w, fams[fi]->sweep[std::size_t(w)], {}, {}};
    }

  const Shard shard = opt.shard.value_or(Shard{});
  if (shard.n < 1 || shard.k < 1 || shard.k > shard.n)
    throw std::invalid_argument("audit: shard " + std::to_string(shard.k) + "/" + std::to_string(shard.n) +
                                " is not k/n with 1 <= k <= n");
  rep.shard = opt.shard;
  const Plan pl = plan(fams, opt.rays, shard);
  std::atomic<std::uint64_t> next{0};
  std::uint64_t done = 0;  // tests, under mu
  std::mutex mu;
  auto worker = [&] {
    for (;;) {
      const std::uint64_t ti = next++;
      if (ti >= pl.tasks) return;
      const Chunk ch = pl.chunk(ti);
      struct {
        const Family* family;
        int sweep, count;
      } const t{ch.sweep->family, ch.sweep->sweep, ch.count};
      const std::size_t fi = ch.sweep->fam_index;
      const std::uint64_t stream = stream_seed(opt.seed, t.family->name, t.sweep, ch.index);
      // The probes' numbers in the sweep value (keep_dealt keeps j % n == k - 1).
      ProbeNumbers number{ch.index * kChunk, 1};
      if (ch.sweep->by_probe) {
        number.stride = shard.n;
        number.first += (shard.k - 1 + shard.n - number.first % shard.n) % shard.n;
      }
      std::vector<std::pair<std::size_t, Stats>> results;
      for (Precision p : {Precision::f32, Precision::f64}) {
        if (t.family->kind == Kind::triangle) {
          bool any = false;
          for (const auto& s : tris) any |= s.precision == p;
          if (!any) continue;
          TriangleBatch b;
          generate(*t.family, t.sweep, p, stream, t.count, b);
          if (ch.sweep->by_probe) b.probes = keep_dealt(b.probes, ch.index, shard);
          std::vector<oracle::Answer> ans;
          std::vector<int> cross;
          std::vector<char> proper;
          std::vector<Refraction<float>> rf32;
          std::vector<Refraction<double>> rf64;
          if (t.family->refracted)
            for (const Probe& pr : b.probes)
              p == Precision::f32 ? rf32.push_back(refraction<float>(b, pr))
                                  : rf64.push_back(refraction<double>(b, pr));
          if (!t.family->secondary) {
            ans = judge(b);
            std::size_t pair = 0;
            for (const Probe& pr : b.probes) {
              cross.push_back(crossings(&ans[pair], pr.count));
              proper.push_back(pr.closed ||
                               (pr.count > 1 && group_is_proper(&b.tris[std::size_t(pr.first)], pr.count, pr.ray.d)));
              pair += std::size_t(pr.count);
            }
          }
          for (std::size_t si = 0; si < tris.size(); ++si) {
            if (tris[si].precision != p) continue;
            Stats st;
            const auto strategy = SelfIntersection(secondary_strategy(t.sweep));
            if (t.family->refracted) {
              p == Precision::f32 ? eval_refracted<float>(tris[si], strategy, b, rf32, st, number)
                                  : eval_refracted<double>(tris[si], strategy, b, rf64, st, number);
            } else if (t.family->secondary) {
              p == Precision::f32 ? eval_secondary<float>(tris[si], strategy, b, st, number)
                                  : eval_secondary<double>(tris[si], strategy, b, st, number);
            } else {
              p == Precision::f32 ? eval_probes<float>(tris[si], b, ans, cross, proper, st, number)
                                  : eval_probes<double>(tris[si], b, ans, cross, proper, st, number);
            }
            results.emplace_back(cell_index(si, fi, t.sweep), st);
          }
        } else {
          bool any = false;
          for (const auto& s : spheres) any |= s.precision == p;
          if (!any) continue;
          std::vector<SphereCase> cs;
          generate(*t.family, t.sweep, p, stream, t.count, cs);
          if (ch.sweep->by_probe) cs = keep_dealt(cs, ch.index, shard);
          std::vector<oracle::Answer> ans;
          std::vector<Refraction<float>> rf32;
          std::vector<Refraction<double>> rf64;
          for (const auto& c : cs)
            if (!t.family->refracted)
              ans.push_back(oracle::sphere(c.ray, c.center, c.radius));
            else
              p == Precision::f32 ? rf32.push_back(refraction<float>(c)) : rf64.push_back(refraction<double>(c));
          for (std::size_t si = 0; si < spheres.size(); ++si) {
            if (spheres[si].precision != p) continue;
            Stats st;
            const auto strategy = SelfIntersection(secondary_strategy(t.sweep));
            if (t.family->refracted)
              p == Precision::f32 ? eval_refracted_spheres<float>(spheres[si], strategy, cs, rf32, st, number)
                                  : eval_refracted_spheres<double>(spheres[si], strategy, cs, rf64, st, number);
            else
              p == Precision::f32 ? eval_spheres<float>(spheres[si], cs, ans, st, number)
                                  : eval_spheres<double>(spheres[si], cs, ans, st, number);
            results.emplace_back(cell_index(tris.size() + si, fi, t.sweep), st);
          }
        }
      }
      std::lock_guard<std::mutex> lock(mu);
      for (auto& [ci, st] : results) rep.cells[ci].stats.merge(st);
      const std::uint64_t judged = ch.sweep->by_probe ? dealt_in_chunk(ch, shard) : std::uint64_t(t.count);
      done += judged * ch.sweep->per_probe;
      if (opt.progress) opt.progress(done, pl.tests);
    }
  };
  const int n = opt.threads > 0 ? opt.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  ra::run_workers(n, worker);  // fewer threads if the system refuses some
  return rep;
}

// ------------------------------------------------------------ report ---
Stats Report::total(std::size_t subject) const {
  Stats s;
  for (const Cell& c : cells)
    if (c.subject == subject) s.merge(c.stats);
  return s;
}

const Cell* Report::worst(std::size_t subject) const {
  const Cell* w = nullptr;
  for (const Cell& c : cells)
    if (c.subject == subject && c.stats.badness() > 0 && (!w || c.stats.badness() > w->stats.badness())) w = &c;
  return w;
}

nlohmann::json Report::to_json() const {
  nlohmann::json subs = nlohmann::json::array(), cs = nlohmann::json::array();
  for (std::size_t i = 0; i < subjects.size(); ++i) {
    const Cell* w = worst(i);
    const auto slash = subjects[i].rfind('/');
    subs.push_back(
        {{"name", subjects[i]},
         {"method", subjects[i].substr(0, slash)},
         {"precision", subjects[i].substr(slash + 1)},
         {"kind", kinds[i]},
         {"peer", peer(i) != nullptr},
         {"totals", total(i).to_json()},
         {"worst", w ? nlohmann::json{{"family", w->family}, {"sweep", w->sweep_label}, {"badness", w->stats.badness()}}
                     : nlohmann::json(nullptr)}});
    if (const PeerInfo* p = peer(i)) subs.back()["what"] = p->what, subs.back()["speed_source"] = p->speed_source;
  }
  for (const Cell& c : cells) {
    const Family* f = find_family(c.family);
    cs.push_back({{"subject", subjects[c.subject]},
                  {"family", c.family},
                  {"param", f ? f->param : ""},
                  {"sweep", c.sweep_label},
                  {"stats", c.stats.to_json()}});
    if (!c.example_ids.empty()) {
      cs.back()["examples"] = c.example_ids;
    } else if (!c.stats.examples.empty()) {
      nlohmann::json ids = nlohmann::json::array();
      for (std::uint64_t e : c.stats.examples) ids.push_back(c.family + ":" + c.sweep_label + ":" + std::to_string(e));
      cs.back()["examples"] = ids;
    }
    if (shard) cs.back()["histograms"] = c.stats.histograms_json();
  }
  nlohmann::json out = {
      {"seed", seed},
      {"version", RAYAUDIT_VERSION},
      {"rays_per_family", rays},
      {"semantics",
       "ray = {o + t d : max(tmin,0) <= t <= tmax}; closed triangle; inputs exact as given "
       "(float cases rounded to float before method and oracle); wrong = false hits + false "
       "misses + hits with relative t error > 1e-2, t NaN or infinite, or (spheres) nearer the far root than "
       "the near one, t judged on hit and boundary cases; hitting or missing a boundary/coplanar/degenerate "
       "case is counted apart, never wrong"},
      {"subjects", subs},
      {"cells", cs}};
  if (shard) out["shard"] = {{"k", shard->k}, {"n", shard->n}};
  return out;
}

Report Report::from_json(const nlohmann::json& j) {
  auto need = [&](const nlohmann::json& o, const char* key) -> const nlohmann::json& {
    if (!o.is_object() || !o.contains(key)) throw std::runtime_error(std::string("no '") + key + "' key");
    return o[key];
  };
  Report r;
  const auto& seed = need(j, "seed");
  const auto& rays = need(j, "rays_per_family");
  if (!seed.is_number_unsigned() || !rays.is_number_integer())
    throw std::runtime_error("'seed' and 'rays_per_family' must be integers");
  r.seed = seed.get<std::uint64_t>();
  r.rays = rays.get<long long>();
  if (j.contains("shard")) {
    const auto& sh = j["shard"];
    if (!need(sh, "k").is_number_unsigned() || !need(sh, "n").is_number_unsigned())
      throw std::runtime_error("'shard' must hold counts k and n");
    r.shard = Shard{sh["k"].get<std::uint64_t>(), sh["n"].get<std::uint64_t>()};
  }
  for (const auto& s : need(j, "subjects")) {
    if (!need(s, "name").is_string() || !need(s, "kind").is_string())
      throw std::runtime_error("a subject without a name or kind");
    r.subjects.push_back(s["name"].get<std::string>());
    r.kinds.push_back(s["kind"].get<std::string>());
    if (s.contains("peer") && !s["peer"].is_boolean()) throw std::runtime_error("a subject's 'peer' is not true/false");
    r.peers.emplace_back();
    if (s.value("peer", false)) r.peers.back() = PeerInfo{s.value("what", ""), s.value("speed_source", "")};
  }
  for (const auto& c : need(j, "cells")) {
    if (!need(c, "subject").is_string() || !need(c, "family").is_string() || !need(c, "sweep").is_string())
      throw std::runtime_error("a cell without subject, family or sweep");
    const auto it = std::find(r.subjects.begin(), r.subjects.end(), c["subject"].get<std::string>());
    if (it == r.subjects.end()) throw std::runtime_error("a cell of an unknown subject");
    Cell cell;
    cell.subject = std::size_t(it - r.subjects.begin());
    cell.family = c["family"].get<std::string>();
    cell.sweep_label = c["sweep"].get<std::string>();
    cell.sweep = 0;
    if (const Family* f = find_family(cell.family)) {
      const auto w = std::find(f->sweep.begin(), f->sweep.end(), cell.sweep_label);
      cell.sweep = int(w - f->sweep.begin());
    }
    try {
      cell.stats = Stats::from_json(need(c, "stats"), c.contains("histograms") ? c["histograms"] : nlohmann::json());
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("cells[" + std::to_string(r.cells.size()) + "]." + e.what());
    }
    // Failing case ids: FAMILY:SWEEP:PROBE back to probe numbers (so shards
    // merge them), any other id kept as written.
    if (c.contains("examples")) {
      if (!c["examples"].is_array())
        throw std::runtime_error("cells[" + std::to_string(r.cells.size()) + "].examples: not an array");
      const std::string prefix = cell.family + ":" + cell.sweep_label + ":";
      for (const auto& e : c["examples"]) {
        if (!e.is_string())
          throw std::runtime_error("cells[" + std::to_string(r.cells.size()) + "].examples: not strings");
        const std::string id = e.get<std::string>();
        const std::string n = id.rfind(prefix, 0) == 0 ? id.substr(prefix.size()) : "";
        if (!n.empty() && n.size() < 20 && n.find_first_not_of("0123456789") == std::string::npos)
          cell.stats.note_example(std::stoull(n));
        else if (cell.example_ids.size() < Stats::kExamples)
          cell.example_ids.push_back(id);
      }
    }
    r.cells.push_back(std::move(cell));
  }
  return r;
}

namespace {
std::string fmt(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char* f, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}
std::string count(std::uint64_t v) { return v ? std::to_string(v) : "-"; }
}  // namespace

std::string Report::summary_table() const {
  std::string out =
      fmt("%-24s %10s %8s %8s %8s %7s %7s %7s %5s %7s %12s  %s\n", "METHOD/PRECISION", "TESTS", "WRONG%", "F.HITS",
          "F.MISS", "BAD-T", "LEAKS", "DOUBLE", "NaN", "SELF%", "T-ULPS md/max", "WORST (family@sweep: bad%)");
  for (std::size_t i = 0; i < subjects.size(); ++i) {
    const Stats s = total(i);
    const Cell* w = worst(i);
    std::string ulps = s.t_samples ? fmt("%llu/%s", (unsigned long long)s.median_ulps(),
                                         s.max_ulps > 99999999 ? fmt("%.1e", double(s.max_ulps)).c_str()
                                                               : std::to_string(s.max_ulps).c_str())
                                   : "-";
    out += fmt(
        "%-24s %10llu %8.4f %8s %8s %7s %7s %7s %5s %7s %12s  %s\n", subjects[i].c_str(), (unsigned long long)s.tests,
        s.tests ? 100.0 * double(s.wrong()) / double(s.tests) : 0.0, count(s.false_hits).c_str(),
        count(s.false_misses).c_str(), count(s.wrong_t).c_str(), count(s.leaks).c_str(), count(s.double_hits).c_str(),
        count(s.nan_inf).c_str(),
        s.spawned ? fmt("%.2f", 100.0 * double(s.self_hits) / double(s.spawned)).c_str() : "-", ulps.c_str(),
        w ? fmt("%s@%s: %.3g%%", w->family.c_str(), w->sweep_label.c_str(), 100 * w->stats.badness()).c_str() : "none");
  }
  out +=
      "WRONG% = (false hits + false misses + BAD-T) / tests; BAD-T = a hit on a hit or boundary case with t off by > "
      "1%, "
      "NaN or infinite, or nearer a sphere's far root;\n"
      "LEAKS = edge/vertex/mesh rays the exact answer hits and the method misses entirely; "
      "DOUBLE = more hits than exact crossings; SELF% = spawned secondary rays re-hitting their triangle;\n"
      "hitting or missing a boundary/coplanar/degenerate case is never counted wrong (its counts are in the JSON).\n";
  for (std::size_t i = 0; i < subjects.size(); ++i)
    if (const PeerInfo* p = peer(i))
      out += "peer " + subjects[i] + ": " + p->what + "; speed figure: " + p->speed_source + "\n";
  return out + refracted_table();
}

std::string Report::refracted_table() const {
  // (kind, precision, strategy) rows in the order met, scale columns.
  struct Row {
    std::string kind, precision, strategy;
    std::vector<std::pair<std::string, Stats>> scales;
  };
  std::vector<Row> rows;
  for (const Cell& c : cells) {
    const Family* f = find_family(c.family);
    if (!f || !f->refracted) continue;
    const auto at = c.sweep_label.find('@');
    const std::string& n = subjects[c.subject];
    const std::string kind = c.subject < kinds.size() ? kinds[c.subject] : "", prec = n.substr(n.rfind('/') + 1);
    const std::string strategy = c.sweep_label.substr(0, at),
                      scale = at == std::string::npos ? "" : c.sweep_label.substr(at + 1);
    auto row = std::find_if(rows.begin(), rows.end(), [&](const Row& r) {
      return r.kind == kind && r.precision == prec && r.strategy == strategy;
    });
    if (row == rows.end()) row = rows.insert(rows.end(), Row{kind, prec, strategy, {}});
    auto col = std::find_if(row->scales.begin(), row->scales.end(), [&](const auto& e) { return e.first == scale; });
    if (col == row->scales.end()) col = row->scales.insert(row->scales.end(), {scale, Stats{}});
    col->second.merge(c.stats);
  }
  if (rows.empty()) return "";
  std::string out =
      "\nrefracted rays (spawned into the solid from each method's own entry hit), summed over the methods of a kind "
      "and precision\n(a method's own failures add to every strategy: per method in the JSON and the report):\n"
      "SELF% / SKIP% of spawned rays per strategy and scale (SELF: nearest hit on the entry surface; SKIP: the far "
      "wall missed or passed)\n";
  out += fmt("%-9s %-7s %-14s", "KIND", "PREC", "STRATEGY");
  for (const auto& [scale, st] : rows[0].scales) out += fmt(" %15s", ("@" + scale).c_str());
  out += fmt(" %9s\n", "SPAWNED");
  for (const Row& r : rows) {
    out += fmt("%-9s %-7s %-14s", r.kind.c_str(), r.precision.c_str(), r.strategy.c_str());
    std::uint64_t spawned = 0;
    for (const auto& scale_stats : r.scales) {
      // Not a structured binding: clang (the fuzz build) does not let a
      // lambda capture one.
      const auto& st = scale_stats.second;
      spawned += st.spawned;
      auto pct = [&](std::uint64_t v) {
        return st.spawned ? fmt("%.2f", 100.0 * double(v) / double(st.spawned)) : "-";
      };
      out += fmt(" %15s", (pct(st.self_hits) + " / " + pct(st.skipped_walls)).c_str());
    }
    out += fmt(" %9llu\n", (unsigned long long)spawned);
  }
  return out;
}

namespace {
// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line
// end: a subject is named after the answers file, which may hold any.
std::string csv_field(const std::string& f) {
  if (f.find_first_of(",\"\r\n") == std::string::npos) return f;
  std::string q = "\"";
  for (char ch : f) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + '"';
}
}  // namespace

std::string Report::to_csv() const {
  std::ostringstream os;
  os << "method,precision,family,sweep,tests,wrong,true_hits,false_hits,true_misses,false_misses,wrong_t,boundary_hits,"
        "boundary_misses,coplanar_hits,coplanar_misses,degenerate_hits,degenerate_misses,nan_inf,"
        "groups,leaks,double_hits,spawned,self_hits,t_ulps_median,t_ulps_max,t_rel_median,t_rel_max,peer\n";
  for (const Cell& c : cells) {
    const Stats& s = c.stats;
    const std::string& n = subjects[c.subject];
    const auto slash = n.rfind('/');
    os << csv_field(n.substr(0, slash)) << ',' << csv_field(n.substr(slash + 1)) << ',' << csv_field(c.family) << ','
       << csv_field(c.sweep_label) << ',' << s.tests << ',' << s.wrong() << ',' << s.true_hits << ',' << s.false_hits
       << ',' << s.true_misses << ',' << s.false_misses << ',' << s.wrong_t << ',' << s.boundary_hits << ','
       << s.boundary_misses << ',' << s.coplanar_hits << ',' << s.coplanar_misses << ',' << s.degenerate_hits << ','
       << s.degenerate_misses << ',' << s.nan_inf << ',' << s.groups << ',' << s.leaks << ',' << s.double_hits << ','
       << s.spawned << ',' << s.self_hits << ',' << s.median_ulps() << ',' << s.max_ulps << ','
       << fmt("%.6g", s.median_rel()) << ',' << fmt("%.6g", s.max_rel) << ',' << (peer(c.subject) ? 1 : 0) << '\n';
  }
  return os.str();
}

}  // namespace ra::audit
