// Subcommand registration: each cmd_*.cpp adds itself to the program with a
// static Registrar, so main.cpp never lists them.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "errors.h"

namespace ra::cli {

// `setup` adds a subcommand to the app and its callback. The callback may
// throw ra::InputError (exit 2) or ra::CheckFailed (exit 1), or return an
// exit code by throwing ExitCode.
struct ExitCode {
  int code;
};

struct Command {
  int order;  // position in --help
  std::function<void(CLI::App&)> setup;
};

std::vector<Command>& commands();

// "a, b,c" -> {"a", "b", "c"}: the comma-separated lists of options such
// as --methods, --families and --offsets (spaces dropped). An empty item
// ("a,,b", "a,", ",") is an error naming `flag`: it was dropped silently,
// and `--methods ,` meant every method.
inline std::vector<std::string> split_list(const std::string& s, const char* flag) {
  std::vector<std::string> out;
  if (s.find_first_not_of(' ') == std::string::npos) return out;  // not given
  std::string cur;
  for (char ch : s + ",") {
    if (ch == ',') {
      if (cur.empty()) throw ra::InputError(std::string(flag) + ": empty item in the list '" + s + "'");
      out.push_back(cur);
      cur.clear();
    } else if (ch != ' ') {
      cur += ch;
    }
  }
  return out;
}

// A validator for list options: given, the list must not be empty (an
// explicit `--families ''` meant every family).
inline CLI::Validator non_empty_list() {
  return CLI::Validator(
      [](std::string& v) {
        return v.find_first_not_of(' ') == std::string::npos ? std::string("empty list") : std::string();
      },
      "LIST");
}

struct Registrar {
  Registrar(int order, std::function<void(CLI::App&)> setup) { commands().push_back({order, std::move(setup)}); }
};

}  // namespace ra::cli
