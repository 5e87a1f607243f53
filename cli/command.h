// Subcommand registration: each cmd_*.cpp adds itself to the program with a
// static Registrar, so main.cpp never lists them.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace ra::cli {

// `setup` adds a subcommand to the app and its callback. The callback may
// throw ra::InputError (exit 2) or ra::CheckFailed (exit 1), or return an
// exit code by throwing ExitCode.
struct ExitCode { int code; };

struct Command {
  int order;  // position in --help
  std::function<void(CLI::App&)> setup;
};

std::vector<Command>& commands();

// "a, b,,c" -> {"a", "b", "c"}: the comma-separated lists of options such
// as --methods, --families and --offsets (spaces and empty items dropped).
inline std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char ch : s + ",") {
    if (ch == ',') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else if (ch != ' ') {
      cur += ch;
    }
  }
  return out;
}

struct Registrar {
  Registrar(int order, std::function<void(CLI::App&)> setup) {
    commands().push_back({order, std::move(setup)});
  }
};

}  // namespace ra::cli
