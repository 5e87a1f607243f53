// The OBJ edge cases of shared/CORPUS.md, one test each. Expected counts,
// areas and boxes are worked out by hand in the comments, never by the parser.
#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <random>
#include <cmath>
#include <cstring>
#include <numbers>

#include "mesh.h"
#include "obj_test_util.h"

namespace ra {
namespace {

using test::load_error;
using test::load_text;
using test::TempDir;

bool ends_with(const std::string& s, const std::string& t) {
  return s.size() >= t.size() && s.compare(s.size() - t.size(), t.size(), t) == 0;
}
// True if some warning ends with `t` (warnings start with the full path).
bool has_warning(const Mesh& m, const std::string& t) {
  for (auto& w : m.warnings)
    if (ends_with(w, t)) return true;
  return false;
}

const char* kTri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";  // right triangle, legs 1: area 0.5

// The geometry a test expects, worked out by hand in the test's comment:
// counts of v / vt / vn and of triangles, the sum of triangle areas and the
// box of all positions. tol 0: area compared to 4 ulps, bbox exactly.
struct Geometry {
  size_t vertices, uvs, normals, triangles;
  double area;
  Vec3d min, max;
  double tol = 0;
};
void expect_geometry_impl(const Mesh& m, const Geometry& g) {
  EXPECT_EQ(m.positions.size(), g.vertices) << "vertices";
  EXPECT_EQ(m.uvs.size(), g.uvs) << "uvs";
  EXPECT_EQ(m.normals.size(), g.normals) << "normals";
  EXPECT_EQ(m.triangles.size(), g.triangles) << "triangles";
  if (g.tol == 0)
    EXPECT_DOUBLE_EQ(m.area(), g.area) << "area";
  else
    EXPECT_NEAR(m.area(), g.area, g.tol) << "area";
  const Bounds3d b = m.bbox();
  for (int k = 0; k < 3; ++k) {
    if (g.tol == 0) {
      EXPECT_EQ(b.min[k], g.min[k]) << "bbox min axis " << k;
      EXPECT_EQ(b.max[k], g.max[k]) << "bbox max axis " << k;
    } else {
      EXPECT_NEAR(b.min[k], g.min[k], g.tol) << "bbox min axis " << k;
      EXPECT_NEAR(b.max[k], g.max[k], g.tol) << "bbox max axis " << k;
    }
  }
}
// The failure points at the caller's line.
#define EXPECT_GEOMETRY(m, ...)                    \
  do {                                             \
    SCOPED_TRACE("EXPECT_GEOMETRY");               \
    expect_geometry_impl(m, Geometry __VA_ARGS__); \
  } while (0)
// kTri with one triangle: 3 v, area 0.5, box (0,0,0)..(1,1,0).
#define EXPECT_KTRI(m, tris) EXPECT_GEOMETRY(m, {3, 0, 0, tris, 0.5 * (tris), {0, 0, 0}, {1, 1, 0}})

// CORPUS.md Faces: `v`, `v/vt`, `v//vn`, `v/vt/vn`.
TEST(ObjFaces, AllFourFormsGiveTheSameTriangle) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) +
                                  "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                                  "f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//1\nf 1/1/1 2/2/1 3/3/1\n");
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_DOUBLE_EQ(m.area(), 4 * 0.5);
  for (auto& t : m.triangles) {
    EXPECT_EQ(t.v[0], 0);
    EXPECT_EQ(t.v[1], 1);
    EXPECT_EQ(t.v[2], 2);
    EXPECT_EQ(t.gnormal, Vec3d(0, 0, 1));  // (1,0,0) x (0,1,0)
  }
  EXPECT_EQ(m.triangles[0].t[0], -1);
  EXPECT_EQ(m.triangles[0].n[0], -1);
  EXPECT_EQ(m.triangles[1].t[2], 2);
  EXPECT_EQ(m.triangles[1].n[2], -1);
  EXPECT_EQ(m.triangles[2].t[1], -1);
  EXPECT_EQ(m.triangles[2].n[1], 0);
  EXPECT_EQ(m.triangles[3].t[1], 1);
  EXPECT_EQ(m.triangles[3].n[1], 0);
  // 3 v, 3 vt, 1 vn; four copies of kTri's triangle: area 4 x 0.5.
  EXPECT_GEOMETRY(m, {3, 3, 1, 4, 2.0, {0, 0, 0}, {1, 1, 0}});
}

// CORPUS.md Faces: negative (relative) indices, also mixed with positive.
TEST(ObjFaces, NegativeIndicesCountBackFromTheFace) {
  // f -3 -2 -1 after 3 vertices = vertices 1 2 3: legs 2, area 2.
  // Then a 4th vertex; `f 1 -3 4`: -3 with 4 defined is vertex 2, so the
  // triangle (0,0,0) (2,0,0) (0,0,1): area |(2,0,0) x (0,0,1)| / 2 = 1.
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\nv 2 0 0\nv 0 2 0\nf -3 -2 -1\nv 0 0 1\nf 1 -3 4\n");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0].v[0], 0);
  EXPECT_EQ(m.triangles[0].v[2], 2);
  EXPECT_EQ(m.triangles[1].v[1], 1);
  EXPECT_EQ(m.triangles[1].v[2], 3);
  EXPECT_EQ(m.triangles[1].gnormal, Vec3d(0, -1, 0));  // (2,0,0) x (0,0,1) = (0,-2,0)
  // area 2 + 1; box of (0,0,0) (2,0,0) (0,2,0) (0,0,1).
  EXPECT_GEOMETRY(m, {4, 0, 0, 2, 3.0, {0, 0, 0}, {2, 2, 1}});
}

