// Example: auditing your OWN intersector with the C++ API and the GoogleTest
// helpers, included as <rayaudit/...> exactly as a user of the installed
// package does. The intersector here is a deliberately naive textbook one.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>
#include <optional>

#include <rayaudit/audit.h>
#include <rayaudit/audit_gtest.h>

namespace {

// The textbook recipe: intersect the plane, then keep the point only if it
// lies inside every edge by more than a fixed epsilon (the kind of constant
// REFERENCES.md warns about). Rays through a shared edge fall in the band
// that both neighbours reject: a leak.
constexpr float kNaiveEpsilon = 1e-6f;

std::optional<ra::TriangleHit<float>> naive(const ra::Rayf& r, const ra::Vec3f& a, const ra::Vec3f& b,
                                            const ra::Vec3f& c) {
  const ra::Vec3f n = cross(b - a, c - a);
  const float denom = dot(n, r.d);
  if (std::abs(denom) < kNaiveEpsilon) return std::nullopt;
  const float t = dot(n, a - r.o) / denom;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  const ra::Vec3f p = r.at(t);
  const float nn = dot(n, n);
  const float w0 = dot(cross(b - a, p - a), n) / nn, w1 = dot(cross(c - b, p - b), n) / nn,
              w2 = dot(cross(a - c, p - c), n) / nn;
  if (w0 <= kNaiveEpsilon || w1 <= kNaiveEpsilon || w2 <= kNaiveEpsilon) return std::nullopt;
  return ra::TriangleHit<float>{t, w2, w0};
}

TEST(ExampleUserIntersector, NaiveEpsilonTestLeaksThroughSharedEdges) {
  const auto mine = ra::audit::triangle_subject<float>("naive", naive);
  // The gtest helper fails, and says where:
  const ::testing::AssertionResult wt = ra::audit::IsWatertight(mine);
  EXPECT_FALSE(wt);
  EXPECT_NE(std::string(wt.message()).find("edge@"), std::string::npos) << wt.message();
  // The same report through the plain C++ API:
  ra::audit::Options o;
  o.families = {"edge"};
  o.rays = 20000;
  const ra::audit::Report rep = ra::audit::run({mine}, {}, o);
  EXPECT_GT(rep.total(0).leaks, 0u) << rep.summary_table();
  std::printf("%s", rep.summary_table().c_str());
}

TEST(ExampleUserIntersector, NaiveTestHasFalseMissesOnNearEdgeRays) {
  const auto mine = ra::audit::triangle_subject<float>("naive", naive);
  EXPECT_FALSE(ra::audit::HasNoWrongAnswers(mine, {.families = {"near-miss", "edge"}}));
}

TEST(ExampleUserIntersector, WrapperAroundRegistryWatertightPasses) {
  const ra::Method* m = ra::find_method("watertight");
  ASSERT_NE(m, nullptr) << "the registry has no method 'watertight'";
  auto k = m->tri_f.hit;
  const auto mine = ra::audit::triangle_subject<float>(
      "my-watertight", [k](const ra::Rayf& r, const ra::Vec3f& a, const ra::Vec3f& b, const ra::Vec3f& c) {
        return k(r, a, b, c, /*cull=*/false);
      });
  EXPECT_WATERTIGHT(mine);
}

// The exact answer itself as an intersector (the oracle on the float
// inputs, which double holds exactly): a hit wherever the closed triangle
// is met, at the exact t. `mangle` spoils the t it returns.
template <class Mangle>
auto exact(Mangle mangle) {
  return ra::audit::triangle_subject<float>(
      "exact",
      [mangle](const ra::Rayf& r, const ra::Vec3f& a, const ra::Vec3f& b,
               const ra::Vec3f& c) -> std::optional<ra::TriangleHit<float>> {
        const ra::oracle::Answer ans = ra::oracle::triangle(ra::Rayd(r), ra::Vec3d(a), ra::Vec3d(b), ra::Vec3d(c));
        if (ans.verdict != ra::oracle::Verdict::hit && ans.verdict != ra::oracle::Verdict::boundary)
          return std::nullopt;
        return ra::TriangleHit<float>{mangle(float(ans.t)), 0.25f, 0.25f};
      });
}

// What the checks must refuse: hits whose t a renderer would
// drop are leaks all the same; a family name that is not a family judged
// nothing, and passed; and the exact answer is watertight, with no double
// hit where it meets a shared edge or vertex exactly.
TEST(ExampleUserIntersector, WatertightJudgesTheTOfHitsAndRefusesUnknownFamilies) {
  const ra::audit::CheckOptions few{.rays = 3000};
  const auto perfect = exact([](float t) { return t; });
  EXPECT_TRUE(ra::audit::IsWatertight(perfect, few));
  ra::audit::Options o;
  o.families = {"edge", "vertex", "closed-mesh"};
  o.rays = 3000;
  const ra::audit::Report rep = ra::audit::run({perfect}, {}, o);
  EXPECT_EQ(rep.total(0).double_hits, 0u) << rep.summary_table();
  EXPECT_EQ(rep.total(0).leaks, 0u);
  for (const auto& [name, spoil] : std::vector<std::pair<const char*, float (*)(float)>>{
           {"NaN", [](float) { return std::numeric_limits<float>::quiet_NaN(); }},
           {"infinite", [](float) { return std::numeric_limits<float>::infinity(); }},
           {"behind the origin", [](float t) { return -t - 1; }},
           {"always 1", [](float) { return 1.f; }}}) {
    const ::testing::AssertionResult wt = ra::audit::IsWatertight(exact(spoil), few);
    EXPECT_FALSE(wt) << name;
    EXPECT_NE(std::string(wt.message()).find("off by more than 1%"), std::string::npos) << name << ": " << wt.message();
  }
  EXPECT_THROW(ra::audit::IsWatertight(perfect, {.families = {"edges"}}), std::invalid_argument);
  EXPECT_THROW(ra::audit::HasNoWrongAnswers(perfect, {.families = {"huge"}}), std::invalid_argument)
      << "a sphere family, and no sphere subject";
  EXPECT_THROW(ra::audit::IsWatertight(perfect, {.rays = 0}), std::invalid_argument);
}

// A long audit spread over GoogleTest's shards: run with GTEST_TOTAL_SHARDS=N
// and GTEST_SHARD_INDEX=0..N-1 (ctest does, per test; CI matrices can), each
// shard judges its 1/N of the rays. Unsharded, it is one test judging them all.
const bool kShardedExample =
    ra::audit::RegisterShardedAudit("ExampleShardedAudit", "NaiveLeaksInEveryShard", [](const ra::audit::Shard& shard) {
      const auto mine = ra::audit::triangle_subject<float>("naive", naive);
      const ra::audit::CheckOptions c{.families = {"edge"}, .rays = 60000, .shard = shard};
      const ::testing::AssertionResult wt = ra::audit::IsWatertight(mine, c);
      EXPECT_FALSE(wt);
      std::printf("judged shard %llu/%llu: %s\n", (unsigned long long)shard.k, (unsigned long long)shard.n,
                  wt.message());
    });

}  // namespace
