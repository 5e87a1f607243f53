// Issue 15 regressions through the real program: full disk, threads the
// system refuses, work and destinations checked first, inputs that are not
// files, options that used to be accepted silently.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/full_disk.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::one_line;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

const std::string kScenes = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes";

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-reliab-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

// AddressSanitizer reserves terabytes of address space: tests that limit it
// with prlimit --as cannot run under the asan preset.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#define SKIP_IF_SANITIZED() \
  if (kSanitized) GTEST_SKIP() << "prlimit --as and AddressSanitizer do not mix"

TEST(ReliabilityCli, RenderOnAFullDiskExits2AndKeepsTheGoodPng) {
  ra::test::FullDisk disk;
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path out = disk.dir() / "out.png";
  std::ofstream(out) << "good";
  // 400 x 300 of the pyramid scene is an 18 KB PNG; about 8 KB are free.
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json -o " + out.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, out.string() + ": cannot write: No space left on device\n");
  EXPECT_EQ(slurp(out), "good");
}

TEST(ReliabilityCli, InfoThreadsBeyond1024IsRefused) {
  const auto r = run_rayaudit("info " + kScenes + "/meshes/quad.obj --threads 100000");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
}

// Under a 2 GB address-space limit 1024 threads' stacks cannot all be
// made: the work goes on with the threads that could start, and the result
// is the one a single thread gives (it used to abort, exit 134).
TEST(ReliabilityCli, AuditWith1024ThreadsUnderAMemoryLimitFallsBack) {
  SKIP_IF_SANITIZED();
  const fs::path many = scratch("audit-1024.json"), one = scratch("audit-1.json");
  const auto r = run_rayaudit("audit --rays 5000 --threads 1024 --json " + many.string(), "prlimit --as=2000000000 --");
  ASSERT_EQ(r.code, 0) << r.all;
  ASSERT_EQ(run_rayaudit("audit --rays 5000 --threads 1 --json " + one.string()).code, 0);
  EXPECT_EQ(slurp(many), slurp(one));
}

TEST(ReliabilityCli, RenderWith1024ThreadsUnderAMemoryLimitFallsBack) {
  SKIP_IF_SANITIZED();
  const fs::path many = scratch("r-1024.png"), one = scratch("r-1.png");
  const std::string scene = kScenes + "/doc000-pyramid.json --width 64 --height 48";
  const auto r = run_rayaudit("render " + scene + " --threads 1024 -o " + many.string(), "prlimit --as=2000000000 --");
  ASSERT_EQ(r.code, 0) << r.all;
  ASSERT_EQ(run_rayaudit("render " + scene + " --threads 1 -o " + one.string()).code, 0);
  EXPECT_EQ(slurp(many), slurp(one));
}

// Audit JSON is identical for 1, 2 and 7 threads over every method and family.
TEST(ReliabilityCli, AuditJsonIsIdenticalFor1And2And7Threads) {
  std::string first;
  for (int n : {1, 2, 7}) {
    const fs::path j = scratch("audit-t" + std::to_string(n) + ".json");
    ASSERT_EQ(run_rayaudit("audit --rays 2000 --threads " + std::to_string(n) + " --json " + j.string()).code, 0);
    if (first.empty()) first = slurp(j);
    else EXPECT_EQ(slurp(j), first) << n << " threads";
  }
  EXPECT_GT(first.size(), 1000u);
}

// A missing output directory is found before a 16384 x 16384 render, not after.
TEST(ReliabilityCli, RenderChecksTheDestinationBeforeTheWork) {
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 16384 --height 16384 -o /nonexistent-dir/x.png");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "/nonexistent-dir/x.png: output directory does not exist\n");
}

TEST(ReliabilityCli, AbsurdRenderIsRefusedWithItsSize) {
  const fs::path out = scratch("absurd.png");
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 16384 --height 16384 --spp 256 -o " +
                              out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "16384x16384 at 256 spp is 68719476736 primary rays, more than the limit of 4294967296 "
            "(16384x16384 at 16 spp): lower --width, --height or --spp\n");
  EXPECT_FALSE(fs::exists(out));
}

