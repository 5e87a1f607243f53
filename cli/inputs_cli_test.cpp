// Inputs that are not what a reader expects, run through the real program:
// FIFOs, devices and symlink loops named as such, bytes that are not UTF-8,
// byte-order marks, NaN coordinates, huge names and headers read in linear
// time, truncated textures, teapot patches that are not 16 points.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

// A FIFO as cases CSV or texture is refused at once (it used to block
// forever); `timeout` turns a hang into exit 124.
TEST(InputsCli, FifoAsCasesOrTextureIsRefused) {
  const fs::path fifo = scratch("cases.csv");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto r = run_rayaudit("audit --cases " + fifo.string(), "timeout 60");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, fifo.string() + ": is a FIFO, not a file\n");

  const fs::path tex = scratch("tex.png"), scene = scratch("tex-scene.json");
  fs::remove(tex);
  ASSERT_EQ(::mkfifo(tex.c_str(), 0600), 0);
  std::ofstream(scene) << R"({"objects": [{"mesh": ")" << kScenes << R"(/meshes/quad.obj", "material": {"texture": ")"
                       << tex.string() << "\"}}]}\n";
  r = run_rayaudit("render " + scene.string() + " -o " + scratch("tex.out.png").string(), "timeout 60");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find(tex.string() + ": is a FIFO, not a file"), std::string::npos) << r.err;
}

TEST(InputsCli, MtllibOfADeviceIsNamedAsSuch) {
  const fs::path obj = scratch("dev.obj");
  std::ofstream(obj) << "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const auto r = run_rayaudit("info " + obj.string());
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.err.find(obj.string() + ":1: material library '/dev/zero' is a device, not a file"), std::string::npos)
      << r.err;
}

TEST(InputsCli, SymlinkLoopAsSceneIsOneLine) {
  const fs::path loop = scratch("loop.json");
  fs::remove(loop);
  fs::create_symlink(loop, loop);
  const auto r = run_rayaudit("render " + loop.string() + " -o " + scratch("loop.png").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, loop.string() + ": cannot read: Too many levels of symbolic links\n");
}

// convert used to write `v nan 0 0`, which our own OBJ reader rejects.
TEST(InputsCli, ConvertRefusesANanCoordinate) {
  const fs::path ply = scratch("nan.ply"), out = scratch("nan.obj");
  std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "nan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const auto r = run_rayaudit("convert " + ply.string() + " -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, ply.string() + ":10: vertex 0 has coordinate nan (not finite)\n");
  EXPECT_FALSE(fs::exists(out));
  // Nor a coordinate beyond 1e30, which the OBJ reader refuses too (PLY and OFF).
  std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n1e31 0 0\n0 1 0\n3 0 1 2\n";
  auto big = run_rayaudit("convert " + ply.string() + " -o " + out.string());
  EXPECT_EQ(big.code, 2);
  EXPECT_EQ(big.err.rfind(ply.string() + ":11: vertex 1 has coordinate ", 0), 0u) << big.err;  // 1e31 as a float
  EXPECT_NE(big.err.find("(magnitude above 1e30)\n"), std::string::npos) << big.err;
  EXPECT_FALSE(fs::exists(out));
  const fs::path off = scratch("big.off");
  std::ofstream(off) << "OFF\n3 1 0\n0 0 0\n1e31 0 0\n0 1 0\n3 0 1 2\n";
  big = run_rayaudit("convert " + off.string() + " -o " + out.string());
  EXPECT_EQ(big.code, 2);
  EXPECT_EQ(big.err.rfind(off.string() + ":4: coordinate with a magnitude above 1e30", 0), 0u) << big.err;
  EXPECT_FALSE(fs::exists(out));
}

// A UTF-8 byte-order mark (as spreadsheets write) is not part of the first
// column's name: it used to read as "missing column 'ox'".
TEST(InputsCli, CasesCsvWithAUtf8BomIsRead) {
  const fs::path csv = scratch("bom.csv"), json = scratch("bom.json");
  std::ofstream(csv) << "\xEF\xBB\xBFox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n"
                        "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n";
  const auto r = run_rayaudit("audit --cases " + csv.string() + " --methods moller --json " + json.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(json));
}

// A cases header of 200k columns with a repeat at its end: the repeat search
// compared all pairs (over 20 s). Under a 20 s CPU limit (a bound against
// runaway, not a timing) it answers with the repeated column.
TEST(InputsCli, CasesHeaderOf200kColumnsIsCheckedInLinearTime) {
  const fs::path csv = scratch("wide.csv");
  {
    std::ofstream out(csv);
    out << "ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz";
    for (int i = 0; i < 200000; ++i) out << ",c" << i;
    out << ",c5\n";
  }
  const auto r = run_rayaudit("audit --cases " + csv.string() + " --methods moller", "prlimit --cpu=20 --");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, csv.string() + ":1: column 'c5' appears twice in the header\n");
}

