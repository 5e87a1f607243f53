// Polygon triangulation (triangulate.h) in time linear in the polygon's
// size: convex, star, spiky, degenerate and overflowing polygons of up to a
// million corners give n - 2 triangles that tile simple polygons exactly;
// beyond the work limit one warning naming the line; beyond a million
// corners a refusal at the line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "errors.h"
#include "formats/mesh.h"
#include "formats/triangulate.h"

namespace fs = std::filesystem;
using namespace ra;

namespace {

// Twice the signed area of the polygon, by the shoelace formula.
double shoelace2(const std::vector<Vec3d>& p) {
  double s = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec3d &a = p[i], &b = p[(i + 1) % p.size()];
    s += a.x * b.y - b.x * a.y;
  }
  return s;
}

double area2d(const std::vector<Vec3d>& p, const std::vector<std::array<int, 3>>& tris) {
  double a = 0;
  for (const auto& t : tris) {
    const Vec3d u = p[size_t(t[1])] - p[size_t(t[0])], v = p[size_t(t[2])] - p[size_t(t[0])];
    a += 0.5 * (u.x * v.y - u.y * v.x);
  }
  return a;
}

// A star of n corners (every other one reflex) as one OBJ face on line 2+n.
std::string star_obj(int n, int faces) {
  std::string text = "# star\n";
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, r = i % 2 ? 0.5 : 1.0;
    text += "v " + std::to_string(r * std::cos(t)) + " " + std::to_string(r * std::sin(t)) + " 0\n";
  }
  for (int f = 0; f < faces; ++f) {
    text += "f";
    for (int i = 1; i <= n; ++i) text += " " + std::to_string(i);
    text += "\n";
  }
  return text;
}

TEST(Triangulate, ConvexPolygonOf300kCornersIsAFan) {
  const int n = 300000;
  std::vector<Vec3d> p(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    p[size_t(i)] = {std::cos(t), std::sin(t), 0};
  }
  std::vector<std::array<int, 3>> out;
  EarClipScratch s;
  EXPECT_FALSE(triangulate_polygon(p.data(), n, out, s)) << "a convex polygon is within the work limit";
  ASSERT_EQ(out.size(), size_t(n - 2));
  for (int i = 0; i < n - 2; ++i) EXPECT_EQ(out[size_t(i)], (std::array<int, 3>{0, i + 1, i + 2})) << i;
  // Area of the regular n-gon of radius 1: n/2 sin(2 pi / n).
  EXPECT_NEAR(area2d(p, out), 0.5 * n * std::sin(2 * M_PI / n), 1e-9);
}

// A star whose inner corners lie at 1% of its radius: they
// shared one or two cells of a grid over the whole polygon, so every
// spike's ear scanned all of them, the work limit was spent and the fan
// came out 118 times the star's area. The grid over the reflex corners
// alone tiles it exactly: its area, by the shoelace formula.
TEST(Triangulate, StarWithClusteredInnerCornersTilesExactly) {
  for (int n : {1000, 2000, 5000}) {
    std::vector<Vec3d> p(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n, r = i % 2 ? 0.01 : 1.0;
      p[size_t(i)] = {r * std::cos(t), r * std::sin(t), 0};
    }
    const double shoelace = shoelace2(p);
    std::vector<std::array<int, 3>> out;
    EarClipScratch s;
    EXPECT_FALSE(triangulate_polygon(p.data(), n, out, s)) << n << ": within the work limit";
    ASSERT_EQ(out.size(), size_t(n - 2));
    EXPECT_NEAR(area2d(p, out), 0.5 * shoelace, 1e-12) << n;
  }
}

// A star of 200k corners (half of them reflex): quadratic before (44 s);
// the work limit keeps it linear. Cut as a fan or not, each cut takes one
// corner with its two current neighbours, so the triangles' signed areas
// still add up to the polygon's (shoelace): a corner cut twice, skipped,
// or cut with stale neighbours would break the sum.
TEST(Triangulate, SpikyPolygonOf200kCornersKeepsItsCountAndArea) {
  const int n = 200000;
  std::vector<Vec3d> p(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, r = i % 2 ? 0.5 : 1.0;
    p[size_t(i)] = {r * std::cos(t), r * std::sin(t), 0};
  }
  std::vector<std::array<int, 3>> out;
  EarClipScratch s;
  EXPECT_TRUE(triangulate_polygon(p.data(), n, out, s)) << "the work limit was spent: the caller must know";
  ASSERT_EQ(out.size(), size_t(n - 2));
  for (const auto& t : out)
    for (int k : t) ASSERT_TRUE(k >= 0 && k < n);
  EXPECT_NEAR(area2d(p, out), 0.5 * shoelace2(p), 1e-9);
}

