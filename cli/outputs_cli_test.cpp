// Where commands write, run through the real program: every destination
// checked before the work, an output that is an input or another output
// refused, a full disk or a FIFO never leaving a broken or replaced file.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/full_disk.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

TEST(OutputsCli, RenderOnAFullDiskExits2AndKeepsTheGoodPng) {
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

// A missing output directory is found before a 16384 x 16384 render, not after.
TEST(OutputsCli, RenderChecksTheDestinationBeforeTheWork) {
  const auto r =
      run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 16384 --height 16384 -o /nonexistent-dir/x.png");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "/nonexistent-dir/x.png: output directory does not exist\n");
}

// What a command prints must arrive: on a full disk (/dev/full) every
// command that writes to stdout says so in one line with exit 2; it exited
// 0 and left `info --json > f` empty.
TEST(OutputsCli, StdoutOnAFullDiskIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  for (const std::string& args :
       std::vector<std::string>{"--version", "methods", "methods --json", "info " + kScenes + "/meshes/tetrahedron.obj",
                                "info --json " + kScenes + "/meshes/tetrahedron.obj"}) {
    const auto r = run_rayaudit(args + " >/dev/full");
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err, "rayaudit: cannot write to standard output: No space left on device\n") << args;
  }
}

// A regular file where the output's directory should be is named as such
// (it read "output directory does not exist").
TEST(OutputsCli, OutputUnderARegularFileIsNamed) {
  const fs::path file = scratch("notes.txt");
  std::ofstream(file) << "x\n";
  const fs::path out = file / "x.png";
  const auto r = run_rayaudit("render " + kScenes + "/meshes/tetrahedron.obj -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, out.string() + ": output directory " + file.string() + " is not a directory\n");
}

TEST(OutputsCli, ExportPovWithIniEqualToOutputIsRefused) {
  const fs::path pov = scratch("same.pov");
  std::ofstream(pov) << "precious";
  const auto r =
      run_rayaudit("export-pov " + kScenes + "/doc000-pyramid.json -o " + pov.string() + " --ini " + pov.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, pov.string() + ": --ini names the same file as -o\n");
  EXPECT_EQ(slurp(pov), "precious");
}

TEST(OutputsCli, OutputNameNear255CharactersIsWritten) {
  const fs::path out = scratch(std::string(246, 'n') + ".png");
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 8 --height 8 -o " + out.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(out));
}

// An existing output that is not a regular file is refused before any work:
// the renamed temporary would have replaced it (run as root, `--json
// /dev/full` turned the device into a file). A FIFO stands in for a device.
TEST(OutputsCli, OutputThatIsAFifoIsRefusedNotReplaced) {
  const fs::path fifo = scratch("out-fifo.png");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& args :
       std::vector<std::string>{"render " + kScenes + "/doc000-pyramid.json --width 8 --height 8 -o " + fifo.string(),
                                "audit --rays 100 --families edge --json " + fifo.string()}) {
    const auto r = run_rayaudit(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.all;
    EXPECT_EQ(r.err, fifo.string() + ": is a FIFO, not a file: not replaced\n") << args;
    EXPECT_TRUE(fs::is_fifo(fifo)) << "replaced by " << args;
  }
  fs::remove(fifo);
}

// An output that is one of the command's inputs (the scene, the mesh or
// texture it references, the cases CSV) is refused before the work: the
// rename replaced the input (`render s.json -o
// tex.png`, `export-pov --ini s.json`, `audit --cases c.csv --json c.csv`).
TEST(OutputsCli, OutputThatIsAnInputIsRefusedAndTheInputKept) {
  const fs::path d = textured_scene_dir("out-is-input");
  const fs::path cases = d / "c.csv";
  ASSERT_EQ(run_rayaudit("audit --export-cases " + cases.string() + " --families edge --rays 10").code, 0);
  fs::create_symlink(d / "tex.png", d / "link.png");
  const std::string s = (d / "s.json").string();
  struct Case {
    std::string args;
    fs::path input;
  };
  for (const Case& c :
       std::vector<Case>{{"render " + s + " -o " + (d / "tex.png").string(), d / "tex.png"},
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
TEST(OutputsCli, TwoOutputsOnOnePathAreRefused) {
  const fs::path d = textured_scene_dir("two-outputs");
  const std::string same = (d / "same").string();
  for (const std::string& args :
       std::vector<std::string>{"audit --rays 50 --families edge --methods moller --json " + same + " --csv " + same,
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

// compare --random --out a/b/c created the missing parents; every other
// command refuses an output whose parent directory does not exist.
TEST(OutputsCli, CompareRandomOutWithAMissingParentIsRefused) {
  const fs::path d = scratch_dir("random-out");
  const auto r = run_rayaudit("compare --random 1 --out " + (d / "a" / "b").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, (d / "a" / "b").string() + ": its parent directory does not exist\n");
  EXPECT_FALSE(fs::exists(d / "a"));
}

}  // namespace