// CORPUS.md Faces: polygons of 4 vertices.
TEST(ObjFaces, QuadIsAFanOfTwo) {
  // Unit square: 2 triangles (0,1,2), (0,2,3), area 1.
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[1].v[0], 0);
  EXPECT_EQ(m.triangles[1].v[1], 2);
  EXPECT_EQ(m.triangles[1].v[2], 3);
  EXPECT_GEOMETRY(m, {4, 0, 0, 2, 1.0, {0, 0, 0}, {1, 1, 0}});
}

// A "U" (counter-clockwise): (0,0) (3,0) (3,2) (2,2) (2,1) (1,1) (1,2) (0,2).
// Area 3x2 minus the 1x1 notch = 5; 6 triangles. A fan from the first vertex
// would cover 7 (its triangle (0,0) (2,2) (2,1) is inverted and outside).
std::string u_shape(double ox, double oy, bool xz_plane) {
  const double pts[8][2] = {{0, 0}, {3, 0}, {3, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::string s;
  char buf[128];
  for (auto& p : pts) {
    if (xz_plane)
      std::snprintf(buf, sizeof buf, "v %.17g 7 %.17g\n", p[0] + ox, p[1] + oy);
    else
      std::snprintf(buf, sizeof buf, "v %.17g %.17g 7\n", p[0] + ox, p[1] + oy);
    s += buf;
  }
  return s + "f 1 2 3 4 5 6 7 8\n";
}

// CORPUS.md Faces: concave polygons (ear clipping, not a fan).
TEST(ObjFaces, ConcavePolygonIsEarClipped) {
  TempDir d;
  const Mesh m = load_text(d, u_shape(0, 0, false));
  ASSERT_EQ(m.triangles.size(), 6u);
  EXPECT_GEOMETRY(m, {8, 0, 0, 6, 5.0, {0, 0, 7}, {3, 2, 7}});
  for (auto& t : m.triangles) EXPECT_EQ(t.gnormal, Vec3d(0, 0, 1)) << "every piece keeps the winding";
}

// CORPUS.md Real bugs: faces lost in triangulation at large coordinates
// (tinyobjloader #295).
TEST(ObjFaces, ConcavePolygonAtLargeCoordinates) {
  // tinyobjloader #295: at 1e8 the projected coordinates lost the polygon.
  // The offsets are integers, so every coordinate and difference is exact.
  TempDir d;
  const Mesh m = load_text(d, u_shape(1e8, -3e8, false));
  EXPECT_GEOMETRY(m, {8, 0, 0, 6, 5.0, {1e8, -3e8, 7}, {1e8 + 3, -3e8 + 2, 7}});
}

// CORPUS.md Faces: concave polygons, in a plane not facing z.
TEST(ObjFaces, ConcavePolygonInAnotherPlane) {
  // (x, y) -> (x, 7, y): winding seen from -y, gnormal (1,0,0) x (0,0,1) = (0,-1,0).
  TempDir d;
  const Mesh m = load_text(d, u_shape(0, 0, true));
  EXPECT_GEOMETRY(m, {8, 0, 0, 6, 5.0, {0, 7, 0}, {3, 7, 2}});
  for (auto& t : m.triangles) EXPECT_EQ(t.gnormal, Vec3d(0, -1, 0));
}

// CORPUS.md Faces: polygons of hundreds of vertices; Text: very long lines.
TEST(ObjFaces, VeryLongLineFaceOf1000Vertices) {
  // Regular 1000-gon of radius 1: area n/2 sin(2 pi / n) = 500 sin(pi/500).
  // Vertices at angles 2 pi i / n: i = 0, 250, 500, 750 are the extremes
  // +-1 on x and y, so the box is (-1,-1,0)..(1,1,0).
  const int n = 1000;
  std::string s;
  char buf[96];
  for (int i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "v %.17g %.17g 0\n", std::cos(2 * std::numbers::pi * i / n),
                  std::sin(2 * std::numbers::pi * i / n));
    s += buf;
  }
  s += "f";
  for (int i = 1; i <= n; ++i) {
    s += ' ';
    s += std::to_string(i);
  }
  TempDir d;
  const Mesh m = load_text(d, s + "\n");
  EXPECT_GEOMETRY(
      m, {size_t(n), 0, 0, size_t(n - 2), 500 * std::sin(std::numbers::pi / 500), {-1, -1, 0}, {1, 1, 0}, 1e-12});
}

// CORPUS.md Faces: mixed forms within one face (accepted, with a warning).
TEST(ObjFaces, MixedFormsDropTheComponentNotOnEveryCorner) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "vt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1/1\n");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0].t[0], -1);  // corner 2 has no vt
  EXPECT_EQ(m.triangles[0].n[1], 0);   // every corner has vn
  EXPECT_TRUE(has_warning(m,
                          "t.obj:6: face mixes vertex forms (v, v/vt, v//vn, v/vt/vn); texture or normal "
                          "indices not on every corner were dropped (1 face)"));
  EXPECT_GEOMETRY(m, {3, 1, 1, 1, 0.5, {0, 0, 0}, {1, 1, 0}});
}

// CORPUS.md Text: `\` line continuation.
TEST(ObjText, LineContinuationJoinsLinesAndKeepsLineNumbers) {
  // v 1 0 0 is split over lines 2-3, the face over 5-6. Line 7's face names
  // vertex 4 of 3: the error must say line 7.
  const std::string text = "v 0 0 0\nv 1 \\\n0 0\nv 0 1 0\nf 1 2 \\\n3\nf 1 2 4\n";
  TempDir d;
  const Mesh m = load_text(d, text.substr(0, text.rfind("f 1 2 4")));
  EXPECT_KTRI(m, 1);
  EXPECT_EQ(load_error(text), "t.obj:7: vertex index 4 is past the end: the file has only 3 vertices");
}

