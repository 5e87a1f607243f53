// The real rayaudit program, run as a user runs it: exit codes, messages,
// and no output file on failure.
#include <gtest/gtest.h>

#include "run_rayaudit.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>
#include <string>

#include <nlohmann/json.hpp>

#include "image.h"

namespace fs = std::filesystem;

namespace {

using ra::test::Result;
using ra::test::run;

fs::path temp_dir() {
  fs::path d = fs::temp_directory_path() / ("rayaudit-cli-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

TEST(Cli, MissingSceneExits2AndWritesNothing) {
  const fs::path out = temp_dir() / "x.png";
  const Result r = run("render missing.json -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("missing.json"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line: " << r.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, RendersTheShippedSceneToAPng) {
  const fs::path out = temp_dir() / "sphere.png";
  const Result r = run(std::string("render ") + RAYAUDIT_SOURCE_DIR + "/scenes/sphere-on-plane.json -o " +
                       out.string() + " --width 64 --height 48");
  ASSERT_EQ(r.code, 0) << r.out;
  const ra::Image img = ra::read_image(out);
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 48);
  // The centre of the image is the red sphere: red dominates.
  const float* c = img.at(32, 24);
  EXPECT_GT(c[0], c[1] + 0.1f);
  // No temporary file is left beside the output.
  for (const auto& e : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

TEST(Cli, BadSceneExits2WithFileAndPath) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "bad.json") << R"({"objects": [{"sphere": {"radius": -1}}]})";
  const Result r = run("render " + (dir / "bad.json").string() + " -o " + (dir / "bad.png").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("bad.json: /objects/0/sphere/radius: must be greater than 0"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "bad.png"));
}

// The documents' method names and the modern references', by kind: the CLI's names are a contract.
const std::vector<std::string> kTriangleMethods = {"angles", "cramer",     "areas",   "triple", "sameside",
                                                   "moller", "watertight", "baldwin", "exact"};
const std::vector<std::string> kSphereMethods = {"kraus", "codeproject", "codeproject-fixed", "stable"};

TEST(Cli, UnknownMethodExits2ListingTheValidOnes) {
  const fs::path out = temp_dir() / "m.png";
  const Result r = run(std::string("render ") + RAYAUDIT_SOURCE_DIR + "/scenes/sphere-on-plane.json -o " +
                       out.string() + " --method nosuch");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line: " << r.out;
  for (const auto& name : kTriangleMethods) EXPECT_NE(r.out.find(name), std::string::npos) << name;
  for (const auto& name : kSphereMethods) EXPECT_NE(r.out.find(name), std::string::npos) << name;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, MethodsJsonListsNineTriangleFourSphereAndOnePlaneMethod) {
  const auto r = ra::test::run_rayaudit("methods --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_array());
  std::map<std::string, std::vector<std::string>> by_kind;
  for (const auto& m : j) {
    ASSERT_TRUE(m.contains("name") && m.contains("kind") && m.contains("source")) << m.dump();
    EXPECT_FALSE(m["source"].get<std::string>().empty()) << m.dump();
    by_kind[m["kind"].get<std::string>()].push_back(m["name"].get<std::string>());
  }
  EXPECT_EQ(by_kind["triangle"], kTriangleMethods);
  EXPECT_EQ(by_kind["sphere"], kSphereMethods);
  EXPECT_EQ(by_kind["plane"].size(), 1u);
  EXPECT_EQ(by_kind.size(), 3u);
}

// The table names, after the registry, the peers the audit grades by name
// and the whole tracers --tracers takes; the JSON above stays the registry.
TEST(Cli, MethodsTableAlsoNamesPeersAndTracers) {
  const auto r = ra::test::run_rayaudit("methods");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto peers_at = r.out.find("PEERS"), tracers_at = r.out.find("TRACERS");
  ASSERT_NE(peers_at, std::string::npos) << r.out;
  ASSERT_NE(tracers_at, std::string::npos) << r.out;
  EXPECT_GT(peers_at, r.out.find("watertight"));
  for (const char* peer : {"\nembree ", "\nembree-robust ", "\ncgal-epick "})
    EXPECT_NE(r.out.find(peer, peers_at), std::string::npos) << peer << "\n" << r.out;
  for (const char* tracer : {"bvh", "embree-robust", "cgal-aabb"})
    EXPECT_NE(r.out.find(tracer, tracers_at), std::string::npos) << tracer;
}

// Every method by name, in both precisions, with culling: each render
// succeeds and writes an image of the asked size in which something was hit
// (not one uniform colour). Triangle methods render the doc002 tetrahedron
// (a mesh), sphere methods the sphere on a plane. `--method NAME` may come
// before SCENE.
TEST(Cli, RendersWithEveryMethodInBothPrecisionsAndWithCulling) {
  const fs::path dir = temp_dir();
  const std::string scene = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes/sphere-on-plane.json";
  const std::string mesh_scene = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes/doc002-tetrahedron.json";
  std::vector<std::pair<std::string, std::string>> cases;  // method, scene
  for (const auto& name : kTriangleMethods) cases.emplace_back(name, mesh_scene);
  for (const auto& name : kSphereMethods) cases.emplace_back(name, scene);
  for (const auto& [name, scene_file] : cases)
    for (const char* precision : {"float", "double"}) {
      const fs::path out = dir / (name + "-" + precision + ".png");
      const Result r = run("render --method " + name + " " + scene_file + " -o " + out.string() +
                           " --width 32 --height 24 --cull --precision " + precision);
      EXPECT_EQ(r.code, 0) << name << " " << precision << ": " << r.out;
      ASSERT_TRUE(fs::exists(out)) << out;
      const ra::Image img = ra::read_image(out);
      EXPECT_EQ(img.width, 32);
      EXPECT_EQ(img.height, 24);
      bool uniform = true;
      for (std::size_t i = 3; i < img.rgb.size(); ++i) uniform = uniform && img.rgb[i] == img.rgb[i % 3];
      EXPECT_FALSE(uniform) << name << " " << precision << ": nothing was hit";
    }
  const Result two = run("render " + scene + " -o " + (dir / "two.png").string() + " --method kraus --method stable");
  EXPECT_EQ(two.code, 2);
  EXPECT_NE(two.out.find("two sphere methods"), std::string::npos) << two.out;
  const Result bad = run("render " + scene + " -o " + (dir / "p.png").string() + " --precision half");
  EXPECT_EQ(bad.code, 2);
  EXPECT_FALSE(fs::exists(dir / "p.png"));
}

TEST(Cli, UsageErrorsExit2AndHelpExits0) {
  EXPECT_EQ(run("render").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(run("render --help").code, 0);
  EXPECT_EQ(run("methods --help").code, 0);
  const Result v = run("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_NE(v.out.find("rayaudit"), std::string::npos);
}

TEST(Cli, UnknownCommandIsNamed) {
  const auto r = ra::test::run_rayaudit("frobnicate");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown command 'frobnicate'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("render"), std::string::npos) << "lists the commands: " << r.err;
}

TEST(Cli, NumberOverflowInASceneNamesFileAndLine) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "big.json") << "{\"objects\": [\n  {\"sphere\": {\"center\": [0, 0, 1e999]}}]}";
  const fs::path out = dir / "big.png";
  const auto r = ra::test::run_rayaudit("render " + (dir / "big.json").string() + " -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("big.json:2: number 1e999 overflows a double"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, ConvertRefusesAnOutputThatIsNotObj) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "t.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  auto r = ra::test::run_rayaudit("convert " + (dir / "t.off").string() + " -o " + (dir / "t.stl").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(dir / "t.stl"));
  r = ra::test::run_rayaudit("convert " + (dir / "t.off").string() + " -o " + (dir / "t.obj").string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "t.obj"));
}

TEST(Cli, NonSquareSppIsRefused) {
  const Result r = run(std::string("render ") + RAYAUDIT_SOURCE_DIR + "/scenes/sphere-on-plane.json -o " +
                       (temp_dir() / "spp.png").string() + " --spp 3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--spp"), std::string::npos) << r.out;
}

}  // namespace
