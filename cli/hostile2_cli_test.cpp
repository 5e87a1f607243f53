// Regressions for the second hostile pass (HOSTILE2 F1, F22, F25, F27, F29,
// F30, F31, F40, F42, F43, F44): audit export/merge, report, crack-maps,
// compare and generate, run through the real program as a user would.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::run_rayaudit;

namespace {

const std::string kScenes = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes";

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-hostile2-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool one_line(const std::string& s) { return !s.empty() && s.back() == '\n' && s.find('\n') == s.size() - 1; }

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// F1: a list of two precisions was taken as double, the float half dropped.
TEST(Hostile2Cli, ExportCasesTakesOnePrecision) {
  const fs::path out = scratch("two-precisions.csv");
  fs::remove(out);
  for (const char* list : {"float,double", "double,float"}) {
    const auto r = run_rayaudit("audit --export-cases " + out.string() + " --precision " + list + " --rays 10");
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_EQ(r.err, std::string("--precision: --export-cases takes one precision (float or double), got '") + list +
                         "'\n");
    EXPECT_FALSE(fs::exists(out));
  }
  const auto ok = run_rayaudit("audit --export-cases " + out.string() + " --precision float --rays 10 --families edge");
  EXPECT_EQ(ok.code, 0) << ok.all;
  EXPECT_NE(ok.out.find("float cases"), std::string::npos) << ok.out;
}

// F29: the export held every case in memory (840 bytes each: 300,000 cases
// did not fit in 200 MB of address space); it streams now.
TEST(Hostile2Cli, ExportCasesStreamsWithinAFixedAddressSpace) {
  if (kSanitized) GTEST_SKIP() << "prlimit --as and AddressSanitizer do not mix";
  const fs::path out = scratch("streamed.csv");
  const auto r = run_rayaudit("audit --export-cases " + out.string() + " --rays 300000 --families random --precision double",
                              "prlimit --as=200000000");
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("wrote 300000 double cases"), std::string::npos) << r.out;
  std::ifstream in(out);
  long lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  EXPECT_EQ(lines, 300001);
  fs::remove(out);
}

}  // namespace
