// methods/exact_simd.h against methods/exact.h: every lane's stage 1 must be
// the scalar filter's (U, V, W bit for bit, the same verdict), a lane the
// window test rejects must be the scalar kernel's miss, and the leaf's
// answer, a rejected lane's miss or after_signs on the lane's values, must
// be the scalar kernel's (hit or miss, t, b1, b2 bit for bit), for closest
// and any-hit, culled or not, on seeded random and adversarial inputs:
// rays through vertices and edge points, shared edges, grazing rays, far
// origins, subnormal and huge coordinates (across the double filter's range
// guard), degenerate triangles, non-finite rays, signed zeros, and windows
// ending at the hit. Both the baseline (SSE) lanes and, where the CPU has
// it, the AVX2 form the tracer's entry points compile are checked.
#include "methods/exact_simd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "methods/exact.h"
#include "methods/simd_test_blocks.h"

namespace ra {
namespace {

using exact::detail::Signs;

template <class T>
bool same_bits(T a, T b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Stage 1 of the block in the form the tracer's AVX2 entry points compile
// (kAvx: vmovmskpd), and in baseline SSE.
template <class T>
[[gnu::target("avx2,fma"), gnu::noinline]] void signs4_avx2(const exact_simd::RayLanes& r, double thi,
                                                            const exact_simd::Tri4<T>& tri, int live,
                                                            exact_simd::Signs4& out) {
  exact_simd::signs4<true>(r, thi, tri, live, out);
}
template <class T>
[[gnu::noinline]] void signs4_base(const exact_simd::RayLanes& r, double thi, const exact_simd::Tri4<T>& tri, int live,
                                   exact_simd::Signs4& out) {
  exact_simd::signs4<false>(r, thi, tri, live, out);
}

// How often each path was seen, so that the test can insist every one was.
struct Seen {
  long miss = 0, inside = 0, undecided = 0, out = 0, hits = 0, lanes = 0;
};

// Compares the 4 lanes of one block (live lanes: the first `count`) with
// the scalar kernel.
template <class T>
void compare_block(const Ray<T>& r, const Vec3<T> (&v)[4][3], int count, bool avx, Seen& seen) {
  exact_simd::Tri4<T> blk{};
  for (int l = 0; l < 4; ++l) blk.set(l, v[l][0], v[l][1], v[l][2]);
  const exact_simd::RayLanes lanes = exact_simd::ray_lanes(r);
  exact_simd::Signs4 s;
  const int live = (1 << count) - 1;
  if (avx)
    signs4_avx2(lanes, double(r.tmax), blk, live, s);
  else
    signs4_base(lanes, double(r.tmax), blk, live, s);
  EXPECT_EQ(s.out & ~live, 0);
  EXPECT_EQ(s.out & s.miss, 0);
  for (int l = 0; l < count; ++l) {
    const int bit = 1 << l;
    const Vec3<T>&a = v[l][0], &b = v[l][1], &c = v[l][2];
    double U, V, W;
    int sign = 0;
    const Signs sg = exact::detail::signs<double>(r, a, b, c, exact::detail::kFilterLimit<T>,
                                                  exact::detail::kFilterTau<T>, U, V, W, sign);
    // Stage 1: the same values and verdict.
    EXPECT_TRUE(same_bits(U, s.U[l]) && same_bits(V, s.V[l]) && same_bits(W, s.W[l]))
        << "lane " << l << ": U " << U << " " << s.U[l] << ", V " << V << " " << s.V[l] << ", W " << W << " " << s.W[l];
    const bool miss = s.miss & bit, pos = s.pos & bit, neg = s.neg & bit, out = s.out & bit;
    EXPECT_EQ(miss, sg == Signs::miss) << "lane " << l;
    EXPECT_EQ(pos || neg, sg == Signs::inside) << "lane " << l;
    if (sg == Signs::inside) {
      EXPECT_EQ(pos ? 1 : -1, sign) << "lane " << l;
    }
    ++seen.lanes;
    seen.miss += sg == Signs::miss;
    seen.inside += sg == Signs::inside;
    seen.undecided += sg == Signs::undecided;
    seen.out += out;
    // The whole answer, as the tracer's leaf forms it, against the scalar
    // prepared kernel.
    const auto p = exact::detail::prepare(a, b, c);
    const Signs lane_sg = miss ? Signs::miss : (pos || neg) ? Signs::inside : Signs::undecided;
    const int lane_s = pos ? 1 : neg ? -1 : 0;
    for (bool cull : {false, true}) {
      const auto want = exact::hit(r, p, cull);
      const auto got = miss || out ? std::nullopt
                                   : exact::detail::after_signs(lane_sg, s.U[l], s.V[l], s.W[l], lane_s, r, p.a, p.b,
                                                                p.c, &p.e, cull, true);
      ASSERT_EQ(want.has_value(), got.has_value()) << "lane " << l << " cull " << cull;
      if (want) {
        EXPECT_TRUE(same_bits(want->t, got->t)) << want->t << " vs " << got->t;
        EXPECT_TRUE(same_bits(want->b1, got->b1)) << want->b1 << " vs " << got->b1;
        EXPECT_TRUE(same_bits(want->b2, got->b2)) << want->b2 << " vs " << got->b2;
        ++seen.hits;
      }
      const bool any_got =
          !miss && !out &&
          exact::detail::after_signs(lane_sg, s.U[l], s.V[l], s.W[l], lane_s, r, p.a, p.b, p.c, &p.e, cull, false)
              .has_value();
      EXPECT_EQ(exact::any(r, p, cull), any_got) << "lane " << l << " cull " << cull;
    }
  }
  // leaf4 visits exactly the live lanes stage 1 did not reject, with their values.
  int visited = 0;
  exact_simd::leaf4(lanes, r.tmax, blk, live, [&](int l, Signs sg, double U, double V, double W, int sign) {
    visited |= 1 << l;
    EXPECT_TRUE(same_bits(U, s.U[l]) && same_bits(V, s.V[l]) && same_bits(W, s.W[l]));
    EXPECT_EQ(sg == Signs::inside, bool((s.pos | s.neg) >> l & 1));
    EXPECT_EQ(sign, (s.pos >> l & 1) ? 1 : (s.neg >> l & 1) ? -1 : 0);
    return false;
  });
  EXPECT_EQ(visited, live & ~s.miss & ~s.out);
}

template <class T>
void random_and_adversarial(std::uint64_t seed, bool avx) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), w(0, 1);
  auto point = [&] { return Vec3<T>(T(u(rng)), T(u(rng)), T(u(rng))); };
  constexpr bool kFloat = sizeof(T) == sizeof(float);
  // Scales: subnormal, tiny, unit, far, huge (double: either side of the
  // filter's 2^330 guard; float: near the top of its range).
  const double scales[] = {kFloat ? 0x1p-140 : 0x1p-1060, kFloat ? 0x1p-100 : 0x1p-700, 1, 0x1p40,
                           kFloat ? 0x1p100 : 0x1p329,    kFloat ? 0x1p120 : 0x1p335};
  Seen seen;
  for (int iter = 0; iter < 6000; ++iter) {
    Vec3<T> v[4][3];
    for (auto& tri : v)
      for (auto& p : tri) p = point();
    const int family = iter % 10;
    if (family == 1) v[1][0] = v[0][1], v[1][1] = v[0][0];              // lane 1 shares lane 0's edge
    if (family == 2) v[2][2] = v[2][1];                                 // degenerate: two equal vertices
    if (family == 3) v[3][2] = v[3][0] + (v[3][1] - v[3][0]) * T(0.5);  // (nearly) collinear
    Ray<T> r;
    r.o = Vec3<T>(T(3 * u(rng)), T(3 * u(rng)), T(3 * u(rng)));
    // Aim at a point of triangle 0: a vertex, an edge point or an interior point.
    const int kind = (iter / 10) % 3;
    const Vec3<T> target = aim_point(v[0], kind, iter % 3, [&] { return w(rng); });
    if (family == 4) {  // grazing: from a point of the plane, nudged off it
      const Vec3<T> n = cross(v[0][1] - v[0][0], v[0][2] - v[0][0]);
      r.o = v[0][0] + (v[0][0] - target) * T(2) + n * T(1e-6 * w(rng));
    }
    if (family == 5) r.o = r.o * T(1e6);  // far origin
    r.d = target - r.o;
    if (family == 6) r.d = v[0][1] - v[0][0];  // parallel to an edge
    if (family == 7) r.d.z = (iter & 1) ? T(0) : -T(0);
    if (family == 8) {  // everything scaled: subnormal to huge
      const T k = T(scales[(iter / 10) % 6]);
      for (auto& tri : v)
        for (auto& p : tri) p = p * k;
      r.o = r.o * k;
      if (iter % 20 < 10) r.d = r.d * k;
    }
    if (family == 9 && iter % 30 == 9) r.d.x = std::numeric_limits<T>::quiet_NaN();
    if (family == 9 && iter % 30 == 19) r.o.y = std::numeric_limits<T>::infinity();
    if (iter % 7 == 3 && family < 8) {
      // A shadow ray: from the surface of triangle 0 (its aimed-at point),
      // away from it, clear of it by tmin.
      r.o = target;
      r.d = Vec3<T>(T(u(rng)), T(u(rng)), T(u(rng)));
      r.tmin = T(1e-4);
    }
    if (iter % 11 == 5) r.tmax = T(0.5 + w(rng));  // a window closing among the triangles
    if (iter % 3 == 0) {
      // A window ending exactly at the scalar kernel's t, or starting there.
      if (auto h = exact::hit(r, v[0][0], v[0][1], v[0][2], false)) (iter % 2 ? r.tmax : r.tmin) = h->t;
    }
    compare_block(r, v, 1 + iter % 4, avx, seen);
  }
  // Every path was taken: rejected, certified inside, undecided, outside
  // the window; and hits.
  EXPECT_GT(seen.out, seen.lanes / 50);
  EXPECT_GT(seen.miss, seen.lanes / 10);
  EXPECT_GT(seen.inside, seen.lanes / 20);
  EXPECT_GT(seen.undecided, seen.lanes / 50);
  EXPECT_GT(seen.hits, seen.lanes / 20);
}

// Signed zeros: rays with -0 components at triangles with vertices on the
// coordinate planes, through vertices and edges.
template <class T>
void signed_zero_rays(bool avx) {
  Seen seen;
  for_each_signed_zero_block<T>([&](const Ray<T>& r, const Vec3<T>(&v)[4][3]) { compare_block(r, v, 4, avx, seen); });
  EXPECT_GT(seen.hits, 0);
}

bool have_avx2() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }

TEST(ExactSimd, FloatLanesAnswerAsTheScalarKernel) { random_and_adversarial<float>(41, false); }
TEST(ExactSimd, DoubleLanesAnswerAsTheScalarKernel) { random_and_adversarial<double>(42, false); }
TEST(ExactSimd, Avx2LanesAnswerAsTheScalarKernel) {
  if (!have_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  random_and_adversarial<float>(43, true);
  random_and_adversarial<double>(44, true);
}
TEST(ExactSimd, SignedZerosAnswerAsTheScalarKernel) {
  for (bool avx : {false, true}) {
    if (avx && !have_avx2()) continue;
    signed_zero_rays<float>(avx);
    signed_zero_rays<double>(avx);
  }
}

}  // namespace
}  // namespace ra