TEST(ReliabilityCli, VersionEndsWithANewline) {
  const auto r = run_rayaudit("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, std::string("rayaudit ") + RAYAUDIT_VERSION + "\n");
}

// What a command prints must arrive: on a full disk (/dev/full) every
// command that writes to stdout says so in one line with exit 2; it exited
// 0 and left `info --json > f` empty.
TEST(ReliabilityCli, StdoutOnAFullDiskIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  for (const std::string& args : std::vector<std::string>{"--version", "methods", "methods --json",
                                                           "info " + kScenes + "/meshes/tetrahedron.obj",
                                 "info --json " + kScenes + "/meshes/tetrahedron.obj"}) {
    const auto r = run_rayaudit(args + " >/dev/full");
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err, "rayaudit: cannot write to standard output: No space left on device\n") << args;
  }
}

// PNG options with an EXR output were ignored (the file identical with or
// without them); refused as other ignored options are.
TEST(ReliabilityCli, PngOptionsWithAnExrAreRefused) {
  const fs::path out = scratch("png_opts.exr");
  for (const char* opt : {"--srgb", "--bits 16"}) {
    const auto r = run_rayaudit("render " + kScenes + "/meshes/tetrahedron.obj -o " + out.string() + " --width 8 --height 8 " + opt);
    EXPECT_EQ(r.code, 2) << opt;
    EXPECT_EQ(r.err, out.string() + ": --srgb and --bits apply to PNG; an EXR holds the linear float values\n") << opt;
    EXPECT_FALSE(fs::exists(out));
  }
}

