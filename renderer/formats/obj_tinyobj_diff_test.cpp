// Differential test: our OBJ loader against tinyobjloader (Debian's rc10) on
// every OBJ of the corpus (ci/fetch-corpus.sh), searched recursively under
// ladder/ (incl. the OFF meshes CGAL ships, converted by `rayaudit convert`),
// assimp-obj/, assimp-invalid/ (assimp's models/invalid/*.obj) and embree/.
//
// For every file: either we reject it, and it is listed in kWeReject with the
// message we give, or we accept it and our triangle count is exactly the one
// counted here from the file's `f` lines (n-2 per n-gon, by a trivial reading
// independent of the parser). Where tinyobj accepts it too: the same vertex
// positions (tinyobj keeps floats, so ours rounded to float must equal them)
// and the same triangle count, unless the file is in kTinyTriangleCount with
// tinyobj's count and the reason. A file tinyobj rejects must be in
// kTinyRejects with the reason. A listed file that no longer differs fails
// too (stale entries hide regressions).
#include <gtest/gtest.h>
#include <tiny_obj_loader.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "../errors.h"
#include "mesh.h"

namespace ra {
namespace {

namespace fs = std::filesystem;

// Files we reject (keyed by path under corpus/), and the end of our message.
const std::map<std::string, std::string> kWeReject = {
    // tinyobj reads garbage from it (no vertices); we say what it is.
    {"assimp-obj/box_UTF16BE.obj", ":1: UTF-16 (big-endian BOM) is not supported: convert the file to UTF-8"},
    // '3.1+e2' is malformed; tinyobj reads 3.1 and drops '+e2'.
    {"assimp-obj/number_formats.obj", ":11: malformed number '3.1+e2'"},
    // assimp's readme: "out-of-range vertex indices" (12 of 8, then -1, 0).
    {"assimp-invalid/malformed.obj", ":23: vertex index 12 is past the end: the file has only 8 vertices"},
    // an `f` without vertices on line 23 (then "non-existent material").
    {"assimp-invalid/malformed2.obj", ":23: face with 0 vertices (at least 3 needed)"},
};

// Files tinyobj rejects (LoadObj returns false), and why.
const std::map<std::string, std::string> kTinyRejects = {
    // rc10 fails on the index 0 of `f 0 7 8 5` (its only hard error for
    // faces); we fail earlier, at the 12 of line 23.
    {"assimp-invalid/malformed.obj", "tinyobj: zero face index is an error"},
};

// Files where tinyobj's triangle count differs from n-2 per n-gon (which
// ours gives, checked above by a count from the `f` lines): tinyobj's count
// and why. rc10's ear clipping (tiny_obj_loader.h, exportGroupsToShape)
// decides whether a corner is convex by the sign of cross x area, where
// "area" is that of the triangle (v0, v1, origin) in the projection plane,
// not the polygon's winding; so for a concave polygon (or one that the
// origin makes look concave) it rejects real ears, and after a full round
// without an ear it stops and silently drops the rest of the polygon.
const std::map<std::string, std::pair<size_t, std::string>> kTinyTriangleCount = {
    // 934 + 10 = 944 triangles: the 936-vertex face gives tinyobj 234 of 934
    {"assimp-obj/box_longline.obj", {244, "936-vertex face: tinyobj's ear clipping stops early (234 of 934)"}},
    // one concave 66-gon: 64 triangles, tinyobj 44
    {"assimp-obj/concave_polygon.obj", {44, "concave 66-gon: tinyobj's ear clipping stops early (44 of 64)"}},
    {"assimp-obj/space_in_material_name.obj", {44, "the same concave 66-gon as concave_polygon.obj (44 of 64)"}},
};

fs::path corpus_root() {
  const char* c = std::getenv("RAYAUDIT_CACHE");
  const char* h = std::getenv("HOME");
  return (c ? fs::path(c) : fs::path(h ? h : ".") / ".cache/rayaudit") / "corpus";
}

std::string key_of(const fs::path& f) { return f.lexically_relative(corpus_root()).generic_string(); }

std::vector<fs::path> corpus_objs() {
  std::vector<fs::path> out;
  for (const char* sub : {"ladder", "assimp-obj", "assimp-invalid", "embree"}) {
    std::error_code ec;
    for (auto& e : fs::recursive_directory_iterator(corpus_root() / sub, ec))
      if (e.is_regular_file() && e.path().extension() == ".obj") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The triangles a file's faces make, n-2 per n-gon, by the plainest reading:
// physical lines (CR dropped) joined where one ends in `\` and holds no `#`,
// cut at `#`, split at whitespace; a statement whose first word is `f` with
// n >= 3 more words adds n-2.
size_t triangles_by_hand(const std::string& text) {
  std::vector<std::string> statements;
  std::string cur, line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool cont = !line.empty() && line.back() == '\\' && line.find('#') == std::string::npos;
    if (cont) line.pop_back();
    cur += line + " ";
    if (!cont) statements.push_back(cur), cur.clear();
  }
  if (!cur.empty()) statements.push_back(cur);
  size_t tris = 0;
  for (auto& s : statements) {
    std::istringstream words(s.substr(0, s.find('#')));
    std::string w;
    if (!(words >> w) || w != "f") continue;
    size_t n = 0;
    while (words >> w) ++n;
    if (n >= 3) tris += n - 2;
  }
  return tris;
}

TEST(ObjVsTinyobj, TrianglesByHandCountsPolygons) {
  // the helper itself: a triangle, a quad, a pentagon split by `\`, a
  // comment, CRLF, an `l` and a 2-vertex `f` (no triangles): 1 + 2 + 3.
  EXPECT_EQ(triangles_by_hand("f 1 2 3\r\nf 1 2 3 4 # c d e\nf 1 2 \\\n3 4 5\nl 1 2 3\nf 1 2\n# f 1 2 3\n"), 6u);
}

TEST(ObjVsTinyobj, EveryCorpusFile) {
  const auto files = corpus_objs();
  if (files.size() < 10) GTEST_SKIP() << "corpus missing under " << corpus_root() << ": run ci/fetch-corpus.sh first";
  int compared = 0;
  std::set<std::string> seen;
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    const std::string key = key_of(f);
    seen.insert(key);
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    const bool tiny_ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, f.c_str(),
                                          (f.parent_path().string() + "/").c_str(), true);
    Mesh m;
    std::string our_err;
    try {
      m = load_obj(f);
    } catch (const InputError& e) {
      our_err = e.what();
    }
    if (kTinyRejects.count(key))
      EXPECT_FALSE(tiny_ok) << "listed as rejected by tinyobj: " << kTinyRejects.at(key);
    else
      EXPECT_TRUE(tiny_ok) << "tinyobj rejects it and kTinyRejects does not say why: " << err;
    if (kWeReject.count(key)) {
      EXPECT_EQ(our_err, f.string() + kWeReject.at(key));
      continue;
    }
    ASSERT_EQ(our_err, "");
    EXPECT_EQ(m.triangles.size(), triangles_by_hand(slurp(f))) << "ours against n-2 per n-gon";
    if (!tiny_ok) continue;
    ++compared;
    ASSERT_EQ(attrib.vertices.size(), 3 * m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(attrib.vertices[3 * i + size_t(k)], float(m.positions[i][k])) << "vertex " << i;
    size_t tiny_tris = 0;
    for (auto& s : shapes) tiny_tris += s.mesh.num_face_vertices.size();
    if (kTinyTriangleCount.count(key)) {
      const auto& [count, why] = kTinyTriangleCount.at(key);
      EXPECT_EQ(tiny_tris, count) << why;
      EXPECT_NE(tiny_tris, m.triangles.size()) << "listed as differing but does not: " << why;
    } else {
      EXPECT_EQ(tiny_tris, m.triangles.size());
    }
  }
  EXPECT_GE(compared, 25);
  for (auto* list : {&kWeReject, &kTinyRejects})
    for (auto& [key, why] : *list) EXPECT_TRUE(seen.count(key)) << "listed but not in the corpus: " << key;
  for (auto& [key, v] : kTinyTriangleCount) EXPECT_TRUE(seen.count(key)) << "listed but not in the corpus: " << key;
}

// The corpus files with hand-derived geometry (counts, area, box).
TEST(ObjVsTinyobj, HandCheckedCorpusFiles) {
  const fs::path root = corpus_root();
  if (!fs::exists(root / "ladder/cube_poly_cgal.obj"))
    GTEST_SKIP() << "corpus missing under " << root << ": run ci/fetch-corpus.sh first";
  {
    // CGAL's cube_poly.off via rayaudit convert: the cube [-1,1]^3 as 2
    // triangles + 5 quads: 2 + 5 x 2 = 12 triangles, area 6 faces x 4 = 24.
    const Mesh m = load_obj(root / "ladder/cube_poly_cgal.obj");
    EXPECT_EQ(m.positions.size(), 8u);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_DOUBLE_EQ(m.area(), 24.0);
    EXPECT_EQ(m.bbox().min, Vec3d(-1, -1, -1));
    EXPECT_EQ(m.bbox().max, Vec3d(1, 1, 1));
  }
  {
    // assimp's invalid/empty.obj: 0 bytes, accepted as an empty mesh (tinyobj too).
    const Mesh m = load_obj(root / "assimp-invalid/empty.obj");
    EXPECT_EQ(m.positions.size(), 0u);
    EXPECT_EQ(m.triangles.size(), 0u);
    EXPECT_EQ(m.area(), 0.0);
    EXPECT_TRUE(m.bbox().empty());
  }
}

// CGAL's OFF meshes on real data: the converted OBJ has the vertex count of
// the OFF header and n-2 triangles per OFF face (read here from the .off).
TEST(ObjVsTinyobj, OffConvertedByUsMatchesTheOffFile) {
  const fs::path root = corpus_root();
  int checked = 0;
  for (const char* mesh : {"elephant", "bunny00", "cube_poly"}) {
    const fs::path off = root / "off" / (std::string(mesh) + ".off");
    const fs::path obj = root / "ladder" / (std::string(mesh) + "_cgal.obj");
    if (!fs::exists(off) || !fs::exists(obj)) continue;
    SCOPED_TRACE(off.string());
    // OFF: "OFF", then "nv nf ne" (comments and blank lines skipped), nv
    // vertex lines, nf face lines "n i1 .. in".
    std::istringstream in(slurp(off));
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) {
      l = l.substr(0, l.find('#'));
      if (l.find_first_not_of(" \t\r") != std::string::npos) lines.push_back(l);
    }
    ASSERT_GE(lines.size(), 2u);
    size_t nv = 0, nf = 0;
    std::istringstream(lines[1]) >> nv >> nf;
    ASSERT_EQ(lines.size(), 2 + nv + nf);
    size_t tris = 0;
    for (size_t i = 2 + nv; i < lines.size(); ++i) {
      size_t n = 0;
      std::istringstream(lines[i]) >> n;
      tris += n - 2;
    }
    const Mesh m = load_obj(obj);
    EXPECT_EQ(m.positions.size(), nv);
    EXPECT_EQ(m.triangles.size(), tris);
    ++checked;
  }
  if (checked == 0)
    GTEST_SKIP() << "no OFF meshes under " << root / "off"
                 << ": run ci/fetch-corpus.sh first";
  EXPECT_EQ(checked, 3);
}

}  // namespace
}  // namespace ra

namespace ra {
namespace {

// The parallel parse on real files: identical triangles to the serial one.
TEST(ObjParallelCorpus, SameAsSerial) {
  const auto files = corpus_objs();
  if (files.size() < 10) GTEST_SKIP() << "corpus missing under " << corpus_root() << ": run ci/fetch-corpus.sh first";
  ObjOptions par;
  par.threads = 3;
  par.parallel_min_bytes = 0;
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    if (kWeReject.count(key_of(f))) continue;
    const Mesh a = load_obj(f), b = load_obj(f, par);
    ASSERT_EQ(a.positions, b.positions);
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    for (size_t i = 0; i < a.triangles.size(); ++i) {
      const auto &s = a.triangles[i], &t = b.triangles[i];
      ASSERT_TRUE(std::equal(s.v, s.v + 3, t.v) && std::equal(s.n, s.n + 3, t.n) && std::equal(s.t, s.t + 3, t.t) &&
                  s.material == t.material && s.gnormal == t.gnormal)
          << "triangle " << i;
    }
    EXPECT_EQ(a.runs, b.runs);
    EXPECT_EQ(a.groups, b.groups);
    EXPECT_EQ(a.warnings, b.warnings);
  }
}

}  // namespace
}  // namespace ra