// CORPUS.md Text: comments after values, with `\` line continuation. A
// comment ends at its line end: a `\` inside it does not continue, so the
// next `v` is a statement of its own (it was swallowed silently before).
TEST(ObjText, BackslashInACommentDoesNotContinue) {
  TempDir d;
  // 3 v: (0,0,0) (2,0,0) (0,2,0); legs 2: area 2.
  const Mesh m = load_text(d, "v 0 0 0 # note \\\nv 2 0 0 #\\\r\nv 0 2 0\n# whole-line comment \\\nf 1 2 3\n");
  EXPECT_EQ(m.positions.at(1), Vec3d(2, 0, 0));
  EXPECT_GEOMETRY(m, {3, 0, 0, 1, 2.0, {0, 0, 0}, {2, 2, 0}});
  // The same in a multi-line statement: the continuation stops at the comment.
  const Mesh c = load_text(d, "v 0 0 0\nv 1 \\\n0 0 # c \\\nv 0 1 0\nf 1 2 3\n");
  EXPECT_KTRI(c, 1);
  // Line numbers stay right: the face on line 5 names vertex 4 of 3.
  EXPECT_EQ(load_error("v 0 0 0 # \\\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n"),
            "t.obj:5: vertex index 4 is past the end: the file has only 3 vertices");
}

// CORPUS.md Text: `\` line continuation with CRLF line ends.
TEST(ObjText, ContinuationWithCrlf) {
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\r\nv 1 \\\r\n 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
  EXPECT_EQ(m.positions[1], Vec3d(1, 0, 0));
  EXPECT_KTRI(m, 1);
}

// CORPUS.md Text: CRLF.
TEST(ObjText, CrlfLineEnds) {
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nusemtl red\r\nf 1 2 3\r\n");
  EXPECT_KTRI(m, 1);
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "red");  // no '\r' in the name
  EXPECT_EQ(load_error("v 0 0 0\r\nv 1 0 0\r\nf 1 2 3\r\n"),
            "t.obj:3: vertex index 3 is past the end: the file has only 2 vertices");
}

// Not in CORPUS.md, found with it: CR-only line ends (classic Mac OS) are
// rejected with a message that says so (a lone CR is whitespace, so the
// parser would otherwise report "malformed number 'v'"). Decided in mesh.h.
TEST(ObjText, CrOnlyLineEndsAreRejectedByName) {
  const std::string msg =
      "t.obj:1: the file uses CR-only line ends (classic Mac OS), which are not supported: convert them to LF or CRLF";
  EXPECT_EQ(load_error("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"), msg);
  EXPECT_EQ(load_error("# comment\rv 0 0 0\r"), msg);
  EXPECT_EQ(load_error("\xEF\xBB\xBFv 0 0 0\rv 1 0 0\r"), msg);
  // A stray CR before the line end, and CRLF, are still fine.
  TempDir d;
  EXPECT_KTRI(load_text(d, "v 0 0 0 \r \r\nv 1 0 0\r\r\nv 0 1 0\nf 1 2 3\r"), 1);
}

// CORPUS.md Text: a UTF-8 BOM.
TEST(ObjText, Utf8BomIsSkipped) {
  TempDir d;
  const Mesh m = load_text(d, "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_KTRI(m, 1);
}

// CORPUS.md assimp OBJ/: box_UTF16BE.obj (and other UTF-16 or binary text).
TEST(ObjText, Utf16IsRejected) {
  EXPECT_EQ(load_error(std::string("\xFE\xFF\0v", 4)),
            "t.obj:1: UTF-16 (big-endian BOM) is not supported: convert the file to UTF-8");
  EXPECT_EQ(load_error(std::string("\xFF\xFEv\0", 4)),
            "t.obj:1: UTF-16 (little-endian BOM) is not supported: convert the file to UTF-8");
  EXPECT_EQ(load_error(std::string("v 0 0 0\n\0v", 10)),
            "t.obj:2: NUL byte in a text file (UTF-16 without BOM, or binary?)");
}

// CORPUS.md Text: no trailing newline; Real bugs: the last line dropped
// without a newline (assimp); Grouping: `usemtl` on the last line.
TEST(ObjText, NoTrailingNewlineKeepsTheLastLine) {
  // assimp dropped the last line; here the last line is a face, then a usemtl.
  TempDir d;
  EXPECT_KTRI(load_text(d, std::string(kTri) + "f 1 2 3"), 1);
  // The last vertex on the last line: the box reaches (0,1,0) only through it.
  EXPECT_KTRI(load_text(d, "v 0 0 0\nv 1 0 0\nv 0 1 0"), 0);
  const Mesh m = load_text(d, std::string(kTri) + "f 1 2 3\nusemtl last");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "last");
  EXPECT_KTRI(m, 1);
  const Mesh n = load_text(d, std::string(kTri) + "f 1 2 3\nusemtl last\n");  // the same with a newline
  ASSERT_EQ(n.materials.size(), 1u);
  EXPECT_EQ(n.materials[0].name, "last");
  ASSERT_EQ(n.triangles.size(), 1u);
  EXPECT_EQ(n.triangles[0].material, -1);  // set after the only face
}

// CORPUS.md Text: tabs and runs of spaces, comments after values.
TEST(ObjText, TabsRunsOfSpacesAndComments) {
  TempDir d;
  const Mesh m = load_text(d,
                           "  # leading comment\n"
                           "v\t0   0\t\t0   # origin\n"
                           "\tv 2 0 0#no space before the comment\n"
                           "v    0 2 0 \t \n"
                           "\n"
                           "f  1\t2   3 # face\n");
  EXPECT_EQ(m.positions[1], Vec3d(2, 0, 0));
  EXPECT_GEOMETRY(m, {3, 0, 0, 1, 2.0, {0, 0, 0}, {2, 2, 0}});  // legs 2
}

