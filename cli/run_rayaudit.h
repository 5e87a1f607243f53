// Test helper: runs the real rayaudit program as a user would and captures
// its exit code, stdout and stderr. Shared by the cli/*_test.cpp files.
#pragma once
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
  const std::filesystem::path err_file = std::filesystem::temp_directory_path() /
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

// A file's bytes (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Exactly one line, ending in a newline (the bad-input rule for stderr).
inline bool one_line(const std::string& s) { return !s.empty() && s.back() == '\n' && s.find('\n') == s.size() - 1; }

}  // namespace ra::test
