// methods/moller_simd.h against methods/moller.h: every lane must answer as
// the scalar kernel, bit for bit (hit or miss, t, b1, b2), on random rays and
// on the edge cases where rounding decides: rays at vertices and edge points,
// parallel and grazing rays, degenerate triangles, windows ending at the hit.
#include "methods/moller_simd.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "methods/moller.h"
#include "methods/simd_test_blocks.h"

namespace ra {
namespace {

template <class T>
bool same_bits(T a, T b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Compares the 4 lanes of one block with the scalar kernel; returns hits.
template <class T>
int compare_block(const Ray<T>& r, const Vec3<T> (&v)[4][3], bool cull) {
  moller_simd::Tri4<T> blk{};
  for (int l = 0; l < 4; ++l) blk.set(l, v[l][0], v[l][1], v[l][2]);
  moller_simd::Hit4<T> h;
  moller_simd::hit4(r, blk, cull, h);
  int hits = 0;
  for (int l = 0; l < 4; ++l) {
    const auto s = moller::hit(r, v[l][0], v[l][1], v[l][2], cull);
    const bool lane = (h.hits >> l) & 1;
    EXPECT_EQ(s.has_value(), lane) << "lane " << l;
    if (s && lane) {
      EXPECT_TRUE(same_bits(s->t, h.t[l])) << s->t << " vs " << h.t[l];
      EXPECT_TRUE(same_bits(s->b1, h.b1[l]));
      EXPECT_TRUE(same_bits(s->b2, h.b2[l]));
      ++hits;
    }
  }
  return hits;
}

template <class T>
void random_and_edge_rays(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), w(0, 1);
  auto point = [&] { return Vec3<T>(T(u(rng)), T(u(rng)), T(u(rng))); };
  int hits = 0, total = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    Vec3<T> v[4][3];
    for (auto& tri : v)
      for (auto& p : tri) p = point();
    if (iter % 7 == 0) v[1][2] = v[1][1];                         // degenerate: two equal vertices
    if (iter % 11 == 0) v[2][2] = v[2][0] + (v[2][1] - v[2][0]);  // (nearly) collinear
    Ray<T> r;
    r.o = Vec3<T>(T(3 * u(rng)), T(3 * u(rng)), T(3 * u(rng)));
    // Aim at a point of triangle 0: a vertex, an edge point or an interior point.
    const int kind = iter % 4;
    const Vec3<T> target = aim_point(v[0], kind, iter % 3, [&] { return w(rng); });
    r.d = target - r.o;
    if (iter % 13 == 0) r.d = v[0][1] - v[0][0];  // parallel to an edge
    if (iter % 17 == 0) r.d.z = T(0);             // an axis-parallel component
    if (iter % 5 == 0) {
      // A window ending exactly at the scalar kernel's t.
      if (auto s = moller::hit(r, v[0][0], v[0][1], v[0][2], false)) r.tmax = s->t;
    }
    if (iter % 19 == 0) r.tmin = T(0.5);
    for (bool cull : {false, true}) {
      hits += compare_block(r, v, cull);
      total += 4;
    }
  }
  EXPECT_GT(hits, total / 20);  // the comparison saw hits, not only misses
}

// Signed zeros: rays with -0 components hitting triangles with vertices on
// the coordinate planes, at vertices and edges, where t, b1 or b2 is a zero
// whose sign the lanes must keep (a broadcast written 0 + x would lose it).
template <class T>
void signed_zero_rays() {
  int hits = 0;
  for_each_signed_zero_block<T>([&](const Ray<T>& r, const Vec3<T>(&v)[4][3]) {
    for (bool cull : {false, true}) hits += compare_block(r, v, cull);
  });
  EXPECT_GT(hits, 0);
}

TEST(MollerSimd, SignedZerosKeepTheirSignInEveryLane) {
  signed_zero_rays<float>();
  signed_zero_rays<double>();
}

TEST(MollerSimd, FloatLanesAreBitIdenticalToScalar) { random_and_edge_rays<float>(1); }
TEST(MollerSimd, DoubleLanesAreBitIdenticalToScalar) { random_and_edge_rays<double>(2); }

}  // namespace
}  // namespace ra
