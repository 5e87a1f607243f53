// `rayaudit bench [--quick] [--json OUT] [--threads N] [--filter REGEX] [--runs N]`:
// checks what it can cheaply, then runs rayaudit-bench (built
// beside rayaudit), which holds Google Benchmark, Embree, tinyobjloader and
// CGAL's AABB tree so that this program does not load them at every start.
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <filesystem>
#include <iostream>

#include "io/atomic_file.h"
#include "command.h"
#include "errors.h"

namespace {

namespace fs = std::filesystem;

struct Args {
  bool quick = false;
  std::string json, filter;
  int threads = 0;
  int runs = 1;
};

// rayaudit-bench in the directory of this very executable.
fs::path bench_program() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path p = (ec ? fs::path(".") : self.parent_path()) / "rayaudit-bench";
  if (access(p.c_str(), X_OK) != 0)
    throw ra::InputError(p.string() + ": not found; build it beside rayaudit (cmake --build --preset release)");
  return p;
}

void run(const Args& a, CLI::App* cmd, const std::vector<std::string>& extras) {
  // Only Google Benchmark's own flags pass through.
  for (const auto& e : extras)
    if (e.rfind("--benchmark_", 0) != 0)
      throw ra::InputError("rayaudit bench: unknown argument \"" + e +
                           "\" (--quick, --json OUT, --threads N, --filter REGEX, --runs N, --benchmark_*)");
  if (!a.json.empty()) ra::check_output_path(a.json);
  const fs::path prog = bench_program();
  std::vector<std::string> argv{prog.string()};
  if (a.quick) argv.push_back("--quick");
  if (!a.json.empty()) argv.push_back("--json=" + a.json);
  if (a.threads > 0) argv.push_back("--threads=" + std::to_string(a.threads));
  if (cmd->count("--filter")) argv.push_back("--filter=" + a.filter);
  if (a.runs > 1) argv.push_back("--runs=" + std::to_string(a.runs));
  argv.insert(argv.end(), extras.begin(), extras.end());
  std::vector<char*> cargv;
  for (auto& s : argv) cargv.push_back(s.data());
  cargv.push_back(nullptr);
  std::cout.flush();
  execv(prog.c_str(), cargv.data());
  throw ra::InputError(prog.string() + ": cannot run: " + std::strerror(errno));
}

void setup(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* cmd =
      app.add_subcommand("bench",
                         "Benchmarks: every method, the documents' optimisations, Embree, POV-Ray, tinyobjloader, CGAL "
                         "(Google Benchmark; its --benchmark_* flags pass through)");
  cmd->add_flag("--quick", args->quick, "Fewer repetitions, mesh ladder up to the bunny (under 2 minutes)");
  cmd->add_option("--json", args->json,
                  "Write Google Benchmark's JSON here (compare.py reads it), with every repetition, its calibration, "
                  "and each row's median, quartiles and range under \"rayaudit\"");
  cmd->add_option("--threads", args->threads, "Threads of the all-threads rows (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--filter", args->filter,
                  "Only rows whose name matches this regex (groups: kernel, scene, peer, oracle, obj)");
  cmd->add_option("--runs", args->runs,
                  "Run the whole selection N times, each a separate process, one after another; the JSON holds "
                  "every repetition of every run and each row's median, quartiles and range over all of them")
      ->check(CLI::Range(1, 20));
  cmd->allow_extras();
  cmd->callback([args, cmd] { run(*args, cmd, cmd->remaining()); });
}

ra::cli::Registrar reg(90, setup);

}  // namespace