// A 1e-5 quad as a bare .obj: POV-Ray's 1e-4 minimum depth drops every
// camera hit, so the image is black; the render says why (it said nothing).
// The same quad at unit size renders without a warning.
TEST(ReliabilityCli, ASceneSmallerThanPovsWindowsIsWarnedAbout) {
  const fs::path obj = scratch("tiny_quad.obj"), unit = scratch("unit_quad.obj"), out = scratch("tiny.png");
  std::ofstream(obj) << "v 0 0 0\nv 1e-5 0 0\nv 0 1e-5 0\nv 1e-5 1e-5 0\nf 1 2 4 3\n";
  std::ofstream(unit) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n";
  auto r = run_rayaudit("render " + obj.string() + " -o " + out.string() + " --width 8 --height 8");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: " + obj.string() + ": the scene is 1.41e-05 across"), std::string::npos) << r.err;
  r = run_rayaudit("render " + unit.string() + " -o " + out.string() + " --width 8 --height 8");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

// A regular file where the output's directory should be is named as such
// (it read "output directory does not exist").
TEST(ReliabilityCli, OutputUnderARegularFileIsNamed) {
  const fs::path file = scratch("notes.txt");
  std::ofstream(file) << "x\n";
  const fs::path out = file / "x.png";
  const auto r = run_rayaudit("render " + kScenes + "/meshes/tetrahedron.obj -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, out.string() + ": output directory " + file.string() + " is not a directory\n");
}

TEST(ReliabilityCli, ExportPovWithIniEqualToOutputIsRefused) {
  const fs::path pov = scratch("same.pov");
  std::ofstream(pov) << "precious";
  const auto r = run_rayaudit("export-pov " + kScenes + "/doc000-pyramid.json -o " + pov.string() + " --ini " +
                              pov.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, pov.string() + ": --ini names the same file as -o\n");
  EXPECT_EQ(slurp(pov), "precious");
}

TEST(ReliabilityCli, SeedOf2To64IsRefusedNotSaturated) {
  const auto r = run_rayaudit("audit --rays 10 --seed 18446744073709551616");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("at most 18446744073709551615"), std::string::npos) << r.err;
  EXPECT_EQ(run_rayaudit("audit --rays 10 --methods moller --seed 18446744073709551615").code, 0);
}

// A FIFO as cases CSV or texture is refused at once (it used to block
// forever); `timeout` turns a hang into exit 124.
TEST(ReliabilityCli, FifoAsCasesOrTextureIsRefused) {
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

TEST(ReliabilityCli, MtllibOfADeviceIsNamedAsSuch) {
  const fs::path obj = scratch("dev.obj");
  std::ofstream(obj) << "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const auto r = run_rayaudit("info " + obj.string());
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.err.find(obj.string() + ":1: material library '/dev/zero' is a device, not a file"), std::string::npos)
      << r.err;
}

TEST(ReliabilityCli, SymlinkLoopAsSceneIsOneLine) {
  const fs::path loop = scratch("loop.json");
  fs::remove(loop);
  fs::create_symlink(loop, loop);
  const auto r = run_rayaudit("render " + loop.string() + " -o " + scratch("loop.png").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, loop.string() + ": cannot read: Too many levels of symbolic links\n");
}

TEST(ReliabilityCli, OutputNameNear255CharactersIsWritten) {
  const fs::path out = scratch(std::string(246, 'n') + ".png");
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 8 --height 8 -o " + out.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(out));
}

// convert used to write `v nan 0 0`, which our own OBJ reader rejects.
TEST(ReliabilityCli, ConvertRefusesANanCoordinate) {
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

}  // namespace

namespace {

// A UTF-8 byte-order mark (as spreadsheets write) is not part of the first
// column's name: it used to read as "missing column 'ox'".
TEST(ReliabilityCli, CasesCsvWithAUtf8BomIsRead) {
  const fs::path csv = scratch("bom.csv"), json = scratch("bom.json");
  std::ofstream(csv) << "\xEF\xBB\xBFox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n"
                        "0.25,0.25,1,0,0,-1,0,0,0,1,0,0,0,1,0\n";
  const auto r = run_rayaudit("audit --cases " + csv.string() + " --methods moller --json " + json.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(json));
}

}  // namespace

namespace {

// A legal 16384 x 16384 texture (a 32 KB PNG: 1-bit grey, all zero, deflated)
// that a process limited to 3 GB cannot hold: one line naming the file, not
// a bare std::bad_alloc.
// A 32 KB 1-bit PNG of 16384 x 16384 peaked at 1.24 GB (a float copy of
// every channel, then 3 floats a texel) before "not enough memory" under
// 4 GB. Textures keep the file's own 8 bits now (256 MB here): it renders
// under 3 GB, and under 700 MB (OIIO's libraries map ~500 MB) it is refused
// from its size before the buffer is allocated, naming the file.
TEST(ReliabilityCli, Texture16384OneBitLoadsInItsOwnBytesOrIsRefusedUpFront) {
  SKIP_IF_SANITIZED();
  const std::string tex = std::string(RAYAUDIT_SOURCE_DIR) + "/cli/testdata/texture-16384-1bit.png";
  const fs::path scene = scratch("bigtex.json");
  std::ofstream(scene) << R"({"objects": [{"mesh": ")" << kScenes << R"(/meshes/quad.obj", "material": {"texture": ")"
                       << tex << "\"}}]}\n";
  const std::string args = "render " + scene.string() + " --width 8 --height 8 -o " + scratch("bigtex.png").string();
  rusage before{};
  ::getrusage(RUSAGE_CHILDREN, &before);
  const auto ok = run_rayaudit(args, "prlimit --as=3000000000 --");
  EXPECT_EQ(ok.code, 0) << ok.all;
  rusage after{};
  ::getrusage(RUSAGE_CHILDREN, &after);
  // Largest child so far: this run, unless an earlier child was larger.
  if (after.ru_maxrss > before.ru_maxrss) {
    EXPECT_LT(after.ru_maxrss, 700L * 1024) << "peak resident KB";
  }
  const auto r = run_rayaudit(args, "prlimit --as=700000000 --");
  if (r.code == 0) GTEST_SKIP() << "OpenImageIO's libraries map less here: 700 MB holds the texture";
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind(tex + ": texture of 16384x16384 needs 256 MB to read, but only ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("not enough memory"), std::string::npos) << r.err;
}

// Under an address-space limit too low for OpenImageIO's libraries (they
// map ~430 MB and start threads as they load), every image command aborted,
// segfaulted or hung at 410-450 MB, or blamed a valid texture up to ~520 MB.
// The module is refused before it is loaded, in one line.
TEST(ReliabilityCli, ImageModuleUnderALowAddressSpaceLimitIsOneLine) {
  SKIP_IF_SANITIZED();
  for (const char* limit : {"300000000", "410000000", "430000000", "450000000", "500000000"}) {
    const auto r = run_rayaudit("render " + kScenes + "/bump-height.json --width 8 --height 8 -o " +
                                    scratch("lowas.png").string(),
                                std::string("prlimit --as=") + limit + " --");
    EXPECT_EQ(r.code, 2) << limit << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << limit << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("rayaudit_image.so: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("MB of address space to load"), std::string::npos) << r.err;
  }
}

// An existing output that is not a regular file is refused before any work:
// the renamed temporary would have replaced it (run as root, `--json
// /dev/full` turned the device into a file). A FIFO stands in for a device.
TEST(ReliabilityCli, OutputThatIsAFifoIsRefusedNotReplaced) {
  const fs::path fifo = scratch("out-fifo.png");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& args : std::vector<std::string>{
           "render " + kScenes + "/doc000-pyramid.json --width 8 --height 8 -o " + fifo.string(),
           "audit --rays 100 --families edge --json " + fifo.string()}) {
    const auto r = run_rayaudit(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.all;
    EXPECT_EQ(r.err, fifo.string() + ": is a FIFO, not a file: not replaced\n") << args;
    EXPECT_TRUE(fs::is_fifo(fifo)) << "replaced by " << args;
  }
  fs::remove(fifo);
}

// A scene with a mesh and a texture in a fresh directory: its files are
// the inputs the output tests below name as outputs.
fs::path textured_scene_dir(const std::string& name) {
  const fs::path d = scratch(name);
  fs::remove_all(d);
  fs::create_directories(d);
  fs::copy_file(kScenes + "/meshes/quad.obj", d / "m.obj");
  fs::copy_file(kScenes + "/textures/uv-grid.png", d / "tex.png");
  std::ofstream(d / "s.json") << R"({"width": 8, "height": 8, "objects": [{"mesh": "m.obj", "material": {"texture": "tex.png"}}]})"
                              << "\n";
  return d;
}

// An output that is one of the command's inputs (the scene, the mesh or
// texture it references, the cases CSV) is refused before the work: the
// rename replaced the input (`render s.json -o
// tex.png`, `export-pov --ini s.json`, `audit --cases c.csv --json c.csv`).
TEST(ReliabilityCli, OutputThatIsAnInputIsRefusedAndTheInputKept) {
  const fs::path d = textured_scene_dir("out-is-input");
  const fs::path cases = d / "c.csv";
  ASSERT_EQ(run_rayaudit("audit --export-cases " + cases.string() + " --families edge --rays 10").code, 0);
  fs::create_symlink(d / "tex.png", d / "link.png");
  const std::string s = (d / "s.json").string();
  struct Case {
    std::string args;
    fs::path input;
  };
  for (const Case& c : std::vector<Case>{
           {"render " + s + " -o " + (d / "tex.png").string(), d / "tex.png"},
           {"render " + s + " -o " + (d / "link.png").string(), d / "tex.png"},
           {"export-pov " + s + " -o " + (d / "x.pov").string() + " --ini " + s, d / "s.json"},
           {"audit --cases " + cases.string() + " --methods moller --json " + cases.string(), cases}}) {
    const std::string before = slurp(c.input);
    const auto r = run_rayaudit(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find("is also an input of this command"), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(slurp(c.input), before) << "replaced by " << c.args;
  }
  EXPECT_FALSE(fs::exists(d / "x.pov"));
  EXPECT_TRUE(fs::is_symlink(d / "link.png"));
}

// Two outputs of one command on one path: the later replaced the earlier
// (`--json X --csv X`; an --ini named like the texture export-pov copies).
TEST(ReliabilityCli, TwoOutputsOnOnePathAreRefused) {
  const fs::path d = textured_scene_dir("two-outputs");
  const std::string same = (d / "same").string();
  for (const std::string& args : std::vector<std::string>{
           "audit --rays 50 --families edge --methods moller --json " + same + " --csv " + same,
           "export-pov " + (d / "s.json").string() + " -o " + (d / "x.pov").string() + " --ini " +
               (d / "x-tex0.png").string()}) {
    const auto r = run_rayaudit(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find("is named as two outputs of this command"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(same));
  EXPECT_FALSE(fs::exists(d / "x.pov"));
  EXPECT_FALSE(fs::exists(d / "x-tex0.png"));
}

// crack-maps names every map before the work: a --mesh named like the
// built-in sphere would share its maps' names (one of each pair lost), and a
// name longer than the file system takes failed after the work, leaving a
// partial directory. Both are refused first, and no directory is left.
TEST(ReliabilityCli, CrackMapsRefusesCollidingAndOverlongNamesBeforeTheWork) {
  const fs::path d = scratch("crack-names");
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  std::ofstream(d / "sphere.obj") << tetra;
  const std::string long_stem(248, 'm');
  std::ofstream(d / (long_stem + ".obj")) << tetra;
  const std::string cm = (d / "cm").string();
  const auto a = run_rayaudit("crack-maps -o " + cm + " --methods moller --offsets 1 --size 8 --mesh " +
                              (d / "sphere.obj").string());
  EXPECT_EQ(a.code, 2) << a.all;
  EXPECT_TRUE(one_line(a.err)) << a.err;
  EXPECT_NE(a.err.find("sphere-moller-1.png: two maps would have this name"), std::string::npos) << a.err;
  const auto b = run_rayaudit("crack-maps -o " + cm + " --methods moller --offsets 1 --size 8 --mesh " +
                              (d / (long_stem + ".obj")).string());
  EXPECT_EQ(b.code, 2) << b.all;
  EXPECT_TRUE(one_line(b.err)) << b.err;
  EXPECT_NE(b.err.find("file name too long"), std::string::npos) << b.err;
  EXPECT_FALSE(fs::exists(cm)) << "left behind";
}

// A cases header of 200k columns with a repeat at its end: the repeat search
// compared all pairs (over 20 s). Under a 20 s CPU limit (a bound against
// runaway, not a timing) it answers with the repeated column.
TEST(ReliabilityCli, CasesHeaderOf200kColumnsIsCheckedInLinearTime) {
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

// A golden manifest claiming 16384x16384 for an 8x8 golden: the golden's
// size is compared first, not after a 3.3 GB render of the claimed size
// (which a 1 GB address-space limit turns into a failed allocation).
TEST(ReliabilityCli, GoldenSizeIsComparedBeforeRenderingTheManifestsSize) {
  SKIP_IF_SANITIZED();
  const fs::path root = scratch("golden-size");
  fs::remove_all(root);
  fs::create_directories(root / "scenes");
  fs::create_directories(root / "golden");
  std::ofstream(root / "scenes" / "t.json") << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}}]})"
                                             << "\n";
  ASSERT_EQ(run_rayaudit("golden bless t --root " + root.string()).code, 0);
  std::string manifest = slurp(root / "golden" / "manifest.json");
  for (const char* key : {"\"width\": ", "\"height\": "}) {
    const auto at = manifest.find(key) + std::string(key).size();
    manifest.replace(at, manifest.find_first_of(",\n", at) - at, "16384");
  }
  std::ofstream(root / "golden" / "manifest.json") << manifest;
  const auto r = run_rayaudit("golden check --root " + root.string() + " --diff-dir " + (root / "d").string(),
                              "prlimit --as=1000000000 --");
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.all.find("but the manifest says 16384x16384"), std::string::npos) << r.all;
}

// The JSON reader records a line for every value of a golden manifest: it
// counted each from the start of the file (2,000 entries took 12.8 s, 100k
// hours). 20,000 entries, the last with a misspelt key, are read within a
// CPU limit linear reading meets many times over, the error at its line.
TEST(ReliabilityCli, ManifestOf20kEntriesIsReadInLinearTime) {
  SKIP_IF_SANITIZED();
  const fs::path root = scratch("golden-lines");
  fs::remove_all(root);
  fs::create_directories(root / "scenes");
  fs::create_directories(root / "golden");
  std::ofstream(root / "scenes" / "t.json") << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}}]})"
                                             << "\n";
  ASSERT_EQ(run_rayaudit("golden bless t --root " + root.string()).code, 0);
  const nlohmann::json m = nlohmann::json::parse(slurp(root / "golden" / "manifest.json"));
  nlohmann::json many = m;
  many["goldens"] = nlohmann::json::array();
  for (int i = 0; i < 20000; ++i) {
    nlohmann::json e = m["goldens"][0];
    e["name"] = "t" + std::to_string(i);
    e["scene"] = "scenes/t" + std::to_string(i) + ".json";  // each its own scene and image, as bless writes them
    e["image"] = "golden/t" + std::to_string(i) + ".png";
    many["goldens"].push_back(e);
  }
  many["goldens"].back()["widht"] = 8;
  const std::string text = many.dump(2);
  const std::size_t key = text.rfind("\"widht\"");
  ASSERT_NE(key, std::string::npos);
  const long line = 1 + long(std::count(text.begin(), text.begin() + std::ptrdiff_t(key), '\n'));
  std::ofstream(root / "golden" / "manifest.json") << text;
  const fs::path manifest = root / "golden" / "manifest.json";
  const auto r = run_rayaudit("golden check --root " + root.string(), "prlimit --cpu=10 --");
  EXPECT_EQ(r.code, 2) << r.all.substr(0, 300);
  EXPECT_EQ(r.err.rfind(manifest.string() + ":" + std::to_string(line) + ": ", 0), 0u) << r.err.substr(0, 300);
  EXPECT_TRUE(one_line(r.err)) << r.err.substr(0, 300);
}