// CORPUS.md Real bugs: `\` in a name swallowing the next line (assimp).
TEST(ObjText, BackslashInsideANameDoesNotSwallowTheNextLine) {
  // assimp bug: `\` in a name ate the following line. Only `\` right before
  // the line end continues a line.
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "usemtl dir\\name\nf 1 2 3\n");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.materials.at(0).name, "dir\\name");
  EXPECT_KTRI(m, 1);
}

// CORPUS.md Numbers: `1e2`, `-.5`, `+3.E-1`, `.8e-001`; Real bugs:
// leading-dot floats (tinyobjloader #201).
TEST(ObjNumbers, AllForms) {
  // 1e2 = 100, -.5, +3.E-1 = 0.3, .8e-001 = 0.08; 1E2 = 100; 2. = 2.
  TempDir d;
  const Mesh m = load_text(d, "v 1e2 -.5 +3.E-1\nv .8e-001 1E2 2.\nv -0 +0 0.0\n");
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[0], Vec3d(100, -0.5, 0.3));
  EXPECT_EQ(m.positions[1], Vec3d(0.08, 100, 2));
  const Bounds3d b = m.bbox();
  EXPECT_EQ(b.min, Vec3d(-0.0, -0.5, 0));
  EXPECT_EQ(b.max, Vec3d(100, 100, 2));
  EXPECT_GEOMETRY(m, {3, 0, 0, 0, 0.0, {-0.0, -0.5, 0}, {100, 100, 2}});
  // A triangle written only in those forms: (-.5, 0, 0) (1, 0, 0) (-.5, 1, 0),
  // legs 1.5 and 1: area 0.75, box (-0.5,0,0)..(1,1,0). 1e0 = 1, 10e-1 = 1,
  // .0e-001 = 0, +0.E-1 = 0, -.0 = -0, 5e-1 = 0.5.
  const Mesh t = load_text(d, "v -.5 +0.E-1 .0e-001\nv 1e0 -.0 0\nv -5e-1 10e-1 +0\nf 1 2 3\n");
  EXPECT_GEOMETRY(t, {3, 0, 0, 1, 0.75, {-0.5, 0, 0}, {1, 1, 0}});
}

// The parser's fast paths (Clinger's, SWAR digit runs, whole-line masks)
// must give exactly std::from_chars's double. Seeded; prints the seed.
TEST(ObjNumbers, FastPathsMatchFromCharsExactly) {
  const unsigned seed = 20261121;
  std::mt19937_64 rnd(seed);
  std::string text;
  std::vector<std::string> tokens;
  char buf[64];
  for (int i = 0; i < 30000; ++i) {
    const double mag = std::pow(10.0, double(int(rnd() % 40)) - 20.0);
    const double x = (double(rnd() % 2000001) / 1e6 - 1.0) * mag;
    switch (rnd() % 4) {
      case 0:
        std::snprintf(buf, sizeof buf, "%.*f", int(rnd() % 12), x);
        break;
      case 1:
        std::snprintf(buf, sizeof buf, "%.*e", int(rnd() % 18), x);
        break;
      case 2:
        std::snprintf(buf, sizeof buf, "%.*g", int(1 + rnd() % 17), x);
        break;
      default:
        std::snprintf(buf, sizeof buf, "%lld.%0*llu", (long long)(rnd() % 100000000) - 50000000, int(rnd() % 10),
                      (unsigned long long)(rnd() % 10000000000ull));
        break;
    }
    tokens.push_back(buf);
  }
  for (size_t i = 0; i + 3 <= tokens.size(); i += 3)
    text += "v " + tokens[i] + " " + tokens[i + 1] + " " + tokens[i + 2] + "\n";
  const Mesh m = parse_obj(text, "n.obj");
  ASSERT_EQ(m.positions.size(), tokens.size() / 3);
  for (size_t i = 0; i + 3 <= tokens.size(); ++i) {
    double want = 0;
    std::from_chars(tokens[i].data(), tokens[i].data() + tokens[i].size(), want);
    const Vec3d& p = m.positions[i / 3];
    const double got = i % 3 == 0 ? p.x : i % 3 == 1 ? p.y : p.z;
    ASSERT_EQ(0, std::memcmp(&want, &got, sizeof got)) << "seed " << seed << ": '" << tokens[i] << "' gave " << got;
  }
}

// CORPUS.md Numbers: `nan`, `inf`, `1.#IND` (errors: no geometry; the
// message is the expectation). assimp OBJ/: number_formats.obj's '3.1+e2'.
TEST(ObjNumbers, NonFiniteAndMalformedAreErrors) {
  EXPECT_EQ(load_error("v 0 0 0\nv nan 0 0\n"), "t.obj:2: non-finite number 'nan' is not accepted");
  EXPECT_EQ(load_error("v -inf 0 0\n"), "t.obj:1: non-finite number '-inf' is not accepted");
  EXPECT_EQ(load_error("v 0 Infinity 0\n"), "t.obj:1: non-finite number 'Infinity' is not accepted");
  EXPECT_EQ(load_error("v 1.#IND 0 0\n"), "t.obj:1: non-finite number '1.#IND' (MSVC notation) is not accepted");
  EXPECT_EQ(load_error("v 1.#INF 0 0\n"), "t.obj:1: non-finite number '1.#INF' (MSVC notation) is not accepted");
  EXPECT_EQ(load_error("v 1 2 3.1+e2\n"), "t.obj:1: malformed number '3.1+e2'");
  EXPECT_EQ(load_error("\nv 1 x 3\n"), "t.obj:2: malformed number 'x'");
  EXPECT_EQ(load_error("v 1 2 0x10\n"), "t.obj:1: malformed number '0x10'");
  EXPECT_EQ(load_error("v 1 2 +-3\n"), "t.obj:1: malformed number '+-3'");
  EXPECT_EQ(load_error("v 1 2 1e400\n"), "t.obj:1: number out of range '1e400'");
  EXPECT_EQ(load_error("v 0 0 0\nv 1e80 0 0\n"),
            "t.obj:2: v: coordinate 1e+80 has a magnitude above 1e30 (its square would overflow a double's products)");
  EXPECT_EQ(load_error("v 0 -1.5e30 0\n").rfind("t.obj:1: v: coordinate -1.5e+30 has a magnitude above 1e30", 0), 0u);
  EXPECT_EQ(load_error("v 1 2\n"), "t.obj:1: v needs x y z, x y z w or x y z r g b (2 values given)");
}

