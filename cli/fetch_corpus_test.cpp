// ci/fetch-corpus.sh, as a newcomer runs it: from an empty cache, and killed
// part way (more than once) then rerun, it must end with exactly the cache
// that an uninterrupted fetch makes (the one ci/test.sh filled before ctest).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

namespace fs = std::filesystem;

namespace {

const char* const kCompared[] = {"ladder", "embree", "assimp-obj", "assimp-invalid", "off", "generated"};

fs::path reference_corpus() {
  const char* c = std::getenv("RAYAUDIT_CACHE");
  const fs::path cache = c && *c ? fs::path(c) : fs::path(std::getenv("HOME")) / ".cache/rayaudit";
  return cache / "corpus";
}

// Starts the fetch into `cache` in its own process group (so a kill reaches
// apt-get, npm, tar and rayaudit too); returns its pid.
pid_t start_fetch(const fs::path& cache) {
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    setenv("RAYAUDIT_CACHE", cache.c_str(), 1);
    const std::string script = std::string(RAYAUDIT_SOURCE_DIR) + "/ci/fetch-corpus.sh";
    const std::string quiet = "exec '" + script + "' '" + RAYAUDIT_EXE + "' >/dev/null 2>&1";
    execl("/bin/sh", "sh", "-c", quiet.c_str(), (char*)nullptr);
    _exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// True if a name at depth 1 or 2 under `root` starts with `prefix` and ends
// with `suffix` (every temporary the fetch makes is there; deeper lie
// thousands of unpacked files).
bool any_path_ends_with(const fs::path& root, const std::string& suffix, const std::string& prefix = "") {
  auto match = [&](const fs::path& p) {
    const std::string name = p.filename().string();
    return name.rfind(prefix, 0) == 0 && ends_with(name, suffix);
  };
  std::error_code ec;
  for (fs::directory_iterator a(root, ec), end; !ec && a != end; a.increment(ec)) {
    if (match(a->path())) return true;
    std::error_code ec2;
    if (!a->is_directory(ec2)) continue;
    for (fs::directory_iterator b(a->path(), ec2); !ec2 && b != end; b.increment(ec2))
      if (match(b->path())) return true;
  }
  return false;
}

// Kills the fetch with SIGKILL as soon as `path_suffix` appears under the
// cache (a step caught half done). Returns false if the fetch ended first.
bool kill_when_seen(pid_t pid, const fs::path& cache, const std::string& path_suffix,
                    const std::string& path_prefix = "") {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (std::chrono::steady_clock::now() < give_up) {
    if (any_path_ends_with(cache / "corpus", path_suffix, path_prefix)) {
      kill(-pid, SIGKILL);
      wait_exit(pid);
      return true;
    }
    int status;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  kill(-pid, SIGKILL);
  wait_exit(pid);
  return false;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Relative path -> size of every regular file in the compared folders.
std::map<std::string, std::uintmax_t> listing(const fs::path& corpus) {
  std::map<std::string, std::uintmax_t> files;
  for (const char* d : kCompared) {
    if (!fs::exists(corpus / d)) continue;
    for (const auto& e : fs::recursive_directory_iterator(corpus / d))
      if (e.is_regular_file()) files[fs::relative(e.path(), corpus).string()] = e.file_size();
  }
  return files;
}

TEST(FetchCorpus, KilledPartWayThenRerunEndsWithTheSameCacheAsAnUninterruptedFetch) {
  const fs::path reference = reference_corpus();
  ASSERT_TRUE(fs::exists(reference / "ladder/dragon.obj"))
      << reference << " is not a filled corpus: ci/test.sh runs ci/fetch-corpus.sh before ctest";
  char tmpl[] = "/tmp/rayaudit-fetch-test-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const fs::path cache = tmpl;

  // Three kills, each in the middle of a different kind of step: a package
  // being unpacked, the dragon being decompressed, a converted mesh being
  // written by rayaudit (its temporary is named .tmp-*).
  const std::pair<std::string, std::string> kill_at[] = {
      {"", ".partial"}, {"", "dragon.ply.tmp"}, {".tmp-", "_cgal.obj"}};
  for (const auto& [prefix, suffix] : kill_at) {
    const pid_t pid = start_fetch(cache);
    EXPECT_TRUE(kill_when_seen(pid, cache, suffix, prefix))
        << "the fetch ended before '" << prefix << "*" << suffix << "' appeared";
  }
  const int rc = wait_exit(start_fetch(cache));
  ASSERT_EQ(rc, 0) << "the rerun after the kills failed (cache kept in " << cache << ")";
  EXPECT_FALSE(any_path_ends_with(cache / "corpus", ".partial")) << "a .partial was left behind";
  EXPECT_FALSE(any_path_ends_with(cache / "corpus", "dragon.ply.tmp")) << "the dragon's PLY was left behind";
  for (const char* dir : {"ladder", "generated"})
    for (const auto& e : fs::directory_iterator(cache / "corpus" / dir))
      EXPECT_NE(e.path().filename().string().rfind(".tmp-", 0), 0u)
          << "a killed rayaudit's temporary was left: " << e.path();

  const auto want = listing(reference), got = listing(cache / "corpus");
  ASSERT_FALSE(want.empty());
  EXPECT_EQ(got, want) << "file list or sizes differ from " << reference;
  if (got == want) {
    for (const auto& [rel, size] : want) {
      EXPECT_TRUE(slurp(cache / "corpus" / rel) == slurp(reference / rel)) << rel << " differs";
    }
  }
  if (!HasFailure()) fs::remove_all(cache);
}

}  // namespace