// export-pov copies a scene's texture: a truncated PNG printed libpng's own
// lines (3-4 on stderr, the first naming no file) before the error.
TEST(InputsCli, ExportPovWithATruncatedTextureIsOneLine) {
  const fs::path d = textured_scene_dir("export-trunc");
  std::ofstream(d / "tex.png", std::ios::binary | std::ios::trunc) << "\x89PNG\r\n\x1a\n";
  const auto r = run_rayaudit("export-pov " + (d / "s.json").string() + " -o " + (d / "x.pov").string());
  EXPECT_TRUE(refused(r, (d / "tex.png").string() + ": cannot read texture: "));
  EXPECT_FALSE(fs::exists(d / "x.pov"));
}

// A non-UTF-8 CSV id made the JSON writer throw
// after the work; info read a PLY or a scene as an empty OBJ (exit 0); an
// OBJ reader trusting st_size read /proc files as empty.
TEST(InputsCli, NonUtf8IdsInfoOnNonObjAndProcFiles) {
  const fs::path dir = scratch_dir("non-utf8-ids");
  std::ofstream(dir / "c.csv")
      << "id,ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n\xff\xfex,0,0,5,0,0,-1,-1,-1,0,1,-1,0,0,1,0\n";
  auto r = run_rayaudit("audit --cases " + (dir / "c.csv").string() + " --methods moller --json " +
                        (dir / "o.json").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(slurp(dir / "o.json").find("\"id\": \"\xEF\xBF\xBD\xEF\xBF\xBDx\""), std::string::npos)
      << "replaced, valid UTF-8";
  std::ofstream(dir / "t.ply") << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
  r = run_rayaudit("info " + (dir / "t.ply").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err,
            (dir / "t.ply").string() + ": a ply file: info reads OBJ meshes (rayaudit convert it to OBJ first)\n");
  r = run_rayaudit("info /proc/self/status");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.err.find("/proc/self/status:1: unsupported statement 'Name:'"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// A 10 MB usemtl name was a 10 MB warning line.
TEST(InputsCli, LongMaterialNamesAreQuotedShort) {
  const fs::path obj = scratch("long-usemtl.obj");
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl " << std::string(1000000, 'u') << "\nf 1 2 3\n";
  const auto r = run_rayaudit("info " + obj.string());
  EXPECT_EQ(r.code, 0) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), 1000u);
  EXPECT_NE(r.err.find("... (1000000 bytes)' is not defined"), std::string::npos) << r.err.substr(0, 300);
}

// A non-UTF-8 byte in a file name or a CSV id made the JSON writers
// throw nlohmann's type_error after the work; the bytes are now written as
// U+FFFD and the JSON is valid.
TEST(InputsCli, NonUtf8NamesAndIdsGiveValidJson) {
  const fs::path mesh = scratch("te\xff.obj");
  fs::copy_file(kScenes + "/meshes/tetrahedron.obj", mesh, fs::copy_options::overwrite_existing);
  const fs::path maps = scratch("cm-latin1");
  fs::remove_all(maps);
  auto r = run_rayaudit("crack-maps -o " + maps.string() + " --mesh '" + mesh.string() +
                        "' --methods moller --offsets 1 --size 8");
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(slurp(maps / "crack_maps.json").find("\"name\": \"te\xef\xbf\xbd\""), std::string::npos);

  const fs::path cases = scratch("latin1-id.csv"), out = scratch("latin1-id.json");
  std::ofstream(cases) << "id,ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n"
                          "\xff\xfe\"x,0,0,5,0,0,-1,-1,-1,0,1,-1,0,0,1,0\n";
  r = run_rayaudit("audit --cases " + cases.string() + " --methods moller --json " + out.string());
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(slurp(out).find("\"id\": \"\xef\xbf\xbd\xef\xbf\xbd\\\"x\""), std::string::npos) << slurp(out);
  // A graded answers file whose name is not UTF-8: the subject is named after it.
  const fs::path exported = scratch("latin1-export.csv"), answers = scratch("ans\xff.csv");
  ASSERT_EQ(run_rayaudit("audit --export-cases " + exported.string() + " --families edge --rays 10").code, 0);
  {
    std::ifstream in(exported);
    std::ofstream a(answers);
    a << "id,hit,t\n";
    std::string line;
    std::getline(in, line);  // the stamp
    std::getline(in, line);  // the header
    while (std::getline(in, line)) a << line.substr(0, line.find(',')) << ",false,\n";
  }
  const fs::path graded = scratch("latin1-graded.json");
  r = run_rayaudit("audit --grade '" + answers.string() + "' --cases " + exported.string() + " --json " +
                   graded.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(slurp(graded).find("ans\xef\xbf\xbd"), std::string::npos);
  // report from a directory whose name is not UTF-8: the script opens it.
  const fs::path dir = scratch("d\xff");
  fs::create_directories(dir);
  ASSERT_EQ(
      run_rayaudit("audit --methods moller --families edge --rays 50 --json '" + (dir / "a.json").string() + "'").code,
      0);
  const fs::path rep = scratch("latin1-report");
  r = run_rayaudit("report --audit '" + (dir / "a.json").string() + "' -o " + rep.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(rep / "index.html"));
  fs::remove_all(rep);
}

// `generate teapot` took 1e400 as a bare "stod", accepted malformed
// patches, and tessellated any number of patches at --steps 256 (16.8 GB).
TEST(InputsCli, TeapotIncIsCheckedAndItsWorkBounded) {
  const std::string head = "bicubic_patch { type 1 flatness 0.01 u_steps 5 v_steps 5\n";
  const std::string row = "<1.4, 0, 2.4> <1.4, -0.784, 2.4> <0.784, -1.4, 2.4> <0, -1.4, 2.4>\n";
  const std::string patch = head + row + row + row + row + "}\n";
  struct Case {
    std::string name, text, message;
    int steps;
  };
  const std::vector<Case> cases = {
      {"e.inc",
       head + "<1e400, 0, 2.4> <1.4, -0.784, 2.4> <0.784, -1.4, 2.4> <0, -1.4, 2.4>\n" + row + row + row + "}\n",
       "e.inc:2: number '1e400' is not a finite number within 1e30", 8},
      {"twenty.inc", head + row + row + row + row + row + "}\n",
       "twenty.inc:1: bicubic_patch with 20 control points (16 needed)", 8},
      {"unclosed.inc", head + row + row + row + row, "unclosed.inc:1: bicubic_patch without a closed { ... }", 8},
      {"two.inc", head + "<1,2> " + row + row + row + row + "}\n", "two.inc:2: vector with 2 components (3 needed)", 8},
      {"many.inc",
       [&] {
         std::string t;
         for (int i = 0; i < 100; ++i) t += patch;
         return t;
       }(),
       "many.inc: 100 patches at --steps 256 make 13107200 triangles (about 5242 MB); at most 1048576: a smaller "
       "--steps",
       256},
  };
  const fs::path out = scratch("teapot.obj");
  for (const auto& c : cases) {
    const fs::path inc = scratch(c.name);
    std::ofstream(inc) << c.text;
    const auto r =
        run_rayaudit("generate teapot " + inc.string() + " -o " + out.string() + " --steps " + std::to_string(c.steps));
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_EQ(r.err, scratch("").string() + c.message + "\n");
    EXPECT_FALSE(fs::exists(out));
  }
  // One good patch still tessellates.
  const fs::path good = scratch("good.inc");
  std::ofstream(good) << patch;
  EXPECT_EQ(run_rayaudit("generate teapot " + good.string() + " -o " + out.string()).code, 0);
  // A flat patch, all at one height: v was 0/0, written as -nan, which our
  // own OBJ reader refused; now the output loads.
  const fs::path flat = scratch("flat.inc");
  std::ofstream(flat) << "bicubic_patch { type 1 flatness 0 u_steps 3 v_steps 3\n"
                         "<0,0,0> <1,0,0> <2,0,0> <3,0,0>\n<0,1,0> <1,1,0> <2,1,0> <3,1,0>\n"
                         "<0,2,0> <1,2,0> <2,2,0> <3,2,0>\n<0,3,0> <1,3,0> <2,3,0> <3,3,0>\n}\n";
  auto r = run_rayaudit("generate teapot " + flat.string() + " -o " + out.string() + " --steps 2");
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_EQ(ra::test::slurp(out).find("nan"), std::string::npos);
  r = run_rayaudit("info " + out.string());
  EXPECT_EQ(r.code, 0) << r.all;
  // An OBJ named .png was written without a word; refused as convert refuses it.
  const fs::path png = scratch("teapot.png");
  r = run_rayaudit("generate teapot " + good.string() + " -o " + png.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, png.string() + ": the output must be a .obj file\n");
  EXPECT_FALSE(fs::exists(png));
}

}  // namespace