// The cut is no longer silent: one warning naming the first such face's
// line, its corner count and how many faces were cut, serial or parallel.
TEST(Triangulate, PolygonBeyondTheWorkLimitIsOneWarningNamingItsLine) {
  const int n = 20000;
  const std::string text = star_obj(n, 3);
  for (int threads : {1, 2}) {
    ObjOptions opt;
    opt.threads = threads;
    opt.parallel_min_bytes = 0;
    const Mesh m = parse_obj(text, "star.obj", opt);
    EXPECT_EQ(m.triangles.size(), size_t(3 * (n - 2)));
    ASSERT_EQ(m.warnings.size(), 1u) << threads;
    EXPECT_EQ(m.warnings[0].rfind("star.obj:" + std::to_string(n + 2) + ": polygon of 20000 corners ", 0), 0u)
        << m.warnings[0];
    EXPECT_NE(m.warnings[0].find("(3 polygons)"), std::string::npos) << m.warnings[0];
  }
  // A concave polygon within the limit: no warning.
  const Mesh u =
      parse_obj("v 0 0 0\nv 3 0 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6 7 8\n", "u.obj");
  EXPECT_EQ(u.triangles.size(), 6u);
  EXPECT_TRUE(u.warnings.empty());
}

// 60k collinear corners (degenerate: no ear at all) took 6.5 s.
TEST(Triangulate, DegeneratePolygonOf60kCornersIsCutAsAFan) {
  const int n = 60000;
  std::vector<Vec3d> p(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) p[size_t(i)] = {double(i), 0, 0};
  std::vector<std::array<int, 3>> out;
  EarClipScratch s;
  triangulate_polygon(p.data(), n, out, s);
  EXPECT_EQ(out.size(), size_t(n - 2));
}

// Extents that overflow (1e308 - -1e308 = inf) must not break the grid of
// reflex corners (the cell of NaN was undefined behaviour).
TEST(Triangulate, OverflowingExtentsStillGiveNMinus2Triangles) {
  const std::vector<Vec3d> p = {{-1e308, 0, 0}, {0, -1e308, 0},     {1e308, 0, 0},
                                {0, 1e-300, 0}, {-1e307, 1e308, 0}, {-5e307, 1e307, 0}};
  std::vector<std::array<int, 3>> out;
  EarClipScratch s;
  triangulate_polygon(p.data(), int(p.size()), out, s);
  ASSERT_EQ(out.size(), p.size() - 2);
  for (const auto& t : out)
    for (int k : t) EXPECT_TRUE(k >= 0 && k < int(p.size()));
}

// A 2 MB face of a million corners (all one vertex): the triangle array's
// growth extrapolated from the few bytes read before the face and asked
// for terabytes (std::bad_alloc naming no file). Now bounded by what the
// rest of the file can hold; the face loads, with the work-limit warning.
TEST(Triangulate, FaceOfAMillionCornersLoadsWithAWarning) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 1000000; ++i) text += " 1";
  text += "\n";
  const Mesh m = parse_obj(text, "million.obj");
  EXPECT_EQ(m.triangles.size(), 999998u);
  EXPECT_LT(m.triangles.capacity(), 2000000u) << "reserved far beyond what the file holds";
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0].rfind("million.obj:4: polygon of 1000000 corners", 0), 0u) << m.warnings[0];
}

// A concave polygon still tiles exactly (a U: 8 corners, area 5).
TEST(Triangulate, ConcaveUStillTilesExactly) {
  const std::vector<Vec3d> p = {{0, 0, 0}, {3, 0, 0}, {3, 2, 0}, {2, 2, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  std::vector<std::array<int, 3>> out;
  EarClipScratch s;
  EXPECT_FALSE(triangulate_polygon(p.data(), 8, out, s));
  ASSERT_EQ(out.size(), 6u);
  for (const auto& t : out) EXPECT_GT(area2d(p, {t}), 0) << t[0] << " " << t[1] << " " << t[2];
  EXPECT_DOUBLE_EQ(area2d(p, out), 5.0);
}

// A face beyond kMaxPolygonCorners is refused at its line: a 20 MB face of
// 9M corners ("1 2 3" repeated) took 1.2 GB and 12 s to triangulate.
TEST(Triangulate, FaceOfMoreThanAMillionCornersIsRefusedAtItsLine) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i <= kMaxPolygonCorners; ++i) text += " 1";
  text += "\n";
  try {
    parse_obj(text, "many.obj");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "many.obj:4: face of more than 1000000 corners (the limit a polygon; split it)");
  }
}

}  // namespace
