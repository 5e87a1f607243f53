// The audit engine and its C++ API: grades intersectors (the registry's or a
// user's own callable) against the exact oracle over the case families.
//
// Use from your own code (link rayaudit::validation):
//   auto s = ra::audit::triangle_subject<float>("mine", [](const ra::Rayf& r,
//       const ra::Vec3f& a, const ra::Vec3f& b, const ra::Vec3f& c)
//       -> std::optional<ra::TriangleHit<float>> { ... });
//   ra::audit::Report rep = ra::audit::run({s}, {}, {});
//   rep.total(0).leaks, rep.summary_table(), rep.to_json() ...
// GoogleTest assertions over it are in audit_gtest.h.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "families.h"
#include <rayaudit/hit.h>
#include "oracle.h"
#include <rayaudit/registry.h>

namespace ra::audit {

template <class T>
using TriangleFn =
    std::function<std::optional<TriangleHit<T>>(const Ray<T>&, const Vec3<T>&, const Vec3<T>&, const Vec3<T>&)>;
template <class T>
using SphereFn = std::function<std::optional<SurfaceHit<T>>(const Ray<T>&, const Vec3<T>&, T)>;

// Another project's own intersector run as a subject (Embree, CGAL, POV-Ray's
// arithmetic: validation/peers/): what it is, and where its speed figure
// comes from (a per-test bench row, or the peer's whole-tracer bench where
// no per-test time exists). Reported beside the counts, marked as a peer.
struct PeerInfo {
  std::string what, speed_source;
};

// An intersector under audit at one precision (only the matching callable is set).
struct TriangleSubject {
  std::string method;
  Precision precision = Precision::f64;
  TriangleFn<float> f32;
  TriangleFn<double> f64;
  std::optional<PeerInfo> peer;  // unset: the registry's method or a user's own
  std::string name() const { return method + "/" + precision_name(precision); }
};
struct SphereSubject {
  std::string method;
  Precision precision = Precision::f64;
  SphereFn<float> f32;
  SphereFn<double> f64;
  std::string name() const { return method + "/" + precision_name(precision); }
};

// A subject of either kind from one callable: its precision is T's.
template <class Subject, class T, class F>
Subject subject_of(std::string method, F&& f) {
  Subject s;
  s.method = std::move(method);
  if constexpr (sizeof(T) == sizeof(float))
    s.precision = Precision::f32, s.f32 = std::forward<F>(f);
  else
    s.precision = Precision::f64, s.f64 = std::forward<F>(f);
  return s;
}
template <class T, class F>
TriangleSubject triangle_subject(std::string method, F&& f) {
  return subject_of<TriangleSubject, T>(std::move(method), std::forward<F>(f));
}
template <class T, class F>
SphereSubject sphere_subject(std::string method, F&& f) {
  return subject_of<SphereSubject, T>(std::move(method), std::forward<F>(f));
}

// A registered method at one precision (two-sided: cull = false).
TriangleSubject registry_triangle(const Method& m, Precision p);
SphereSubject registry_sphere(const Method& m, Precision p);

// A rounded relative t error above this is a wrong t (the hit is reported at
// another point of the surface, e.g. a far sphere root), not a rounding error.
inline constexpr double kWrongTRelative = 1e-2;

// Counts for one subject over a set of cases.
struct Stats {
  // Per ray/primitive test, by exact verdict and the subject's answer.
  std::uint64_t tests = 0, true_hits = 0, false_hits = 0, true_misses = 0, false_misses = 0, boundary_hits = 0,
                boundary_misses = 0, coplanar_hits = 0, coplanar_misses = 0, degenerate_hits = 0, degenerate_misses = 0;
  std::uint64_t nan_inf = 0;  // a reported hit with a NaN or infinite t, b1 or b2
  // A right hit whose t is off by more than kWrongTRelative, or (spheres, both
  // roots in the window and distinct in the subject's precision) whose t is
  // closer to the far root than to the near one: the wrong root.
  std::uint64_t wrong_t = 0;
  // Per group (edge pair, vertex fan, closed mesh): the exact answer meets
  // the group but the subject hits none of it (leak), or the subject reports
  // more hits than the ray has distinct exact crossings (double hit).
  std::uint64_t groups = 0, leaks = 0, double_hits = 0;
  // Secondary rays: spawned, and how many hit the triangle they left.
  // Refracted rays (spawned into a closed solid) must reach the far wall: a
  // self-hit is a nearest hit on the entry triangle (spheres: on the entry
  // side of the chord's midpoint), a skipped wall a miss of everything or a
  // nearest hit on a triangle the ray does not cross. Both are the
  // strategy's outcome, not wrong answers: the method's answer for the ray
  // as spawned is booked as a test like any other.
  std::uint64_t spawned = 0, self_hits = 0, skipped_walls = 0;
  // t error of right hits: ulps in the subject's precision and relative.
  // Relative errors: bin 0 is exact, then 8 bins per octave from 2^-80 to
  // 2^64 (below 2^-80 counts in bin 1, above 2^64 in the last bin): double
  // rounding errors are ~2^-53, float ~2^-24, a wrong root can be >> 1.
  static constexpr int kRelMinExp = -80, kRelMaxExp = 64;
  static constexpr int kUlpBins = 320, kRelBins = 1 + (kRelMaxExp - kRelMinExp) * 8;
  std::uint64_t t_samples = 0, max_ulps = 0;
  double max_rel = 0;
  std::array<std::uint64_t, kUlpBins> ulp_hist{};
  std::array<std::uint64_t, kRelBins> rel_hist{};
  // Hit cases (exact verdict hit) whose ray meets the triangle from behind,
  // d . ((b-a) x (c-a)) > 0, and how many of them the subject missed: all
  // of them missed while the front is hit is a one-sided (culling) subject.
  std::uint64_t back_hits = 0, back_false_misses = 0;
  // The lowest probe numbers (within the family's sweep value, as the
  // export numbers them) with a wrong answer, leak, double hit or NaN: at
  // most kExamples, the same whatever the threads or shards.
  static constexpr std::size_t kExamples = 3;
  std::vector<std::uint64_t> examples;
  // wrong + NaN + leaks + double hits: what makes a probe an example.
  std::uint64_t bad() const { return wrong() + nan_inf + leaks + double_hits; }
  void note_example(std::uint64_t probe);

