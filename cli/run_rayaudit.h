// Test helpers shared by the cli/*_test.cpp files: runs the real rayaudit
// program as a user would and captures its exit code, stdout and stderr;
// scratch files; the skip for tests that limit the address space.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ra::test {

struct CliResult {
  int code;
  std::string out;  // stdout
  std::string err;  // stderr
  std::string all;  // stdout then stderr
};

// `env` is prefixed to the command line (e.g. "RAYAUDIT_CACHE=/x").
inline CliResult run_rayaudit(const std::string& args, const std::string& env = "") {
  static int counter = 0;
  const std::filesystem::path err_file =
      std::filesystem::temp_directory_path() /
      ("rayaudit-test-stderr-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const std::string cmd = env + " " + std::string(RAYAUDIT_EXE) + " " + args + " 2>" + err_file.string();
  FILE* p = popen(cmd.c_str(), "r");
  CliResult r{0, "", "", ""};
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  std::ifstream in(err_file);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  std::filesystem::remove(err_file);
  r.all = r.out + r.err;
  return r;
}

// The exit code and the whole output (stdout then stderr), for tests that
// look at both together.
struct Result {
  int code;
  std::string out;  // stdout and stderr
};

inline Result run(const std::string& args, const std::string& env = "") {
  const CliResult r = run_rayaudit(args, env);
  return {r.code, r.all};
}

// A file's bytes (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Exactly one line, ending in a newline (the bad-input rule for stderr).
inline bool one_line(const std::string& s) { return !s.empty() && s.back() == '\n' && s.find('\n') == s.size() - 1; }

// The bad-input rule: exit 2 and one stderr line that starts with `start`.
inline ::testing::AssertionResult refused(const CliResult& r, const std::string& start) {
  if (r.code != 2) return ::testing::AssertionFailure() << "exit " << r.code << ", not 2: " << r.all;
  if (!one_line(r.err)) return ::testing::AssertionFailure() << "not one line: " << r.err;
  if (r.err.rfind(start, 0) != 0)
    return ::testing::AssertionFailure() << "does not start with " << start << ": " << r.err;
  return ::testing::AssertionSuccess();
}

// A path in this process's scratch directory (TMPDIR/rayaudit-cli-PID/NAME),
// the directory made if missing. ctest runs each test in a process of its own.
inline std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("rayaudit-cli-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d / name;
}

// A copy of `text` in the scratch file NAME with its first `from` replaced
// by `to` (a failed expectation, and the text unchanged, if there is none).
inline std::filesystem::path scratch_variant(const std::string& text, const std::string& name, const std::string& from,
                                             const std::string& to) {
  std::string t = text;
  const auto at = t.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) t.replace(at, from.size(), to);
  const std::filesystem::path p = scratch(name);
  std::ofstream(p) << t;
  return p;
}

// The scratch directory NAME, empty (made, or emptied if it was there).
inline std::filesystem::path scratch_dir(const std::string& name) {
  const std::filesystem::path d = scratch(name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

#ifdef RAYAUDIT_SOURCE_DIR
// The shipped scenes (scenes/*.json, scenes/meshes, scenes/textures).
inline const std::string kScenes = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes";

// A scene with a mesh and a texture in a fresh scratch directory NAME:
// s.json, m.obj and tex.png, inputs that tests name as outputs.
inline std::filesystem::path textured_scene_dir(const std::string& name) {
  const std::filesystem::path d = scratch_dir(name);
  std::filesystem::copy_file(kScenes + "/meshes/quad.obj", d / "m.obj");
  std::filesystem::copy_file(kScenes + "/textures/uv-grid.png", d / "tex.png");
  std::ofstream(d / "s.json")
      << R"({"width": 8, "height": 8, "objects": [{"mesh": "m.obj", "material": {"texture": "tex.png"}}]})"
      << "\n";
  return d;
}
#endif

// AddressSanitizer reserves terabytes of address space: tests that limit it
// (prlimit --as, RLIMIT_AS) cannot run under the asan preset.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

}  // namespace ra::test

// The skip for such a test (a macro: GTEST_SKIP returns from the test body).
#define RAYAUDIT_SKIP_IF_SANITIZED() \
  if (ra::test::kSanitized) GTEST_SKIP() << "prlimit --as and AddressSanitizer do not mix"