// A render whose image buffers exceed the memory left is refused before
// the work with its estimate (it died of a bare std::bad_alloc after 37 s).
TEST(ReliabilityCli, RenderBeyondTheMemoryLimitIsRefusedWithAnEstimate) {
  SKIP_IF_SANITIZED();
  const fs::path out = scratch("huge.png");
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 16384 --height 16384 -o " +
                                  out.string(),
                              "prlimit --as=2000000000 --");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind("render: 16384x16384 needs about 6144 MB for its image buffers, but only ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// An empty item in a list option was dropped (`--offsets 1,,2`), and an
// empty list meant "all" (`--methods ''`, `--families ,`): both refused.
TEST(ReliabilityCli, ListOptionsWithAnEmptyItemAreRefused) {
  const fs::path out = scratch("list.json");
  struct Case {
    std::string args, says;
  };
  for (const Case& c : std::vector<Case>{
           {"audit --rays 5 --families edge,,vertex --json " + out.string(), "--families: empty item in the list 'edge,,vertex'"},
           {"audit --rays 5 --families , --json " + out.string(), "--families: empty item in the list ','"},
           {"audit --rays 5 --methods moller, --json " + out.string(), "--methods: empty item in the list 'moller,'"},
           {"audit --rays 5 --precision float, --json " + out.string(), "--precision: empty item in the list 'float,'"},
           {"audit --rays 5 --methods '' --json " + out.string(), "--methods: empty list"},
           {"crack-maps -o " + scratch("cm-list").string() + " --offsets 1,,2", "--offsets: empty item in the list '1,,2'"}}) {
    const auto r = run_rayaudit(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(scratch("cm-list")));
}

// export-pov copies a scene's texture: a truncated PNG printed libpng's own
// lines (3-4 on stderr, the first naming no file) before the error.
TEST(ReliabilityCli, ExportPovWithATruncatedTextureIsOneLine) {
  const fs::path d = textured_scene_dir("export-trunc");
  std::ofstream(d / "tex.png", std::ios::binary | std::ios::trunc) << "\x89PNG\r\n\x1a\n";
  const auto r = run_rayaudit("export-pov " + (d / "s.json").string() + " -o " + (d / "x.pov").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind((d / "tex.png").string() + ": cannot read texture: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(d / "x.pov"));
}

// report: its audit input named as its report.json output is refused before
// the script runs; stage times of nan, -5 or with a NUL are refused at their
// line (they were drawn, or failed as a Python traceback).
TEST(ReliabilityCli, ReportRefusesItsInputAsOutputAndBadStageTimes) {
  const fs::path d = scratch("report-in-out");
  fs::remove_all(d);
  fs::create_directories(d / "rep");
  const fs::path audit = d / "rep" / "report.json";
  ASSERT_EQ(run_rayaudit("audit --rays 50 --families edge --methods moller --json " + audit.string()).code, 0);
  const std::string before = slurp(audit);
  auto r = run_rayaudit("report --audit " + audit.string() + " -o " + (d / "rep").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, audit.string() + ": is also an input of this command (" + audit.string() +
                       "): it would be replaced; choose another output\n");
  EXPECT_EQ(slurp(audit), before);
  EXPECT_FALSE(fs::exists(d / "rep" / "index.html"));
  for (const std::string& stage : {std::string("build\tnan\n"), std::string("build\t-5\n"), std::string("build\t1\0x\n", 10)}) {
    std::ofstream(d / "st.tsv", std::ios::binary) << stage;
    r = run_rayaudit("report --audit " + audit.string() + " --stages " + (d / "st.tsv").string() + " -o " +
                     (d / "out").string());
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind((d / "st.tsv").string() + ":1: ", 0), 0u) << r.err;
  }
  EXPECT_FALSE(fs::exists(d / "out"));
}

// compare --random --out a/b/c created the missing parents; every other
// command refuses an output whose parent directory does not exist.
TEST(ReliabilityCli, CompareRandomOutWithAMissingParentIsRefused) {
  const fs::path d = scratch("random-out");
  fs::remove_all(d);
  fs::create_directories(d);
  const auto r = run_rayaudit("compare --random 1 --out " + (d / "a" / "b").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, (d / "a" / "b").string() + ": its parent directory does not exist\n");
  EXPECT_FALSE(fs::exists(d / "a"));
}

}  // namespace

// `audit --json ""` wrote nothing and exited 0; every
// option given an empty value is refused by name before any work.
TEST(ReliabilityCli, EmptyOptionValuesAreRefusedByName) {
  const fs::path dir = scratch("empty-values");
  fs::create_directories(dir);
  const std::string scene = kScenes + "/doc002-tetrahedron.json";
  const std::pair<std::string, std::string> cases[] = {
      {"audit --methods moller --families edge --rays 10 --json ''", "--json"},
      {"audit --methods moller --families edge --rays 10 --csv ''", "--csv"},
      {"audit --methods moller --families edge --rays 10 --export-cases ''", "--export-cases"},
      {"render " + scene + " -o ''", "--output"},
      {"compare " + scene + " --width 8 --height 8 --diff ''", "--diff"},
      {"convert " + kScenes + "/meshes/quad.obj -o ''", "--output"},
      {"golden check --root " + std::string(RAYAUDIT_SOURCE_DIR) + " --diff-dir '' doc002-tetrahedron", "--diff-dir"},
      {"render '' -o " + (dir / "x.png").string(), "scene"},
  };
  for (const auto& [args, flag] : cases) {
    const auto r = run_rayaudit(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(flag + ": empty value"), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

// `golden check --diff-dir ROOT/golden` replaced the
// golden it compared against with this render (the next check passed);
// --json naming a diff image lost the render; `golden bless A BAD` rewrote
// A's image and failed on BAD, leaving the manifest stale.
TEST(ReliabilityCli, GoldenOutputsNeverReplaceInputsAndBlessIsAllOrNothing) {
  const fs::path root = scratch("golden-io");
  fs::remove_all(root);
  fs::create_directories(root / "scenes");
  fs::create_directories(root / "out");
  std::ofstream(root / "scenes" / "t.json") << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}}]})"
                                             << "\n";
  ASSERT_EQ(run_rayaudit("golden bless t --root " + root.string()).code, 0);
  // A golden that differs from the render: a check fails and writes its images.
  std::ofstream(root / "scenes" / "t.json") << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 0.5}}]})"
                                             << "\n";
  const std::string golden = slurp(root / "golden" / "t.png"), manifest = slurp(root / "golden" / "manifest.json");
  auto r = run_rayaudit("golden check t --root " + root.string() + " --diff-dir " + (root / "golden").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("t.png: is also an input of this command"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(root / "golden" / "t.png"), golden);
  EXPECT_FALSE(fs::exists(root / "golden" / "t.diff.png"));

  r = run_rayaudit("golden check t --root " + root.string() + " --diff-dir " + (root / "out").string() + " --json " +
                   (root / "out" / "t.png").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_NE(r.err.find("is named as two outputs of this command"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(root / "out"));

  std::ofstream(root / "scenes" / "zbad.json") << R"({"objects": [{"mesh": "meshes/nosuch.obj"}]})" << "\n";
  r = run_rayaudit("golden bless t zbad --root " + root.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_NE(r.err.find("zbad.json: /objects/0/mesh: file not found"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(root / "golden" / "t.png"), golden) << "rewritten although the bless failed";
  EXPECT_EQ(slurp(root / "golden" / "manifest.json"), manifest);
  fs::remove_all(root);
}

// A second precision for --export-cases was dropped
// silently (a file of double cases, exit 0); `--version extra` exited 0.
TEST(ReliabilityCli, ExportCasesWithTwoPrecisionsAndVersionWithAnArgumentAreRefused) {
  const fs::path out = scratch("two-precisions.csv");
  auto r = run_rayaudit("audit --export-cases " + out.string() + " --precision float,double --rays 10");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, "--precision: --export-cases takes one precision (float or double), got 'float,double'\n");
  EXPECT_FALSE(fs::exists(out));
  r = run_rayaudit("audit --export-cases " + out.string() + " --precision float --rays 10");
  EXPECT_EQ(r.code, 0) << r.all;
  r = run_rayaudit("--version extra");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_TRUE(r.out.empty());
  fs::remove(out);
}

// An OBJ read through its memory map was not noted as an
// input, so `crack-maps --mesh` naming one of its own maps overwrote it.
TEST(ReliabilityCli, CrackMapsMeshThatIsOneOfItsMapsIsRefused) {
  const fs::path dir = scratch("cm-mesh-input");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path mesh = dir / "sphere-moller-1.png";
  fs::copy_file(kScenes + "/meshes/tetrahedron.obj", mesh);
  const std::string before = slurp(mesh);
  const auto r = run_rayaudit("crack-maps -o " + dir.string() + " --mesh " + mesh.string() +
                              " --methods moller --offsets 1 --size 8");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("sphere-moller-1.png: is also an input of this command"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(mesh), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

// A non-UTF-8 CSV id made the JSON writer throw
// after the work; info read a PLY or a scene as an empty OBJ (exit 0); an
// OBJ reader trusting st_size read /proc files as empty.
TEST(ReliabilityCli, NonUtf8IdsInfoOnNonObjAndProcFiles) {
  const fs::path dir = scratch("f31");
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "c.csv") << "id,ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n\xff\xfex,0,0,5,0,0,-1,-1,-1,0,1,-1,0,0,1,0\n";
  auto r = run_rayaudit("audit --cases " + (dir / "c.csv").string() + " --methods moller --json " + (dir / "o.json").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(slurp(dir / "o.json").find("\"id\": \"\xEF\xBF\xBD\xEF\xBF\xBDx\""), std::string::npos) << "replaced, valid UTF-8";
  std::ofstream(dir / "t.ply") << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
  r = run_rayaudit("info " + (dir / "t.ply").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, (dir / "t.ply").string() + ": a ply file: info reads OBJ meshes (rayaudit convert it to OBJ first)\n");
  r = run_rayaudit("info /proc/self/status");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.err.find("/proc/self/status:1: unsupported statement 'Name:'"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// An audit JSON with a UTF-8 BOM passed the C++ checks and
// ended in a 13-line Python traceback; report.py reads it as utf-8-sig.
TEST(ReliabilityCli, ReportReadsAnAuditJsonWithABom) {
  const fs::path dir = scratch("report-bom");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path audit = dir / "a.json";
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 20 --json " + audit.string()).code, 0);
  std::ofstream(dir / "bom.json") << "\xEF\xBB\xBF" << slurp(audit);
  const auto r = run_rayaudit("report --audit " + (dir / "bom.json").string() + " -o " + (dir / "rep").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(dir / "rep" / "index.html"));
  fs::remove_all(dir);
}

// An image beside a compare JSON that PIL cannot open ended
// the report in a 13-line traceback; it is one line naming the image.
TEST(ReliabilityCli, ReportWithAnUnreadableCompareImageIsOneLine) {
  const fs::path dir = scratch("report-f40");
  fs::remove_all(dir);
  fs::create_directories(dir / "cmp");
  const fs::path audit = dir / "a.json";
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 20 --json " + audit.string()).code, 0);
  std::ofstream(dir / "cmp" / "x.json") << R"({"width": 8, "height": 8, "differing": 0, "identical": true, "differences": []})";
  std::ofstream(dir / "cmp" / "x-pov.png") << "not a png\n";
  const auto r = run_rayaudit("report --audit " + audit.string() + " --compare " + (dir / "cmp").string() + " -o " +
                              (dir / "rep").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind((dir / "cmp" / "x-pov.png").string() + ": not a readable image (", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir / "rep"));
  fs::remove_all(dir);
}

// A 10 MB usemtl name was a 10 MB warning line.
TEST(ReliabilityCli, LongMaterialNamesAreQuotedShort) {
  const fs::path obj = scratch("long-usemtl.obj");
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl " << std::string(1000000, 'u') << "\nf 1 2 3\n";
  const auto r = run_rayaudit("info " + obj.string());
  EXPECT_EQ(r.code, 0) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), 1000u);
  EXPECT_NE(r.err.find("... (1000000 bytes)' is not defined"), std::string::npos) << r.err.substr(0, 300);
}

// `golden check /elsewhere/x.json` checked ROOT/scenes/x.json
// and named that file; a path outside scenes/ is refused as such, and an
// absolute path inside it is its scene.
TEST(ReliabilityCli, GoldenCheckOfAPathOutsideScenesIsNamedAsSuch) {
  const std::string root = RAYAUDIT_SOURCE_DIR;
  auto r = run_rayaudit("golden check /tmp/any/where/x.json --root " + root);
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err.rfind("/tmp/any/where/x.json: not a scene under ", 0), 0u) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  r = run_rayaudit("golden check " + root + "/scenes/doc000-pyramid.json --root " + root + " --diff-dir " +
                   scratch("gd").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("ok   doc000-pyramid: identical"), std::string::npos) << r.out;
}
