// `rayaudit info` and `rayaudit convert` run as a user would.
#include <gtest/gtest.h>

#include "run_rayaudit.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "../renderer/formats/obj_test_util.h"

namespace {

using ra::test::Result;
using ra::test::run;

TEST(CliInfo, JsonFields) {
  ra::test::TempDir d;
  // Unit square split in 2 (area 1) plus a point, a line and a missing library.
  const auto f = d.write("sq.obj",
                         "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 2\nvn 0 0 1\nvt 0 0\n"
                         "g side\nusemtl red\nf 1 2 3\nf 1 3 4\np 1\nl 1 2\n");
  const Result r = run("info --json " + f.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["vertices"], 4);
  EXPECT_EQ(j["normals"], 1);
  EXPECT_EQ(j["uvs"], 1);
  EXPECT_EQ(j["triangles"], 2);
  // (0,0,0) (1,0,0) (1,1,0): 0.5; (0,0,0) (1,1,0) (0,1,2): |(1,1,0) x (0,1,2)| / 2
  // = |(2,-2,1)| / 2 = 1.5. Total 2.
  EXPECT_DOUBLE_EQ(j["area"].get<double>(), 2.0);
  EXPECT_EQ(j["bbox"]["min"], nlohmann::json::array({0, 0, 0}));
  EXPECT_EQ(j["bbox"]["max"], nlohmann::json::array({1, 1, 2}));
  EXPECT_EQ(j["groups"], nlohmann::json::array({"side"}));
  EXPECT_EQ(j["materials"], nlohmann::json::array({"red"}));
  EXPECT_EQ(j["skipped"]["p"], 1);
  EXPECT_EQ(j["skipped"]["l"], 1);
  EXPECT_EQ(j["skipped"]["vp"], 0);
  ASSERT_EQ(j["warnings"].size(), 2u);
  EXPECT_EQ(j["warnings"][0], f.string() + ":1: material library 'gone.mtl' not found (its materials get defaults)");
}

TEST(CliInfo, ErrorExitsTwoWithFileAndLine) {
  ra::test::TempDir d;
  const auto f = d.write("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
  const Result r = run("info " + f.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, f.string() + ":3: vertex index 3 is past the end: the file has only 2 vertices\n");
}

TEST(CliInfo, TextModePrintsWarningsToStderr) {
  ra::test::TempDir d;
  const auto f = d.write("w.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n");
  const Result r = run("info " + f.string());
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("warning: " + f.string() + ":4: material 'x' is not defined"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("triangles  1"), std::string::npos) << r.out;
}

TEST(CliConvert, OffToObj) {
  ra::test::TempDir d;
  const auto in = d.write("t.off", "OFF\n4 1 0\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n4 0 1 2 3\n");
  const auto out = d.dir / "t.obj";
  const Result r = run("convert " + in.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const ra::Mesh m = ra::load_obj(out);
  EXPECT_EQ(m.triangles.size(), 2u);
  EXPECT_DOUBLE_EQ(m.area(), 4.0);  // the 2x2 square
  EXPECT_EQ(run("convert " + in.string() + " -o " + (d.dir / "no/such/dir.obj").string()).code, 2);
}

}  // namespace
