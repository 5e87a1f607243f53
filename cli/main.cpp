// rayaudit: one program, several subcommands (each in its own cmd_*.cpp).
// Exit codes: 0 ok, 1 a check failed, 2 bad input or usage.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <new>
#include <string_view>

#include "command.h"
#include "errors.h"

namespace ra::cli {
std::vector<Command>& commands() {
  static std::vector<Command> all;
  return all;
}
}  // namespace ra::cli

namespace {

// An empty value is never meant: `--json ""` wrote nothing and exited 0,
// `-o ""` failed late, `--seed ""` said something about a conversion. Every
// option that takes a value (and every positional) refuses "" by name.
void refuse_empty_values(CLI::App& app) {
  const CLI::Validator non_empty(
      [](std::string& v) {
        return v.empty() ? std::string("empty value (a file name or value is needed)") : std::string();
      },
      "", "NON_EMPTY");
  for (CLI::Option* opt : app.get_options())
    if (opt->get_type_size_max() > 0) opt->check(non_empty);
  for (CLI::App* sub : app.get_subcommands({})) refuse_empty_values(*sub);
}

// What a command printed must have arrived: `info --json > f` on a full
// disk exited 0 and left f empty. Both streams are flushed
// and checked before a success is reported.
int finish(int code) {
  // An output over stdio's buffer (4 KiB: `methods --json` since the exact
  // method) fails in an earlier write, whose reason is still in errno.
  const int earlier = errno;
  errno = 0;
  std::cout.flush();  // into stdio's buffer (synced), written out by the fflush
  const bool flush_failed = std::fflush(stdout) != 0;
  const int err = errno ? errno : std::ferror(stdout) ? earlier : 0;  // the reason of the failing write
  if (!(flush_failed || std::ferror(stdout) || !std::cout) || code != 0) return code;
  std::cerr << "rayaudit: cannot write to standard output"
            << (err ? std::string(": ") + std::strerror(err) : std::string(" (disk full, or closed)")) << "\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // Answered before any command is set up, with its newline.
  // `--version extra` printed the version and exited 0, the extra ignored.
  if (argc > 2 && std::string_view(argv[1]) == "--version") {
    std::cerr << "rayaudit: --version takes no arguments, got '" << argv[2] << "' (see --help)\n";
    return 2;
  }
  if (argc == 2 && std::string_view(argv[1]) == "--version") {
    std::cout << "rayaudit " << RAYAUDIT_VERSION << "\n";
    return finish(0);
  }
  CLI::App app{"rayaudit: is your ray-intersection code right, and how fast is it?", "rayaudit"};
  app.set_version_flag("--version", std::string("rayaudit ") + RAYAUDIT_VERSION);
  app.require_subcommand(1);
  auto& cmds = ra::cli::commands();
  std::sort(cmds.begin(), cmds.end(), [](auto& a, auto& b) { return a.order < b.order; });
  for (auto& c : cmds) c.setup(app);
  refuse_empty_values(app);
  // CLI11 would call an unknown command "A subcommand is required": name it.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->check_name(argv[1]);
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "rayaudit: unknown command '" << argv[1] << "' (commands: " << names << "; see --help)\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version arrive here too, with exit code 0.
    if (e.get_exit_code() == 0) return finish(app.exit(e));
    std::cerr << "rayaudit: " << e.what() << " (see --help)\n";
    return 2;
  } catch (const ra::cli::ExitCode& e) {
    return finish(e.code);
  } catch (const ra::InputError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const ra::CheckFailed& e) {
    std::cerr << e.what() << "\n";
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the checks before did not see (a symlink loop met by exists(),
    // a directory without permission): "PATH: the system's reason", as
    // every other input error, not the library's "filesystem error: status: ...".
    const std::string path = !e.path1().empty() ? e.path1().string() : "rayaudit";
    std::cerr << path << ": " << e.code().message() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    // An allocation the checks before did not foresee: one line that says
    // what happened, not the library's "std::bad_alloc".
    std::cerr << "rayaudit: not enough memory for this input (an allocation failed; free memory or raise "
                 "`ulimit -v`, or give smaller sizes)\n";
    return 2;
  } catch (const std::exception& e) {
    // Anything else (a filesystem error, an allocation too large for this
    // machine) is still about this input: the contract has 0, 1 and 2 only.
    std::cerr << "rayaudit: error: " << e.what() << "\n";
    return 2;
  }
  return finish(0);
}
