// The bad-input corpus (cli/badinput/): every file is run through
// the real rayaudit by the command that reads its kind, in a child process
// with its address space and CPU time limited. Each must give exit 2, one
// stderr line naming the file and its expected message (cli/badinput/
// expected.tsv: line or byte offset included where there is one), write
// nothing, and leave an existing output file untouched.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kCorpus = fs::path(RAYAUDIT_SOURCE_DIR) / "cli" / "badinput";

struct Case {
  std::string file;      // kind/name, relative to kCorpus
  std::string expected;  // a fragment of the one stderr line
};

std::vector<Case> load_cases() {
  std::vector<Case> out;
  std::ifstream in(kCorpus / "expected.tsv");
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto tab = line.find('\t');
    out.push_back({line.substr(0, tab), tab == std::string::npos ? "" : line.substr(tab + 1)});
  }
  return out;
}

struct ChildRun {
  int code = -1;
  std::string err;
  long max_rss_kb = 0;
  bool killed = false;
};

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// Limits of the child: 4 GB of address space (ASan needs its own, so none
// then), 60 s of CPU, and a 120 s wall-clock guard against a hang (a FIFO
// read). These are bounds against runaway, not measurements of speed.
constexpr rlim_t kMaxAddressSpace = rlim_t(4) << 30;
constexpr long kMaxRssKb = 1L << 20;  // 1 GB resident at most

ChildRun run_limited(const std::vector<std::string>& args, const fs::path& err_file) {
  std::vector<char*> argv;
  std::string exe = RAYAUDIT_EXE;
  argv.push_back(exe.data());
  std::vector<std::string> copy = args;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!kSanitized) {
      rlimit as{kMaxAddressSpace, kMaxAddressSpace};
      ::setrlimit(RLIMIT_AS, &as);
    }
    rlimit cpu{60, 60};
    ::setrlimit(RLIMIT_CPU, &cpu);
    const int fd = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(fd, 2);
    ::dup2(null, 1);
    ::dup2(null, 0);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ChildRun r;
  int status = 0;
  rusage ru{};
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  for (;;) {
    const pid_t w = ::wait4(pid, &status, WNOHANG, &ru);
    if (w == pid) break;
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::wait4(pid, &status, 0, &ru);
      r.killed = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.max_rss_kb = ru.ru_maxrss;
  std::ifstream in(err_file);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) out.insert(e.path().lexically_relative(dir).string());
  return out;
}

class BadInput : public ::testing::TestWithParam<Case> {};

TEST_P(BadInput, Exits2WithOneLineNamingTheFileAndWritesNothing) {
  const Case& c = GetParam();
  const fs::path file = kCorpus / c.file;
  const std::string kind = fs::path(c.file).begin()->string();
  const fs::path work = fs::temp_directory_path() / ("rayaudit-badinput-" + std::to_string(::getpid()));
  fs::remove_all(work);
  fs::create_directories(work / "out");
  const fs::path out = work / "out";
  // Existing outputs, which a failed run must leave as they are.
  const std::string precious = "precious: an earlier good output\n";
  for (const char* n : {"out.png", "out.obj", "out.json"}) std::ofstream(out / n) << precious;

  std::string named = file.string();  // the path the message must name
  std::vector<std::string> args;
  const std::string src = RAYAUDIT_SOURCE_DIR;
  const std::vector<std::string> render_to = {"-o", (out / "out.png").string(), "--width", "8", "--height", "8"};
  if (kind == "obj" || kind == "scene") {
    args = {"render", file.string()};
    args.insert(args.end(), render_to.begin(), render_to.end());
  } else if (kind == "mtl") {
    std::ofstream(work / "wrap.obj") << "mtllib " << file.string()
                                     << "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
    args = {"render", (work / "wrap.obj").string()};
    args.insert(args.end(), render_to.begin(), render_to.end());
  } else if (kind == "ply" || kind == "off") {
    args = {"convert", file.string(), "-o", (out / "out.obj").string()};
  } else if (kind == "csv") {
    args = {"audit", "--cases", file.string(), "--json", (out / "out.json").string()};
  } else if (kind == "tolerance") {
    args = {"compare",     src + "/scenes/doc002-tetrahedron.json",
            "--tolerance", file.string(),
            "--json",      (out / "out.json").string(),
            "--width",     "8",
            "--height",    "8"};
  } else if (kind == "golden") {
    fs::create_directories(work / "root" / "golden");
    fs::create_directories(work / "root" / "scenes");
    fs::copy_file(file, work / "root" / "golden" / "manifest.json");
    named = (work / "root" / "golden" / "manifest.json").string();
    args = {"golden", "check", "--root", (work / "root").string(), "--diff-dir", out.string()};
  } else if (kind == "texture") {
    std::ofstream(work / "scene.json") << R"({"objects": [{"mesh": ")" << src
                                       << R"(/scenes/meshes/quad.obj", "material": {"texture": ")" << file.string()
                                       << "\"}}]}\n";
    args = {"render", (work / "scene.json").string()};
    args.insert(args.end(), render_to.begin(), render_to.end());
  } else {
    FAIL() << "unknown kind " << kind;
  }
  const auto before = listing(work);
  const ChildRun r = run_limited(args, work / "stderr.txt");
  fs::remove(work / "stderr.txt");

  EXPECT_FALSE(r.killed) << "no answer in 120 s";
  EXPECT_EQ(r.code, 2) << r.err;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.back(), '\n') << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line:\n" << r.err;
  EXPECT_NE(r.err.find(named), std::string::npos) << "names " << named << ":\n" << r.err;
  EXPECT_FALSE(c.expected.empty()) << "expected.tsv gives no message for " << c.file;
  EXPECT_NE(r.err.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in:\n" << r.err;
  for (const char* n : {"out.png", "out.obj", "out.json"}) EXPECT_EQ(slurp(out / n), precious) << n;
  EXPECT_EQ(listing(work), before) << "a file was written or left behind";
  EXPECT_LT(r.max_rss_kb, kMaxRssKb) << "peak resident memory";
  fs::remove_all(work);
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n = info.param.file;
  for (char& ch : n)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(load_cases()), case_name);

// Every file of the corpus has its line in expected.tsv (none forgotten).
TEST(BadInputCorpus, EveryFileIsListedAndThereAreAtLeast80) {
  std::set<std::string> listed;
  for (const auto& c : load_cases()) listed.insert(c.file);
  std::size_t files = 0;
  for (const auto& kind : fs::directory_iterator(kCorpus)) {
    if (!kind.is_directory()) continue;
    for (const auto& e : fs::directory_iterator(kind.path())) {
      const std::string rel = e.path().lexically_relative(kCorpus).string();
      EXPECT_TRUE(listed.count(rel)) << rel << " is not in expected.tsv";
      ++files;
    }
  }
  EXPECT_GE(files, 80u);
  EXPECT_EQ(files, listed.size());
}

}  // namespace
