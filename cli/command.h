// Subcommand registration: each cmd_*.cpp adds itself to the program with a
// static Registrar, so main.cpp never lists them.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
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

struct Registrar {
  Registrar(int order, std::function<void(CLI::App&)> setup) {
    commands().push_back({order, std::move(setup)});
  }
};

}  // namespace ra::cli