  void merge(const Stats& o);
  std::uint64_t wrong() const { return false_hits + false_misses + wrong_t; }
  // Median ulps is exact below 64 ulps, within 1/4 octave above; median
  // relative error within 1/8 octave (both report the bin's lower bound).
  std::uint64_t median_ulps() const;
  double median_rel() const;
  // (wrong + leaks + double hits + NaN) per test: what "worst" ranks by.
  double badness() const;
  nlohmann::json to_json() const;
  // The t error histograms as sparse [bin, count] pairs (shard outputs carry
  // them, so merged medians are those of the unsharded run, bin for bin).
  nlohmann::json histograms_json() const;
  // Inverse of to_json() + histograms_json(); throws std::runtime_error
  // naming the first missing or malformed key.
  static Stats from_json(const nlohmann::json& stats, const nlohmann::json& histograms);
};

// Shard k of n (1 <= k <= n): the chunks c of every family and sweep value
// with c % n == k - 1. Chunks are fixed (256 probes), so a shard judges the
// same rays whatever the thread count, and the n shards together judge
// exactly the rays of the unsharded run.
struct Shard {
  std::uint64_t k = 1, n = 1;
};
inline constexpr std::uint64_t kMaxShards = 1000000;

struct Options {
  std::vector<std::string> families;  // empty: every family of the subjects' kinds
  long long rays = 20000;             // ray/primitive tests per family per subject
  std::uint64_t seed = 1;
  int threads = 0;             // 0: all hardware threads
  std::optional<Shard> shard;  // unset: every ray
  // Called after each chunk (from any thread, serialised) with the cases done
  // and planned, counted as --rays counts them (ray/primitive tests per family).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

struct Cell {
  std::size_t subject;  // index into Report::subjects
  std::string family;
  int sweep;
  std::string sweep_label;
  Stats stats;
  // Failing case ids when they are not FAMILY:SWEEP:PROBE of stats.examples
  // (graded answers name their own); to_json writes one or the other.
  std::vector<std::string> example_ids;
};

struct Report {
  std::uint64_t seed = 0;
  long long rays = 0;
  std::vector<std::string> subjects;           // "method/precision", triangles then spheres
  std::vector<std::string> kinds;              // "triangle" / "sphere", per subject
  std::vector<std::optional<PeerInfo>> peers;  // per subject (or empty: none is a peer)
  std::vector<Cell> cells;                     // subject-major, families and sweeps in order
  std::optional<Shard> shard;                  // set: a shard's partial counts (to_json adds
                                               // "shard" and per-cell "histograms" for merging)