TEST(ObjNumbers, AbsurdlyLongNumberIsAnError) {
  const std::string digits(10000, '1');
  EXPECT_EQ(load_error("v 0 0 " + digits + "\n"), "t.obj:1: number too long (10000 characters, at most 200)");
  EXPECT_EQ(load_error("v 0 0 1e-400\n"), "t.obj:1: number out of range '1e-400'");  // underflow too
  const std::string zeros = "0." + std::string(10000, '0') + "1";                    // in range, but 10003 characters
  EXPECT_EQ(load_error("v 0 0 " + zeros + "\n"), "t.obj:1: number too long (10003 characters, at most 200)");
}

// CORPUS.md: `v x y z w` (rational weight), `v x y z r g b` (vertex
// colours); assimp OBJ/: cube_with_vertexcolors*.obj.
TEST(ObjVertices, WeightAndColoursAreIgnored) {
  // w is not divided by (only assimp does); the colours are not kept.
  TempDir d;
  const Mesh m = load_text(d, "v 1 2 3 0.5\nv 4 5 6 1 0 0\n");
  EXPECT_EQ(m.positions[0], Vec3d(1, 2, 3));
  EXPECT_EQ(m.positions[1], Vec3d(4, 5, 6));
  // (0,0,0) (2,0,0) (0,2,0), legs 2: area 2. Had w = 0.5 divided, the second
  // vertex would be (4,0,0) and the area 4; had the colours been read as
  // coordinates the box would reach z = 1.
  const Mesh t = load_text(d, "v 0 0 0 1\nv 2 0 0 0.5\nv 0 2 0 0.25 0.5 1\nf 1 2 3\n");
  EXPECT_GEOMETRY(t, {3, 0, 0, 1, 2.0, {0, 0, 0}, {2, 2, 0}});
  EXPECT_EQ(load_error("v 1 2 3 4 5\n"), "t.obj:1: v needs x y z, x y z w or x y z r g b (5 values given)");
  EXPECT_EQ(load_error("v 1 2 3 4 5 6 7 8\n"), "t.obj:1: v: too many values (at most 7)");
}

// CORPUS.md: `vt u v w` (and `vt u`, `vt u v`).
TEST(ObjVertices, TexCoordsWithOneToThreeValues) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "vt 0.5\nvt 0.25 0.75\nvt 0.125 0.5 1\nf 1/1 2/2 3/3\n");
  EXPECT_GEOMETRY(m, {3, 3, 0, 1, 0.5, {0, 0, 0}, {1, 1, 0}});  // the uvs change no geometry
  ASSERT_EQ(m.uvs.size(), 3u);
  EXPECT_EQ(m.uvs[0], (std::array<double, 2>{0.5, 0}));
  EXPECT_EQ(m.uvs[1], (std::array<double, 2>{0.25, 0.75}));
  EXPECT_EQ(m.uvs[2], (std::array<double, 2>{0.125, 0.5}));
  EXPECT_EQ(load_error("vt\n"), "t.obj:1: vt needs 1 to 3 values (none given)");
  EXPECT_EQ(load_error("vt 1 2 3 4\n"), "t.obj:1: vt: too many values (at most 3)");
}

// CORPUS.md: `vp`, `l` and `p` elements; assimp OBJ/: testline, testpoints,
// testmixed.obj.
TEST(ObjElements, PointsLinesAndParamVerticesAreCountedAndSkipped) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "vp 0.5\nvp 0.5 0.5\nl 1 2\nl 1 2 3\nl 3 1\np 1\nf 1 2 3\n");
  EXPECT_EQ(m.skipped.vp, 2);
  EXPECT_EQ(m.skipped.l, 3);
  EXPECT_EQ(m.skipped.p, 1);
  EXPECT_KTRI(m, 1);  // lines and points add no triangles and no area
  // Only lines and points: no triangles, area 0, the box still of the v.
  const Mesh lp = load_text(d, "v -1 0 0\nv 1 2 3\nl 1 2\np 2\n");
  EXPECT_GEOMETRY(lp, {2, 0, 0, 0, 0.0, {-1, 0, 0}, {1, 2, 3}});
}

