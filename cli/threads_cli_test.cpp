// Threads, run through the real program: a count the system refuses is an
// error or a fall-back to fewer threads, never an abort; the audit's JSON is
// the same whatever the thread count.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <filesystem>
#include <string>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

TEST(ThreadsCli, InfoThreadsBeyond1024IsRefused) {
  const auto r = run_rayaudit("info " + kScenes + "/meshes/quad.obj --threads 100000");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
}

// Under a 2 GB address-space limit 1024 threads' stacks cannot all be
// made: the work goes on with the threads that could start, and the result
// is the one a single thread gives (it used to abort, exit 134).
TEST(ThreadsCli, AuditWith1024ThreadsUnderAMemoryLimitFallsBack) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const fs::path many = scratch("audit-1024.json"), one = scratch("audit-1.json");
  const auto r = run_rayaudit("audit --rays 5000 --threads 1024 --json " + many.string(), "prlimit --as=2000000000 --");
  ASSERT_EQ(r.code, 0) << r.all;
  ASSERT_EQ(run_rayaudit("audit --rays 5000 --threads 1 --json " + one.string()).code, 0);
  EXPECT_EQ(slurp(many), slurp(one));
}

TEST(ThreadsCli, RenderWith1024ThreadsUnderAMemoryLimitFallsBack) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const fs::path many = scratch("r-1024.png"), one = scratch("r-1.png");
  const std::string scene = kScenes + "/doc000-pyramid.json --width 64 --height 48";
  const auto r = run_rayaudit("render " + scene + " --threads 1024 -o " + many.string(), "prlimit --as=2000000000 --");
  ASSERT_EQ(r.code, 0) << r.all;
  ASSERT_EQ(run_rayaudit("render " + scene + " --threads 1 -o " + one.string()).code, 0);
  EXPECT_EQ(slurp(many), slurp(one));
}

// Audit JSON is identical for 1, 2 and 7 threads over every method and family.
TEST(ThreadsCli, AuditJsonIsIdenticalFor1And2And7Threads) {
  std::string first;
  for (int n : {1, 2, 7}) {
    const fs::path j = scratch("audit-t" + std::to_string(n) + ".json");
    ASSERT_EQ(run_rayaudit("audit --rays 2000 --threads " + std::to_string(n) + " --json " + j.string()).code, 0);
    if (first.empty())
      first = slurp(j);
    else
      EXPECT_EQ(slurp(j), first) << n << " threads";
  }
  EXPECT_GT(first.size(), 1000u);
}

}  // namespace
