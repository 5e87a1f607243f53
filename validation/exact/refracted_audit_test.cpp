// The refracted family (validation/exact/families.cpp, audit.cpp): rays
// spawned into a closed solid from a method's own entry hit must reach the
// far wall. Hand-made rays with answers from the geometry, then the family's
// counts where the geometry alone decides them (a fixed window longer than
// the whole solid skips every wall; a rounding error far above the window
// puts about half the origins outside).
#include <gtest/gtest.h>

#include <cmath>

#include "audit.h"
#include "spawn.h"

namespace {

using namespace ra::audit;
using ra::SelfIntersection;
using ra::Vec3d;
using ra::Vec3f;

// The cube [-s, s]^3 (the closed-mesh family's box scaled by s) and the
// index of the triangle of its top face (z = s) holding (x, y): found
// here by the face's own half-planes, not by the code under test.
struct Cube {
  std::vector<Tri> tris;
  int top = -1;
};
Cube cube(double s, double x, double y) {
  Cube c;
  for (const Tri& t : closed_mesh_triangles(1)) c.tris.push_back({t.a * s, t.b * s, t.c * s});
  for (int i = 0; i < int(c.tris.size()); ++i) {
    const Tri& t = c.tris[std::size_t(i)];
    if (t.a.z != s || t.b.z != s || t.c.z != s) continue;
    auto side = [&](const Vec3d& p, const Vec3d& q) { return (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x); };
    const double e0 = side(t.a, t.b), e1 = side(t.b, t.c), e2 = side(t.c, t.a);
    if ((e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0)) c.top = i;
  }
  return c;
}

const ra::Method& moller() {
  const ra::Method* m = ra::find_method("moller");
  EXPECT_NE(m, nullptr);
  return *m;
}

// Entering the top face at (s/4, s/2, s), straight down and a little aside.
const Vec3d kDown{0.125, 0.25, -1};

TEST(RefractedGrading, OriginMovedOutwardHitsTheEntryTriangle) {
  // A strategy that moved the origin along the outward normal (the wrong
  // side for a ray going in): the ray starts above the face and meets it first.
  const Cube c = cube(1, 0.25, 0.5);
  ASSERT_GE(c.top, 0);
  Stats st;
  grade_refracted(st, registry_triangle(moller(), Precision::f64), c.tris, c.top, {0.25, 0.5, 1},
                  {Vec3d{0.25, 0.5, 1 + 0x1p-10}, kDown});
  EXPECT_EQ(st.spawned, 1u);
  EXPECT_EQ(st.self_hits, 1u);
  EXPECT_EQ(st.skipped_walls, 0u);
  EXPECT_EQ(st.wrong(), 0u);  // the ray as spawned does cross the face: moller is right, the strategy is not
}

TEST(RefractedGrading, OriginMovedInwardReachesTheFloor) {
  const Cube c = cube(1, 0.25, 0.5);
  Stats st;
  grade_refracted(st, registry_triangle(moller(), Precision::f64), c.tris, c.top, {0.25, 0.5, 1},
                  {Vec3d{0.25, 0.5, 1 - 0x1p-30}, kDown});
  EXPECT_EQ(st.self_hits, 0u);
  EXPECT_EQ(st.skipped_walls, 0u);
  EXPECT_EQ(st.true_hits, 1u);  // the floor z = -1, at t = 2 - 2^-30
  EXPECT_EQ(st.wrong_t, 0u);
}

TEST(RefractedGrading, AFixedWindowLongerThanTheSolidSkipsTheFarWall) {
  // eps's window (t > 1e-5) in a cube of side 2^-19 (about 1.9e-6): the
  // floor is at t = 2^-19, inside the window's dead zone.
  const double s = 0x1p-20;
  const Cube c = cube(s, 0.25 * s, 0.5 * s);
  Stats st;
  grade_refracted(st, registry_triangle(moller(), Precision::f64), c.tris, c.top, Vec3d{0.25, 0.5, 1} * s,
                  {Vec3d{0.25, 0.5, 1} * s, kDown, ra::epsilon5, INFINITY});
  EXPECT_EQ(st.self_hits, 0u);
  EXPECT_EQ(st.skipped_walls, 1u);
  EXPECT_EQ(st.true_misses, 1u);  // nothing lies in that window: missing is right, for the method
}

TEST(RefractedGrading, EpsSelfHitsFromARoundedPointFarFromTheOriginNormalOffsetDoesNot) {
  // Float, a cube of half-side 2^24: floats there are 2 apart, so a hit
  // point rounded one ulp above the face is 2 above it, 2e5 times eps's 1e-5.
  const float s = 0x1p24f;
  const Cube c = cube(s, 0.25 * s, 0.5 * s);
  const Vec3f exact{0.25f * s, 0.5f * s, s};
  const Vec3f above{exact.x, exact.y, std::nextafter(s, INFINITY)};
  const Vec3f dir(ra::normalize(kDown));
  const Tri& t = c.tris[std::size_t(c.top)];
  // The hit's barycentrics as a method reports them (pbrt's error bound is
  // computed from them); exact here: the face's own coordinates of (x, y).
  const Vec3f A(t.a), B(t.b), C(t.c);
  const ra::Vec3f e1 = B - A, e2 = C - A, q = exact - A;
  const float det = e1.x * e2.y - e1.y * e2.x;
  const float b1 = (q.x * e2.y - q.y * e2.x) / det, b2 = (e1.x * q.y - e1.y * q.x) / det;
  const Vec3f err = ra::triangle_point_error(A, B, C, b1, b2);
  const Vec3f up{0, 0, 1};
  const TriangleSubject m = registry_triangle(moller(), Precision::f32);

  Stats eps, normal;
  const auto r_eps = ra::spawn_ray(SelfIntersection::eps, above, err, up, dir, false, 0.0f);
  grade_refracted(eps, m, c.tris, c.top, Vec3d(exact), ra::Rayd(r_eps));
  EXPECT_EQ(eps.self_hits, 1u);

  // spawn_ray turns n to the side the ray leaves toward (inward here) and
  // moves by the bound (7 gamma(1) |p| ~ 7 here, above the 2 of rounding).
  const auto r_off = ra::spawn_ray(SelfIntersection::normal_offset, above, err, up, dir, false, 0.0f);
  EXPECT_LT(r_off.o.z, s);
  grade_refracted(normal, m, c.tris, c.top, Vec3d(exact), ra::Rayd(r_off));
  EXPECT_EQ(normal.self_hits, 0u);
  EXPECT_EQ(normal.skipped_walls, 0u);
  EXPECT_EQ(normal.true_hits, 1u);
}

// The family with moller, where geometry decides: the solid at scale label
// L has size s in [L, 1e4 L] (log-uniform), so about half the probes have
// s < 100 L, and its far wall is at most its diameter 2s away.
Report refracted_run(Precision p, bool spheres) {
  Options o;
  o.families = {"refracted"};
  // 400 probes per strategy and scale: a mesh probe counts its 46 triangles.
  o.rays = spheres ? 6400 : 6400 * 46;
  o.seed = 5;
  if (spheres) {
    // stable, not kraus: kraus drops roots nearer than 1e-5 itself (its
    // document's epsilon), which would be counted with the strategies'.
    const ra::Method* k = ra::find_method("stable");
    EXPECT_NE(k, nullptr);
    return run({}, {registry_sphere(*k, p)}, o);
  }
  return run({registry_triangle(moller(), p)}, {}, o);
}

const Stats& cell(const Report& r, const std::string& sweep) {
  for (const Cell& c : r.cells)
    if (c.sweep_label == sweep) return c.stats;
  ADD_FAILURE() << "no cell " << sweep;
  static const Stats none;
  return none;
}

TEST(RefractedFamily, EveryStrategyAndScaleSpawnsForTrianglesAndSpheres) {
  for (bool spheres : {false, true}) {
    const Report r = refracted_run(Precision::f64, spheres);
    ASSERT_EQ(r.cells.size(), 16u);  // 4 strategies x 4 scales
    for (const Cell& c : r.cells) {
      EXPECT_EQ(c.family, "refracted");
      // Every primary ray enters (aimed strictly inside a face from outside):
      // a method that finds the hit spawns once per probe.
      EXPECT_GT(c.stats.spawned, 390u) << c.sweep_label;
      EXPECT_LE(c.stats.self_hits + c.stats.skipped_walls, c.stats.spawned);
    }
  }
}

TEST(RefractedFamily, FixedWindowsSkipTheFarWallOfTinySolids) {
  // Scale 1e-08: s < 5e-6 (67% of the log range) puts the whole solid
  // within eps's 1e-5; s < 5e-5 (92%) within pov's 1e-4. Both precisions.
  for (bool spheres : {false, true})
    for (Precision p : {Precision::f32, Precision::f64}) {
      const Report r = refracted_run(p, spheres);
      const Stats& eps = cell(r, "eps@1e-08");
      const Stats& pov = cell(r, "pov@1e-08");
      EXPECT_GT(eps.skipped_walls, eps.spawned / 2) << precision_name(p) << (spheres ? " sphere" : " mesh");
      EXPECT_GT(pov.skipped_walls, pov.spawned * 8 / 10) << precision_name(p) << (spheres ? " sphere" : " mesh");
      // ulp-offset moves points near the origin by 2^-16 (1.5e-5) per
      // component: through the whole solid when s < 7e-6.
      const Stats& ulp = cell(r, "ulp-offset@1e-08");
      EXPECT_GT(ulp.skipped_walls, ulp.spawned / 2) << precision_name(p) << (spheres ? " sphere" : " mesh");
    }
}

TEST(RefractedFamily, NormalOffsetNeverSelfHitsNorSkipsOnTheMeshOrTheSphere) {
  // pbrt's offset: inward by the hit point's error bound, a few ulps of the
  // coordinates, always far below the far wall's distance (>= ~0.05 s). On
  // the sphere the bound is pbrt's for the point reprojected onto it; from
  // o + t d as the method's t gives it, about 0.5% of rays self-hit.
  for (const bool spheres : {false, true})
    for (Precision p : {Precision::f32, Precision::f64}) {
      const Report r = refracted_run(p, spheres);
      for (const Cell& c : r.cells) {
        if (c.sweep_label.rfind("normal-offset@", 0) != 0) continue;
        EXPECT_GT(c.stats.spawned, 0u) << c.sweep_label;
        EXPECT_EQ(c.stats.self_hits, 0u) << precision_name(p) << (spheres ? " sphere " : " mesh ") << c.sweep_label;
        EXPECT_EQ(c.stats.skipped_walls, 0u) << precision_name(p) << (spheres ? " sphere " : " mesh ") << c.sweep_label;
      }
    }
}

TEST(RefractedFamily, EpsSelfHitsInFloatFarFromTheOriginButNotInDouble) {
  // Scale 1e4 (s up to 1e8): a float hit point is off the surface by about
  // 6e-8 |p| >= 6e-4, far above eps's 1e-5, on the outside about half the
  // time; in double, 1e-16 |p| <= 1e-8 stays inside eps's window.
  const Report fr = refracted_run(Precision::f32, false);
  const Stats& f = cell(fr, "eps@10000");
  EXPECT_GT(f.self_hits, f.spawned / 10);
  const Report d = refracted_run(Precision::f64, false);
  for (const char* scale : {"1", "10000"}) {
    EXPECT_EQ(cell(d, std::string("eps@") + scale).self_hits, 0u) << scale;
    EXPECT_EQ(cell(d, std::string("eps@") + scale).skipped_walls, 0u) << scale;
  }
}

TEST(RefractedFamily, FamilyOfBothKindsUnderOneName) {
  const auto named = families_named("refracted");
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[0]->kind, ra::Kind::triangle);
  EXPECT_EQ(named[1]->kind, ra::Kind::sphere);
  EXPECT_EQ(find_family("refracted", ra::Kind::sphere), named[1]);
  EXPECT_EQ(named[0]->sweep, find_family("secondary")->sweep);
  // Named once in the list a user reads.
  const std::string names = family_names();
  EXPECT_EQ(names.find("refracted"), names.rfind("refracted")) << names;
  // Asked for by name with sphere subjects only, the sphere family runs.
  Options o;
  o.families = {"refracted"};
  o.rays = 160;
  const ra::Method* k = ra::find_method("kraus");
  ASSERT_NE(k, nullptr);
  const Report r = run({}, {registry_sphere(*k, Precision::f64)}, o);
  EXPECT_EQ(r.cells.size(), 16u);
  EXPECT_GT(r.total(0).spawned, 0u);
}

}  // namespace