// CORPUS.md: `g` with several names, `o`, `usemtl` before `o`, `s 1` and
// `s off`, `mtllib` with several files.
TEST(ObjGrouping, ObjectsGroupsSmoothingAndMaterials) {
  TempDir d;
  d.write("a.mtl", "newmtl red\nKd 1 0 0\n");
  d.write("b.mtl", "newmtl blue\nKd 0 0 1\n");
  const Mesh m = load_text(d, std::string(kTri) +
                                  "f 1 2 3\n"               // before anything: -1 everywhere
                                  "mtllib a.mtl   b.mtl\n"  // two libraries
                                  "usemtl blue\n"           // usemtl before o
                                  "o first thing\n"
                                  "g left  right\n"  // two names: one group "left right"
                                  "s 1\n"
                                  "f 1 2 3\n"
                                  "g other\nusemtl red\ns off\n"
                                  "f 1 2 3\n"
                                  "g left right\n"
                                  "f 1 2 3\n");
  ASSERT_EQ(m.triangles.size(), 4u);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "red");  // library order, not use order
  EXPECT_EQ(m.materials[1].name, "blue");
  EXPECT_EQ(m.materials[1].Kd, Vec3d(0, 0, 1));
  EXPECT_EQ(m.objects, (std::vector<std::string>{"first thing"}));
  EXPECT_EQ(m.groups, (std::vector<std::string>{"left right", "other"}));
  const auto& t = m.triangles;
  EXPECT_EQ(t[0].material, -1);
  EXPECT_EQ(m.run_of(0).group, -1);
  EXPECT_EQ(m.run_of(0).object, -1);
  EXPECT_EQ(m.run_of(0).smoothing, 0);
  EXPECT_EQ(t[1].material, 1);
  EXPECT_EQ(m.run_of(1).group, 0);
  EXPECT_EQ(m.run_of(1).object, 0);
  EXPECT_EQ(m.run_of(1).smoothing, 1);
  EXPECT_EQ(t[2].material, 0);
  EXPECT_EQ(m.run_of(2).group, 1);
  EXPECT_EQ(m.run_of(2).smoothing, 0);
  EXPECT_EQ(m.run_of(3).group, 0);
  EXPECT_EQ(m.run_of(3).object, 0);
  EXPECT_EQ(m.runs.size(), 4u);  // every triangle changes group, object or smoothing
  EXPECT_TRUE(m.warnings.empty()) << m.warnings[0];
  EXPECT_KTRI(m, 4);  // four copies of kTri's triangle
}

// CORPUS.md: `s off|0|N`: off and 0 both mean no smoothing group (0), N is
// kept; anything else is an error.
TEST(ObjGrouping, SmoothingOffZeroAndN) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) +
                                  "s 3\nf 1 2 3\n"
                                  "s off\nf 1 2 3\n"
                                  "s 12\nf 1 2 3\n"
                                  "s 0\nf 1 2 3\n"
                                  "s 2147483647 # the largest\nf 1 2 3\n");
  ASSERT_EQ(m.triangles.size(), 5u);
  EXPECT_EQ(m.run_of(0).smoothing, 3);
  EXPECT_EQ(m.run_of(1).smoothing, 0);
  EXPECT_EQ(m.run_of(2).smoothing, 12);
  EXPECT_EQ(m.run_of(3).smoothing, 0);
  EXPECT_EQ(m.run_of(4).smoothing, 2147483647);
  EXPECT_KTRI(m, 5);
  EXPECT_EQ(load_error("s on\n"), "t.obj:1: s needs 'off' or a non-negative group number, found 'on'");
  EXPECT_EQ(load_error("s -1\n"), "t.obj:1: s needs 'off' or a non-negative group number, found '-1'");
}

// CORPUS.md MTL: `newmtl` with leading spaces, names with spaces; assimp
// OBJ/: space_in_material_name.obj, cube_mtllib_after_g.obj.
TEST(ObjMaterials, MtllibAfterUsemtlAndNameWithSpaces) {
  TempDir d;
  d.write("my lib.mtl", "  newmtl  Material with spaces  \nKd 0.5 0.25 0.125\n");
  const Mesh m = load_text(d, std::string(kTri) + "usemtl Material with spaces\nf 1 2 3\nmtllib my lib.mtl\n");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "Material with spaces");
  EXPECT_EQ(m.materials[0].Kd, Vec3d(0.5, 0.25, 0.125));
  EXPECT_EQ(m.triangles[0].material, 0);
  EXPECT_TRUE(m.warnings.empty());
  EXPECT_KTRI(m, 1);
}

// CORPUS.md MTL: a missing .mtl (warn and use a default, do not crash).
TEST(ObjMaterials, MissingLibraryAndUndefinedMaterialAreWarnings) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "mtllib nowhere.mtl\nusemtl ghost\nf 1 2 3\n");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "ghost");
  EXPECT_EQ(m.materials[0].Kd, Vec3d(0.8, 0.8, 0.8));  // the default
  EXPECT_EQ(m.triangles[0].material, 0);
  EXPECT_TRUE(has_warning(m, "t.obj:4: material library 'nowhere.mtl' not found (its materials get defaults)"));
  EXPECT_TRUE(has_warning(m, "t.obj:5: material 'ghost' is not defined (default material used)"));
  EXPECT_KTRI(m, 1);
}

TEST(ObjMaterials, UnknownStatementIsOneWarningPerKeyword) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "curv 0 1 1 2\nfoo\ncurv 0 1 2 3\n");
  ASSERT_EQ(m.warnings.size(), 2u);
  EXPECT_TRUE(has_warning(m, "t.obj:4: unsupported statement 'curv' ignored (2 lines)"));
  EXPECT_TRUE(has_warning(m, "t.obj:5: unsupported statement 'foo' ignored (1 line)"));
}

