// Issue 15 regressions in the renderer library: writes on a full disk,
// thread start-up that falls back, image headers bounded by their file,
// triangulation in linear time, inputs that are not regular files.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>

#include "io/atomic_file.h"
#include "errors.h"
#include "io/full_disk.h"
#include "image.h"
#include "io/input_file.h"
#include "io/json_input.h"
#include "formats/mesh.h"
#include "formats/triangulate.h"
#include "workers.h"

namespace fs = std::filesystem;
using namespace ra;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// An image whose PNG does not compress to nothing (noise-like values).
Image busy_image(int w, int h) {
  Image img(w, h);
  std::uint32_t s = 12345;
  for (auto& v : img.rgb) {
    s = s * 1664525u + 1013904223u;
    v = float(s >> 8) / float(1u << 24);
  }
  return img;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Every image format, on a full disk: an InputError naming the output, the
// good file that was there untouched, no temporary left behind.
TEST(FullDisk, WriteImageFailsAndKeepsTheGoodFile) {
  test::FullDisk disk(16384);
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const Image img = busy_image(200, 200);  // about 120 KB of PNG: more than the room left
  // The good files first (a page each on tmpfs), then the writes that fail.
  for (const char* name : {"out.png", "out16.png", "out.exr"}) std::ofstream(disk.dir() / name) << "good";
  for (const std::string name : {"out.png", "out16.png", "out.exr"}) {
    SCOPED_TRACE(name);
    const fs::path out = disk.dir() / name;
    ASSERT_EQ(slurp(out), "good");
    ImageWriteOptions o;
    o.bits = name == "out16.png" ? 16 : 8;
    const std::string err = error_of([&] { write_image(out, img, o); });
    EXPECT_NE(err.find(out.string()), std::string::npos) << err;
    EXPECT_NE(err.find("cannot write"), std::string::npos) << err;
    EXPECT_EQ(slurp(out), "good");
  }
  for (const auto& e : fs::directory_iterator(disk.dir()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

TEST(FullDisk, WriteTextFailsAndKeepsTheGoodFile) {
  test::FullDisk disk;
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path out = disk.dir() / "out.json";
  std::ofstream(out) << "good";
  const std::string err = error_of([&] { write_text_atomically(out, std::string(100000, 'j')); });
  EXPECT_NE(err.find("No space left on device"), std::string::npos) << err;
  EXPECT_EQ(slurp(out), "good");
}

// The PNG bytes written through our checked path are a PNG OIIO reads back.
TEST(FullDisk, PngWrittenInMemoryReadsBack) {
  const fs::path out = fs::temp_directory_path() / ("rayaudit-png-" + std::to_string(::getpid()) + ".png");
  Image img(3, 2);
  img.at(2, 1)[0] = 1.0f;
  img.at(0, 0)[1] = 0.5f;
  write_image(out, img, {8, false});
  const Image back = read_image(out);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  EXPECT_EQ(back.at(2, 1)[0], 1.0f);
  EXPECT_EQ(back.at(0, 0)[1], 128.0f / 255.0f);
  fs::remove(out);
}

// A name near NAME_MAX (255) still has a temporary that fits.
TEST(AtomicFile, OutputNameNear255CharactersIsWritten) {
  const fs::path dir = fs::temp_directory_path();
  const fs::path out = dir / (std::string(250, 'n') + ".txt");
  write_text_atomically(out, "ok");
  EXPECT_EQ(slurp(out), "ok");
  fs::remove(out);
}

TEST(Workers, AllWorkIsDoneWhateverTheThreadCount) {
  for (int n : {1, 2, 7, 64}) {
    std::atomic<int> next{0}, sum{0};
    const int ran = run_workers(n, [&] {
      for (int i; (i = next.fetch_add(1)) < 1000;) sum += i;
    });
    EXPECT_EQ(sum.load(), 999 * 1000 / 2) << n;
    EXPECT_GE(ran, 1);
    EXPECT_LE(ran, n);
  }
}

// A worker's exception, from whichever thread, reaches the caller after the
// others are joined (escaping a thread, or a joinable std::thread destroyed,
// would abort the process; the asan build found the first).
TEST(Workers, AnExceptionInAnyThreadIsRethrownAfterJoining) {
  std::atomic<int> calls{0};
  EXPECT_THROW(run_workers(4,
                           [&] {
                             if (calls.fetch_add(1) == 0) throw InputError("first");
                           }),
               InputError);
  EXPECT_EQ(calls.load(), 4);
}

TEST(InputFile, DirectoryFifoDeviceAndLoopAreNamed) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-input-" + std::to_string(::getpid()));
  fs::create_directories(d);
  EXPECT_EQ(input_file_problem(d), "is a directory, not a file");
  ASSERT_EQ(::mkfifo((d / "fifo").c_str(), 0600), 0);
  EXPECT_EQ(input_file_problem(d / "fifo"), "is a FIFO, not a file");
  EXPECT_EQ(input_file_problem("/dev/zero"), "is a device, not a file");
  EXPECT_EQ(input_file_problem(d / "absent"), "no such file");
  fs::create_symlink(d / "loop", d / "loop");
  EXPECT_NE(input_file_problem(d / "loop").find("Too many levels of symbolic links"), std::string::npos);
  std::ofstream(d / "file") << "x";
  EXPECT_EQ(input_file_problem(d / "file"), "");
  fs::remove_all(d);
}

// A FIFO given as an image is refused at once rather than read forever.
TEST(ImageHeader, FifoIsRefusedWithoutBlocking) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-fifo-" + std::to_string(::getpid()));
  fs::create_directories(d);
  ASSERT_EQ(::mkfifo((d / "t.png").c_str(), 0600), 0);
  const std::string err = error_of([&] { read_image(d / "t.png"); });
  EXPECT_EQ(err, (d / "t.png").string() + ": is a FIFO, not a file");
  fs::remove_all(d);
}

TEST(JsonInput, DuplicateKeyIsRefusedAtItsLine) {
  const std::string err = error_of([] { parse_json_text("{\"a\": 1,\n \"b\": {\"c\": 1,\n \"c\": 2}}", "f.json"); });
  EXPECT_EQ(err, "f.json:3: key \"c\" given twice in one object");
  // The same key in two objects is fine.
  EXPECT_EQ(parse_json_text("[{\"a\": 1}, {\"a\": 2}]", "f.json").size(), 2u);
}

TEST(JsonInput, OverflowIsReportedWhereTheNumberIs) {
  // The text "1e400" appears first in a key on line 1; the number is on line 3.
  const std::string err = error_of([] { parse_json_text("{\"1e400\": 0,\n \"x\": 1,\n \"y\": 1e400}", "f.json"); });
  EXPECT_EQ(err, "f.json:3: number 1e400 overflows a double");
}

TEST(JsonInput, LibraryPrefixesAreRemoved) {
  const std::string err = error_of([] { parse_json_text("{\n\"a\" 1}", "f.json"); });
  EXPECT_EQ(err.rfind("f.json:2: invalid JSON: syntax error", 0), 0u) << err;
  EXPECT_EQ(err.find("[json.exception"), std::string::npos) << err;
}

// ---- triangulation in linear time (a 10 MB file never takes more than seconds) ----

double area2d(const std::vector<Vec3d>& p, const std::vector<std::array<int, 3>>& tris) {
  double a = 0;
  for (const auto& t : tris) {
    const Vec3d u = p[size_t(t[1])] - p[size_t(t[0])], v = p[size_t(t[2])] - p[size_t(t[0])];
    a += 0.5 * (u.x * v.y - u.y * v.x);
  }
  return a;
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
    double shoelace = 0;
    for (int i = 0; i < n; ++i) {
      const Vec3d& a = p[size_t(i)];
      const Vec3d& b = p[size_t((i + 1) % n)];
      shoelace += a.x * b.y - b.x * a.y;
    }
    std::vector<std::array<int, 3>> out;
    EarClipScratch s;
    EXPECT_FALSE(triangulate_polygon(p.data(), n, out, s)) << n << ": within the work limit";
    ASSERT_EQ(out.size(), size_t(n - 2));
    EXPECT_NEAR(area2d(p, out), 0.5 * shoelace, 1e-12) << n;
  }
}

// A star of 200k corners (half of them reflex): quadratic before (44 s);
// the work limit keeps it linear while every triangle keeps the winding
// count (n - 2 triangles).
TEST(Triangulate, SpikyPolygonOf200kCornersKeepsItsCount) {
  const int n = 200000;
  std::vector<Vec3d> p(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, r = i % 2 ? 0.5 : 1.0;
    p[size_t(i)] = {r * std::cos(t), r * std::sin(t), 0};
  }
  std::vector<std::array<int, 3>> out;
  EarClipScratch s;
  EXPECT_TRUE(triangulate_polygon(p.data(), n, out, s)) << "the work limit was spent: the caller must know";
  EXPECT_EQ(out.size(), size_t(n - 2));
  for (const auto& t : out)
    for (int k : t) ASSERT_TRUE(k >= 0 && k < n);
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
  const Mesh u = parse_obj("v 0 0 0\nv 3 0 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6 7 8\n", "u.obj");
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
  const std::vector<Vec3d> p = {{-1e308, 0, 0}, {0, -1e308, 0}, {1e308, 0, 0}, {0, 1e-300, 0},
                                {-1e307, 1e308, 0}, {-5e307, 1e307, 0}};
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

// Messages quote bad input: control bytes and bytes that are not UTF-8
// come out as \xNN, so the message stays one printable line.
TEST(Located, ControlAndNonUtf8BytesAreEscaped) {
  EXPECT_EQ(located("f.ply", 9, std::string("malformed PLY value '") + '\0' + "'"), "f.ply:9: malformed PLY value '\\x00'");
  EXPECT_EQ(located("a\nb", 0, "x\ry\xff\xfez"), "a\\x0ab: x\\x0dy\\xff\\xfez");
  EXPECT_EQ(located("f", 1, "caf\xc3\xa9 \xe2\x82\xac"), "f:1: caf\xc3\xa9 \xe2\x82\xac");  // UTF-8 kept
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

}  // namespace

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