  Stats total(std::size_t subject) const;
  const PeerInfo* peer(std::size_t subject) const {
    return subject < peers.size() && peers[subject] ? &*peers[subject] : nullptr;
  }
  const Cell* worst(std::size_t subject) const;  // nullptr when nothing went wrong
  nlohmann::json to_json() const;
  // Reads what to_json() wrote for a shard (throws std::runtime_error).
  static Report from_json(const nlohmann::json& j);
  std::string summary_table() const;
  // The refracted cells summed over the methods of each kind and precision:
  // self-hits and skipped walls per strategy (rows) and scale (columns), in
  // % of the rays spawned; empty when no refracted cell is there.
  std::string refracted_table() const;
  std::string to_csv() const;
};

// Runs every subject over the chosen families (triangle subjects on triangle
// families, sphere subjects on sphere families). Deterministic for any
// thread count: cases depend only on (seed, family, sweep, chunk).
// Throws std::invalid_argument for a family name that is not a family
// (a typo judged nothing, and a check on nothing passed), a named family
// no subject's kind grades, rays outside 1..1e10 or threads below 0.
Report run(const std::vector<TriangleSubject>& tris, const std::vector<SphereSubject>& spheres, const Options& opt);

// Grading answers computed elsewhere (`rayaudit audit --grade`): one probe is
// a ray against `count` triangles (a group when count > 1: edge pair, vertex
// fan, or a closed mesh when `closed`), with the subject's answer for each.
// Books exactly as for a registered method of precision p: the oracle's
// verdicts, t errors in ulps of p, leaks and double hits over the group.
struct GivenAnswer {
  bool hit = false;
  double t = 0, u = 0, v = 0;  // u, v: barycentrics if given (only checked for NaN/inf)
};
void grade_probe(Stats& st, Precision p, const Rayd& ray, const Tri* tris, const GivenAnswer* given, int count,
                 bool closed);

// One refracted ray graded as the refracted family grades it, for rays
// spawned by hand (tests; a strategy of one's own): tris is a closed convex
// mesh entered through tris[entry] at entry_point (the exact entry point,
// rounded), spawned the ray a strategy made there going into the mesh (in
// s's precision). The far wall is the first exact crossing, the entry
// triangle left out, of the ray from entry_point along spawned.d. The
// subject's nearest hit over the mesh counts as a self-hit (the entry
// triangle), a skipped wall (nothing, or a triangle the ray does not cross)
// or the wall, and books one test against the exact answer for the spawned
// ray on that triangle (no hit: on the far wall, else the entry). Throws
// std::invalid_argument when the ray from entry_point meets no other triangle.
void grade_refracted(Stats& st, const TriangleSubject& s, const std::vector<Tri>& tris, int entry,
                     const Vec3d& entry_point, const Rayd& spawned);

// Every probe of a family with its exact answers, as the audit sees them
// (for the export and for tests that check the families themselves).
struct ProbeCase {
  Rayd ray;
  std::vector<Tri> tris;
  std::vector<oracle::Answer> answers;
};
// probe_cases() one at a time, chunk by chunk (the same cases in the same
// order), so an export's memory does not grow with --rays.
void for_each_probe_case(const Family& f, int sweep, Precision p, std::uint64_t seed, long long rays,
                         const std::function<void(const ProbeCase&)>& visit);
std::vector<ProbeCase> probe_cases(const Family& f, int sweep, Precision p, std::uint64_t seed, long long rays);
std::vector<SphereCase> sphere_cases(const Family& f, int sweep, Precision p, std::uint64_t seed, long long rays);
// Probes per sweep value for a --rays budget (the unit of chunking).
long long probes_per_sweep(const Family& f, int sweep, long long rays);

}  // namespace ra::audit