// CORPUS.md Faces: `f 0/0/0` and indices past the end must be errors with
// the line number; faces with fewer than 3 vertices. (Errors: the message
// is the expected result.)
TEST(ObjErrors, IndexErrorsNameTheFaceLine) {
  const std::string t = kTri;
  EXPECT_EQ(load_error(t + "f 0 1 2\n"), "t.obj:4: vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(load_error(t + "f 0/0/0 1 2\n"), "t.obj:4: vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(load_error(t + "\nf 1 2 4\n"), "t.obj:5: vertex index 4 is past the end: the file has only 3 vertices");
  EXPECT_EQ(load_error(t + "f -4 -2 -1\n"),
            "t.obj:4: relative vertex index -4 reaches before the first one (3 defined before this face)");
  EXPECT_EQ(load_error(t + "vt 0 0\nf 1/2 2/1 3/1\n"),
            "t.obj:5: texture index 2 is past the end: the file has only 1 texture coordinate");
  EXPECT_EQ(load_error(t + "f 1//1 2//1 3//1\n"),
            "t.obj:4: normal index 1 is past the end: the file has only 0 normals");
  EXPECT_EQ(load_error(t + "f 1 2\n"), "t.obj:4: face with 2 vertices (at least 3 needed)");
  EXPECT_EQ(load_error(t + "f\n"), "t.obj:4: face with 0 vertices (at least 3 needed)");
  EXPECT_EQ(load_error(t + "f 1 2 3x\n"), "t.obj:4: malformed face vertex near 'x'");
  EXPECT_EQ(load_error(t + "f 1/ 2 3\n"), "t.obj:4: malformed texture index ''");
  EXPECT_EQ(load_error(t + "f 1 2 99999999999999999999\n"),
            "t.obj:4: vertex index out of range '99999999999999999999'");
}

// An index past the end says which it is, so the user knows what to fix:
// one defined only after the face is a forward reference (not allowed: say
// where it is defined); one never defined says how many the whole file has.
TEST(ObjErrors, ForwardReferenceAndNeverDefinedAreTold) {
  const std::string t = kTri;
  auto forward = [](int face_line, const char* kind, int index, int defined_line, int before) {
    return "t.obj:" + std::to_string(face_line) + ": " + kind + " index " + std::to_string(index) +
           " is defined later, at line " + std::to_string(defined_line) + ": forward references are not allowed (" +
           std::to_string(before) + " defined before this face)";
  };
  // vertex 4 is the `v` on line 6 (line 5 is a vt, which does not count).
  EXPECT_EQ(load_error(t + "f 1 2 4\nvt 0 0\nv 1 1 1\n"), forward(4, "vertex", 4, 6, 3));
  // the face spans lines 4-5 (continuation); vertex 5 is on line 8, after a
  // continued `v` on lines 6-7 (vertex 4).
  EXPECT_EQ(load_error(t + "f 1 2 \\\n5\nv 1 \\\n1 1\nv 2 2 2\n"), forward(4, "vertex", 5, 8, 3));
  EXPECT_EQ(load_error(t + "f 1/1 2/1 3/2\nvt 0 0\nvt 1 1\n"), forward(4, "texture", 1, 5, 0));
  EXPECT_EQ(load_error(t + "vn 0 0 1\nf 1//1 2//1 3//2\nvn 0 0 1\n"), forward(5, "normal", 2, 6, 1));
  // Never defined: the count is the whole file's (4 v, one after the face).
  EXPECT_EQ(load_error(t + "f 1 2 9\nv 1 1 1\n"),
            "t.obj:4: vertex index 9 is past the end: the file has only 4 vertices");
  EXPECT_EQ(load_error("v 0 0 0\nf 1 1 2\n"), "t.obj:2: vertex index 2 is past the end: the file has only 1 vertex");
}

// CORPUS.md Real bugs: heap overflows found by fuzzing in face parsing
// (tinyobjloader #175, assimp OSS-Fuzz): faces cut off at the end of the
// buffer (no newline) give a one-line error, never a read past the end.
TEST(ObjErrors, FaceCutAtTheEndOfTheBuffer) {
  const std::string t = kTri;
  EXPECT_EQ(load_error(t + "f 1 2 3/"), "t.obj:4: malformed texture index ''");
  EXPECT_EQ(load_error(t + "f 1 2 -"), "t.obj:4: malformed vertex index '-'");
  EXPECT_EQ(load_error(t + "f 1 2"), "t.obj:4: face with 2 vertices (at least 3 needed)");
  EXPECT_EQ(load_error(t + "f 1 2 3//"), "t.obj:4: malformed normal index ''");
  TempDir d;
  EXPECT_KTRI(load_text(d, t + "f 1 2 3"), 1);
  EXPECT_KTRI(load_text(d, t + "f 1 2 3 \t"), 1);
}

TEST(ObjErrors, FileLimits) {
  TempDir d;
  const auto p = d.write("big.obj", std::string(20, '\n'));
  try {
    read_file_bytes(p, 10);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(ends_with(e.what(), "big.obj: file is 20 bytes, more than the limit of 10"));
  }
  EXPECT_THROW(load_obj(d.dir / "absent.obj"), InputError);
}

TEST(ObjMeshHelpers, BboxAreaSphere) {
  TempDir d;
  // Triangle (0,0,0) (4,0,0) (0,3,0) plus an unused vertex (0,0,-2):
  // area 6, box (0,0,-2)..(4,3,0), centre (2,1.5,-1); farthest position:
  // all four corners used are at sqrt(4+2.25+1) = sqrt(7.25).
  const Mesh m = load_text(d, "v 0 0 0\nv 4 0 0\nv 0 3 0\nv 0 0 -2\nf 1 2 3\n");
  EXPECT_DOUBLE_EQ(m.area(), 6.0);
  EXPECT_EQ(m.bbox().min, Vec3d(0, 0, -2));
  EXPECT_EQ(m.bbox().max, Vec3d(4, 3, 0));
  const auto s = m.bounding_sphere();
  EXPECT_EQ(s.center, Vec3d(2, 1.5, -1));
  EXPECT_DOUBLE_EQ(s.radius, std::sqrt(7.25));
  EXPECT_TRUE(Mesh{}.bbox().empty());
}

TEST(ObjMeshHelpers, DegenerateTriangleHasZeroNormal) {
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 2\n");
  EXPECT_EQ(m.triangles[0].gnormal, Vec3d(0, 0, 0));
  EXPECT_EQ(m.triangles[1].gnormal, Vec3d(0, 0, 0));
}

// A deterministic OBJ exercising state across chunk boundaries: relative
// and absolute indices, polygons, usemtl / g / o / s changes, continuations.
std::string stress_obj(int n) {
  std::string s = "mtllib none.mtl\n";
  unsigned x = 12345;
  auto rnd = [&] { return (x = x * 1103515245u + 12345u) >> 8; };
  long verts = 0;
  for (int i = 0; i < n; ++i) {
    s += "v " + std::to_string(int(rnd() % 100)) + " " + std::to_string(int(rnd() % 100)) + (i % 7 ? " " : " \\\n") +
         std::to_string(int(rnd() % 100)) + "\n";
    s += "vt 0." + std::to_string(rnd() % 100) + " 0.5\nvn 0 0 1\n";
    ++verts;
    if (i % 97 == 5) s += "usemtl m" + std::to_string(rnd() % 5) + "\n";
    if (i % 131 == 7) s += "g g" + std::to_string(rnd() % 4) + " x\n";
    if (i % 151 == 3) s += "o o" + std::to_string(rnd() % 3) + "\n";
    if (i % 61 == 1) s += "s " + std::to_string(rnd() % 3) + "\n";
    if (verts >= 5) {
      const int k = 3 + int(rnd() % 3);
      s += "f";
      for (int j = 0; j < k; ++j) {
        const long idx = 1 + long(rnd() % verts);
        s += (rnd() % 2) ? " " + std::to_string(idx) + "/" + std::to_string(idx) + "/" + std::to_string(idx)
                         : " " + std::to_string(idx - verts - 1) + "/" + std::to_string(idx - verts - 1) + "/" +
                               std::to_string(idx - verts - 1);
      }
      s += "\n";
    }
    if (i % 211 == 9) s += "l 1 2\np 1\nvp 0.5\n";
  }
  return s;
}

void expect_same(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions, b.positions);
  ASSERT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.uvs, b.uvs);
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    const auto &s = a.triangles[i], &t = b.triangles[i];
    ASSERT_EQ(0, std::memcmp(s.v, t.v, sizeof s.v)) << i;
    ASSERT_EQ(0, std::memcmp(s.n, t.n, sizeof s.n)) << i;
    ASSERT_EQ(0, std::memcmp(s.t, t.t, sizeof s.t)) << i;
    ASSERT_EQ(s.material, t.material) << i;
    ASSERT_EQ(s.gnormal, t.gnormal) << i;
  }
  std::vector<std::string> an, bn;
  for (auto& m : a.materials) an.push_back(m.name);
  for (auto& m : b.materials) bn.push_back(m.name);
  EXPECT_EQ(an, bn);
  EXPECT_EQ(a.runs, b.runs);
  EXPECT_EQ(a.groups, b.groups);
  EXPECT_EQ(a.objects, b.objects);
  EXPECT_EQ(a.skipped.vp, b.skipped.vp);
  EXPECT_EQ(a.skipped.l, b.skipped.l);
  EXPECT_EQ(a.skipped.p, b.skipped.p);
  EXPECT_EQ(a.warnings, b.warnings);
}

