// All triangle methods against the construction and against each other on
// 100,000 seeded random rays (double) that stay far from edges, and the
// watertight method's guarantee on rays aimed at a shared edge.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "../registry.h"

namespace ra {
namespace {

constexpr std::uint64_t kSeed = 20240611;
constexpr int kRays = 100000;

struct Sample {
  Rayd ray;
  Vec3d a, b, c;
  bool cull;
  bool expect_hit;
  double t, b1, b2;  // the construction's hit (when expect_hit)
};

// One ray/triangle pair whose answer is known by construction: the aim
// point's barycentrics are >= 1e-3 from every edge inside, or one is below
// -1e-2 outside; triangles have area >= 0.1 and rays make |cos| >= 0.1 with
// the normal, so no document tolerance (epsilon3, MINUS_ZERO, 1e-6, PLUS_ZERO)
// can flip the answer.
Sample make_sample(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  Sample s{};
  Vec3d n;
  do {
    s.a = {u(rng), u(rng), u(rng)};
    s.b = {u(rng), u(rng), u(rng)};
    s.c = {u(rng), u(rng), u(rng)};
    n = cross(s.b - s.a, s.c - s.a);
  } while (length(n) < 0.2);
  const bool inside = u01(rng) < 0.5;
  double b0, b1, b2;
  do {
    if (inside) {
      b1 = u01(rng);
      b2 = u01(rng);
    } else {
      b1 = 3 * u01(rng) - 1;
      b2 = 3 * u01(rng) - 1;
    }
    b0 = 1 - b1 - b2;
  } while (inside ? std::min({b0, b1, b2}) < 1e-3 : std::min({b0, b1, b2}) > -1e-2);
  const Vec3d p = s.a * b0 + s.b * b1 + s.c * b2;
  Vec3d dir;
  do {
    dir = {u(rng), u(rng), u(rng)};
  } while (length(dir) > 1 || length(dir) < 0.1 || std::abs(dot(normalize(dir), normalize(n))) < 0.1);
  dir = dir * (0.5 + 1.5 * u01(rng));  // not unit length
  const double t = 0.5 + 4.5 * u01(rng);
  const bool behind = u01(rng) < 0.1;  // the triangle behind the origin
  s.ray = Rayd{behind ? p + dir * t : p - dir * t, dir};
  s.cull = u01(rng) < 0.5;
  const bool back = dot(dir, n) >= 0;
  s.expect_hit = inside && !behind && !(s.cull && back);
  s.t = t;
  s.b1 = b1;
  s.b2 = b2;
  return s;
}

TEST(TriangleAgreement, AllMethodsMatchConstructionFarFromEdges) {
  std::mt19937_64 rng(kSeed);
  std::vector<const Method*> tri;
  for (const auto& m : methods())
    if (m.kind == Kind::triangle && !m.wrong_on_purpose) tri.push_back(&m);
  ASSERT_EQ(tri.size(), 9u);
  alignas(64) unsigned char pre[512];
  int failures = 0, hits = 0;
  for (int i = 0; i < kRays && failures < 10; ++i) {
    const Sample s = make_sample(rng);
    hits += s.expect_hit;
    for (const Method* m : tri) {
      const auto& k = m->triangle<double>();
      k.prepare(s.a, s.b, s.c, pre);
      const auto h = k.hit(s.ray, s.a, s.b, s.c, s.cull);
      const auto hp = k.hit_pre(s.ray, pre, s.cull);
      const bool ok = h.has_value() == s.expect_hit && hp.has_value() == s.expect_hit &&
                      (!h || (std::abs(h->t - s.t) <= 1e-9 * s.t && std::abs(h->b1 - s.b1) <= 1e-9 &&
                              std::abs(h->b2 - s.b2) <= 1e-9));
      if (!ok) {
        ++failures;
        ADD_FAILURE() << m->name << " disagrees on ray " << i << " (seed " << kSeed << "): expected "
                      << (s.expect_hit ? "hit" : "miss") << " t=" << s.t << " b=(" << s.b1 << ", " << s.b2 << "), got "
                      << (h ? "hit t=" + std::to_string(h->t) + " b=(" + std::to_string(h->b1) + ", " +
                                  std::to_string(h->b2) + ")"
                            : std::string("miss"))
                      << " cull=" << s.cull << " o=" << s.ray.o << " d=" << s.ray.d;
      }
    }
  }
  // The construction itself: about half of the unculled, in-front rays hit.
  EXPECT_GT(hits, kRays / 5) << "seed " << kSeed;
}

// Two triangles sharing the edge PQ with consistent winding, as in a closed
// mesh; rays that cross the surface at a point of PQ (the aim is rounded to
// T, so it is near the edge, not on it) must hit at least one of them: the
// guarantee watertight.h states.
template <class T>
int edge_leaks(const char* name, std::uint64_t seed, int n, int* tried_out = nullptr) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), u01(0.05, 0.95);
  const auto& k = find_method(name)->template triangle<T>();
  int leaks = 0, tried = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3d p{u(rng), u(rng), u(rng)}, q{u(rng), u(rng), u(rng)};
    const Vec3d x{u(rng), u(rng), u(rng)}, y{u(rng), u(rng), u(rng)};
    const Vec3d aim = p + (q - p) * u01(rng);
    const Vec3d o = Vec3d{u(rng), u(rng), u(rng)} * 4.0;
    const Vec3<T> P(p), Q(q), X(x), Y(y);
    // Keep rays that cross the two-triangle surface (both faces seen from the
    // same side, not grazing); a ray that only touches a ridge may miss both.
    const Vec3d n1 = normalize(cross(q - p, x - p)), n2 = normalize(cross(p - q, y - q));
    const Vec3d dn = normalize(aim - o);
    if (!(dot(dn, n1) * dot(dn, n2) > 0) || std::abs(dot(dn, n1)) < 0.05 || std::abs(dot(dn, n2)) < 0.05) continue;
    const Ray<T> r{Vec3<T>(o), Vec3<T>(aim - o)};
    // Consistent winding (P, Q, X) and (Q, P, Y), as in a closed mesh.
    ++tried;
    if (!k.hit(r, P, Q, X, false) && !k.hit(r, Q, P, Y, false)) ++leaks;
  }
  EXPECT_GT(tried, n / 10) << "too few usable configurations";
  if (tried_out) *tried_out = tried;
  return leaks;
}

TEST(TriangleAgreement, WatertightNeverLeaksThroughSharedEdge) {
  constexpr std::uint64_t seed = 7;
  EXPECT_EQ(edge_leaks<float>("watertight", seed, 20000), 0) << "seed " << seed;
  EXPECT_EQ(edge_leaks<double>("watertight", seed, 20000), 0) << "seed " << seed;
  // For the record (not asserted: the other methods make no such promise).
  int tried = 0;
  const int moller = edge_leaks<float>("moller", seed, 20000, &tried);
  const int baldwin = edge_leaks<float>("baldwin", seed, 20000);
  std::printf("shared-edge leaks in float out of %d rays: moller %d, baldwin %d\n", tried, moller, baldwin);
}

}  // namespace
}  // namespace ra
