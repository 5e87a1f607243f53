// The installed package, used as a user's project uses it: rayaudit is
// installed into a temporary prefix, validation/consumer/ (its own
// CMakeLists.txt with find_package(rayaudit REQUIRED), a textbook float
// Möller–Trumbore and EXPECT_WATERTIGHT) is configured, built and run against
// it, and its test must report the textbook method's leaks on shared edges.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <rayaudit/audit.h>
#include <rayaudit/audit_gtest.h>

#include "consumer/textbook_moller.h"

namespace fs = std::filesystem;

namespace {

struct ShellResult {
  int code;
  std::string out;  // stdout and stderr together
};

ShellResult sh(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  ShellResult r{-1, ""};
  if (!p) return r;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  return r;
}

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// The asan preset's libraries call the sanitizers' runtime: the consumer is
// then compiled and linked with the same flags, as a user of such a build would.
#ifdef RAYAUDIT_CONSUMER_FLAGS
const std::string kConsumerFlags =
    " -DCMAKE_CXX_FLAGS='" RAYAUDIT_CONSUMER_FLAGS "' -DCMAKE_EXE_LINKER_FLAGS='" RAYAUDIT_CONSUMER_FLAGS "'";
#else
const std::string kConsumerFlags;
#endif

class PackageConsumer : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/rayaudit-consumer-XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    if (!HasFailure()) fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(PackageConsumer, InstalledPackageBuildsAUsersProjectAndItsTestReportsTheLeaks) {
  const fs::path prefix = dir_ / "prefix", build = dir_ / "build";
  const std::string cmake = quoted(RAYAUDIT_CMAKE_COMMAND);

  const ShellResult install = sh(cmake + " --install " + quoted(RAYAUDIT_BUILD_DIR) + " --prefix " + quoted(prefix));
  ASSERT_EQ(install.code, 0) << install.out;
  // Headers are where users include them from, and nowhere flatter.
  EXPECT_TRUE(fs::exists(prefix / "include/rayaudit/audit.h"));
  EXPECT_TRUE(fs::exists(prefix / "include/rayaudit/audit_gtest.h"));
  EXPECT_FALSE(fs::exists(prefix / "include/audit.h"));
  // The image module (OpenImageIO, loaded on first use) is installed, and the
  // installed rayaudit finds it from bin/: it writes a PNG.
  ASSERT_TRUE(fs::exists(prefix / "lib/rayaudit/rayaudit_image.so"));
  const fs::path png = dir_ / "installed.png";
  const ShellResult render = sh(quoted(prefix / "bin/rayaudit") + " render " +
                                quoted(fs::path(RAYAUDIT_SOURCE_DIR) / "scenes/doc000-pyramid.json") +
                                " --width 16 --height 12 -o " + quoted(png));
  ASSERT_EQ(render.code, 0) << render.out;
  EXPECT_GT(fs::file_size(png), 50u);

  const ShellResult configure =
      sh(cmake + " -S " + quoted(fs::path(RAYAUDIT_SOURCE_DIR) / "validation/consumer") + " -B " + quoted(build) +
         " -G Ninja -DCMAKE_BUILD_TYPE=Release" + " -DCMAKE_PREFIX_PATH=" + quoted(prefix) + kConsumerFlags);
  ASSERT_EQ(configure.code, 0) << configure.out;
  const ShellResult compile = sh(cmake + " --build " + quoted(build));
  ASSERT_EQ(compile.code, 0) << compile.out;

  // A program linking the package finds the module through its RUNPATH.
  const ShellResult dynamic = sh("readelf -d " + quoted(build / "my_intersector_test"));
  EXPECT_NE(dynamic.out.find((prefix / "lib/rayaudit").string()), std::string::npos) << dynamic.out;

  const ShellResult test = sh(quoted(build / "my_intersector_test"));
  // The textbook method is not watertight: the user's test must fail, and say so.
  EXPECT_EQ(test.code, 1) << test.out;
  EXPECT_NE(test.out.find("[  FAILED  ] MyIntersector.IsWatertight"), std::string::npos) << test.out;

  // The same check run here, in the build tree, on the same source: the
  // installed package must reach the same verdict, leak for leak.
  const auto here = ra::audit::triangle_subject<float>("textbook-moller", my::textbook_moller);
  const ::testing::AssertionResult expected = ra::audit::IsWatertight(here);
  ASSERT_FALSE(expected) << "the textbook float Möller–Trumbore no longer leaks on shared edges";
  const std::string message = expected.message();
  EXPECT_NE(message.find("textbook-moller/"), std::string::npos) << message;
  EXPECT_NE(message.find(" leaked "), std::string::npos) << message;
  EXPECT_NE(test.out.find(message), std::string::npos) << "installed consumer said:\n"
                                                       << test.out << "\nthe build tree says:\n"
                                                       << message;
}

}  // namespace