TEST(ObjParallel, IdenticalToSerialForAnyThreadCount) {
  const std::string text = stress_obj(3000);
  const Mesh serial = parse_obj(text, "s.obj");
  ASSERT_GT(serial.triangles.size(), 5000u);
  ASSERT_GT(serial.groups.size(), 1u);
  for (int threads : {2, 3, 7, 64}) {
    ObjOptions opt;
    opt.threads = threads;
    opt.parallel_min_bytes = 0;
    SCOPED_TRACE(threads);
    expect_same(serial, parse_obj(text, "s.obj", opt));
  }
}

TEST(ObjParallel, SameErrorAsSerial) {
  std::string text = stress_obj(2000);
  const size_t at = text.size() * 3 / 4;
  const size_t nl = text.find('\n', at);
  text.insert(nl + 1, "f 1 2 0\n");
  const long line = 2 + long(std::count(text.begin(), text.begin() + long(nl), '\n'));
  ObjOptions opt;
  opt.threads = 4;
  opt.parallel_min_bytes = 0;
  std::string serial, parallel;
  try {
    parse_obj(text, "s.obj");
  } catch (const InputError& e) {
    serial = e.what();
  }
  try {
    parse_obj(text, "s.obj", opt);
  } catch (const InputError& e) {
    parallel = e.what();
  }
  EXPECT_EQ(serial, "s.obj:" + std::to_string(line) + ": vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(parallel, serial);
}

// Distinct unsupported keywords: the first ten warned one line each, the
// rest in one line (100k of them printed 100k lines, in quadratic time).
TEST(ObjWarnings, ManyUnsupportedKeywordsAreTenLinesAndACount) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int i = 0; i < 25; ++i) text += "zz" + std::to_string(i) + " 1\nzz" + std::to_string(i) + " 2\n";
  text += "f 1 2 3\n";
  const Mesh m = parse_obj(text, "kw.obj");
  ASSERT_EQ(m.warnings.size(), 11u);
  EXPECT_EQ(m.warnings[0], "kw.obj:4: unsupported statement 'zz0' ignored (2 lines)");
  EXPECT_EQ(m.warnings[10], "kw.obj:24: 15 more unsupported keywords ignored (30 lines)");
}

}  // namespace
}  // namespace ra
