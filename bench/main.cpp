// rayaudit-bench (issue 13), run as `rayaudit bench`: every group registered,
// the arguments checked before anything runs (one line and exit 2 on bad
// input, nothing written), then Google Benchmark, whose JSON goes to a
// temporary file renamed to --json OUT only when every row succeeded.
//
//   rayaudit-bench [--quick] [--json OUT] [--threads N] [--filter REGEX] [--benchmark_*...]
#include <malloc.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <new>
#include <random>
#include <regex>
#include <set>

#include "io/atomic_file.h"
#include "bench.h"
#include "errors.h"
#include "pov_runner.h"
#include "scene/scene_mesh.h"

// ---- Heap accounting (peak bytes per triangle of the OBJ parsers, bytes of
// our acceleration structures): every operator new counts its usable size.
namespace {
std::atomic<long> g_live{0}, g_peak{0};
void* counted_alloc(std::size_t n) {
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  const long now = g_live.fetch_add(long(malloc_usable_size(p)), std::memory_order_relaxed) +
                   long(malloc_usable_size(p));
  long peak = g_peak.load(std::memory_order_relaxed);
  while (now > peak && !g_peak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
  return p;
}
void counted_free(void* p) {
  if (!p) return;
  g_live.fetch_sub(long(malloc_usable_size(p)), std::memory_order_relaxed);
  std::free(p);
}
}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }

namespace rb {
long heap_live() { return g_live.load(); }
long heap_peak() { return g_peak.load(); }
void heap_reset_peak() { g_peak = g_live.load(); }
}  // namespace rb

namespace {

namespace fs = std::filesystem;

const char* const kGroups = "kernel, scene, peer, oracle, obj";

struct Args {
  bool quick = false;
  std::string json;
  int threads = 0;
  std::string filter;
  bool has_filter = false;
  std::vector<std::string> passthrough;  // --benchmark_*
};

// "--name VALUE" or "--name=VALUE"; advances i past a separate value.
bool option(int argc, char** argv, int& i, const char* name, std::string& value) {
  const std::size_t n = std::strlen(name);
  if (std::strncmp(argv[i], name, n) != 0) return false;
  if (argv[i][n] == '=') {
    value = argv[i] + n + 1;
    return true;
  }
  if (argv[i][n] != '\0') return false;
  if (i + 1 >= argc) throw ra::InputError(std::string(name) + ": needs a value");
  value = argv[++i];
  return true;
}

// Values of the passed-through flags Google Benchmark would take badly
// (a negative repetition count was "error: vector::reserve", exit 1; an
// unknown format printed its usage and exited 0; HOSTILE2 F34).
void check_passthrough(const std::string& arg) {
  const auto eq = arg.find('=');
  const std::string name = arg.substr(0, eq), value = eq == std::string::npos ? "" : arg.substr(eq + 1);
  if (name == "--benchmark_repetitions") {
    char* end = nullptr;
    const long n = std::strtol(value.c_str(), &end, 10);
    if (value.empty() || *end || n < 1 || n > 10000)
      throw ra::InputError(name + ": must be a whole number from 1 to 10000, got \"" + value + "\"");
  } else if (name == "--benchmark_format" || name == "--benchmark_out_format") {
    if (value != "console" && value != "json" && value != "csv")
      throw ra::InputError(name + ": must be console, json or csv, got \"" + value + "\"");
  }
}

Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    std::string v;
    const std::string arg = argv[i];
    if (arg == "--quick") {
      a.quick = true;
    } else if (option(argc, argv, i, "--json", v)) {
      if (v.empty()) throw ra::InputError("--json: needs a file name");
      a.json = v;
    } else if (option(argc, argv, i, "--threads", v)) {
      char* end = nullptr;
      const long t = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end || t < 1 || t > 1024)
        throw ra::InputError("--threads: must be a whole number from 1 to 1024, got \"" + v + "\"");
      a.threads = int(t);
    } else if (option(argc, argv, i, "--filter", v)) {
      a.filter = v;
      a.has_filter = true;
    } else if (arg.rfind("--benchmark_out", 0) == 0 || arg.rfind("--benchmark_filter", 0) == 0) {
      throw ra::InputError(arg.substr(0, arg.find('=')) + ": use --json OUT and --filter REGEX instead");
    } else if (arg.rfind("--benchmark_", 0) == 0) {
      check_passthrough(arg);
      a.passthrough.push_back(arg);
    } else {
      throw ra::InputError("rayaudit bench: unknown argument \"" + arg +
                           "\" (--quick, --json OUT, --threads N, --filter REGEX, --benchmark_*)");
    }
  }
  // Listing runs nothing: --json was replaced by an empty file (HOSTILE2 F33).
  if (!a.json.empty())
    for (const auto& p : a.passthrough)
      if (p.rfind("--benchmark_list_tests", 0) == 0 && p != "--benchmark_list_tests=false")
        throw ra::InputError("--benchmark_list_tests: runs no benchmark, so there is nothing for --json: drop one");
  return a;
}

// Google Benchmark's filter: an extended regex searched in the name, "-"
// in front negates it, "" / "all" / "." select everything.
std::function<bool(const std::string&)> filter_matcher(const std::string& spec) {
  if (spec.empty() || spec == "all" || spec == ".") return [](const std::string&) { return true; };
  const bool negate = spec[0] == '-';
  std::shared_ptr<std::regex> re;
  try {
    re = std::make_shared<std::regex>(negate ? spec.substr(1) : spec, std::regex::extended);
  } catch (const std::regex_error& e) {
    throw ra::InputError("--filter: \"" + spec + "\" is not a regular expression: " + e.what());
  }
  return [re, negate](const std::string& name) { return std::regex_search(name, *re) != negate; };
}

// Every registered row the filter selects; an error when none is (an
// unknown group, a mesh not in this run) or a group is named that does not
// exist. Each missing corpus file is named with the script that fetches it.
void check_selection(const Args& a) {
  const auto match = filter_matcher(a.filter);
  std::set<fs::path> needs;
  std::size_t selected = 0;
  bool pov = false;
  for (const rb::Registered& r : rb::registered())
    if (match(r.name)) {
      ++selected;
      needs.insert(r.needs.begin(), r.needs.end());
      pov = pov || r.name.rfind("peer/pov/", 0) == 0;
    }
  // A filter that starts with a plain word before '/' names a group.
  static const std::regex group_word("^\\^?([A-Za-z_]+)/");
  std::smatch m;
  if (a.has_filter && std::regex_search(a.filter, m, group_word)) {
    const std::string g = m[1];
    if (g != "kernel" && g != "scene" && g != "peer" && g != "oracle" && g != "obj")
      throw ra::InputError("--filter: unknown group \"" + g + "\" (groups: " + kGroups + ")");
  }
  if (selected == 0)
    throw ra::InputError("--filter: \"" + a.filter + "\" selects no benchmark" +
                         (a.quick ? " of --quick" : "") + " (groups: " + kGroups + ")");
  for (const fs::path& p : needs) {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      throw ra::InputError(ra::located(p.string(), 0, "missing from the mesh corpus: ci/fetch-corpus.sh fetches it"));
  }
  // A peer that is not installed is an error, not a skip (Embree,
  // tinyobjloader and CGAL are linked in: without them there is no program).
  if (pov) ra::find_povray();
}

// The temporary JSON beside OUT (created now: proves OUT's directory is
// writable before the run), renamed into place at the end.
fs::path make_temp_beside(const fs::path& out) {
  ra::check_output_path(out);
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::random_device rd;
  const fs::path tmp = dir / (".tmp-" + std::to_string(rd()) + "-" + out.filename().string());
  FILE* f = std::fopen(tmp.c_str(), "wx");
  if (!f) throw ra::InputError(ra::located(out.string(), 0, std::string("cannot write: ") + std::strerror(errno)));
  std::fclose(f);
  return tmp;
}

// Ctrl-C or a kill during the run removes the temporary JSON too (the
// handler may only call async-signal-safe functions: unlink, _exit).
char g_tmp_path[4096];
void remove_tmp_and_exit(int sig) {
  if (g_tmp_path[0]) unlink(g_tmp_path);
  _exit(128 + sig);
}

// The console table as usual; remembers whether a row failed.
class Reporter : public benchmark::ConsoleReporter {
 public:
  bool failed = false;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.error_occurred) {
        failed = true;
        std::fprintf(stderr, "rayaudit bench: %s failed: %s\n", r.benchmark_name().c_str(), r.error_message.c_str());
      }
    ConsoleReporter::ReportRuns(runs);
  }
};

void register_all() {
  rb::register_kernel();
  rb::register_scene();
  rb::register_embree();
  rb::register_pov();
  rb::register_cgal();
  rb::register_obj();
  rb::register_oracle();
}

int run(int argc, char** argv) {
  const Args a = parse_args(argc, argv);
  rb::config().quick = a.quick;
  rb::config().threads_all = a.threads > 0 ? a.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  register_all();
  check_selection(a);
  // The rows read the mesh corpus: --json naming one of its files replaced
  // the mesh with the JSON (HOSTILE2 F36).
  if (!a.json.empty()) {
    std::error_code ec;
    const fs::path out = fs::weakly_canonical(a.json, ec), cache = fs::weakly_canonical(ra::cache_dir(), ec);
    const auto rel = out.lexically_relative(cache);
    if (!cache.empty() && !rel.empty() && *rel.begin() != ".." && rel.is_relative())
      throw ra::InputError(ra::located(a.json, 0, "is in the corpus the benchmarks read (" + cache.string() +
                                                      "): choose another output"));
  }
  fs::path tmp;
  if (!a.json.empty()) tmp = make_temp_beside(a.json);
  struct RemoveTmp {
    fs::path p;
    ~RemoveTmp() {
      std::error_code ec;
      if (!p.empty()) fs::remove(p, ec);
    }
  } guard{tmp};
  if (!tmp.empty() && tmp.native().size() < sizeof g_tmp_path) {
    std::strcpy(g_tmp_path, tmp.c_str());
    signal(SIGINT, remove_tmp_and_exit);
    signal(SIGTERM, remove_tmp_and_exit);
    signal(SIGHUP, remove_tmp_and_exit);
  }

  std::vector<std::string> gb_args = {argv[0], "--benchmark_repetitions=" + std::to_string(rb::repetitions()),
                                      "--benchmark_min_time=" + std::to_string(rb::min_time()),
                                      "--benchmark_display_aggregates_only=true"};
  if (a.has_filter) gb_args.push_back("--benchmark_filter=" + a.filter);
  if (!a.json.empty()) {
    gb_args.push_back("--benchmark_out=" + tmp.string());
    gb_args.push_back("--benchmark_out_format=json");
  }
  gb_args.insert(gb_args.end(), a.passthrough.begin(), a.passthrough.end());
  std::vector<char*> gb_argv;
  for (auto& s : gb_args) gb_argv.push_back(s.data());
  int gb_argc = int(gb_argv.size());
  gb_argv.push_back(nullptr);
  benchmark::Initialize(&gb_argc, gb_argv.data());
  if (benchmark::ReportUnrecognizedArguments(gb_argc, gb_argv.data())) return 2;
  Reporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  if (!rb::notes().empty()) {
    std::printf("\n");
    for (const auto& n : rb::notes()) std::printf("%s\n", n.c_str());
  }
  if (reporter.failed) {
    std::fprintf(stderr, "rayaudit bench: some rows failed%s\n", a.json.empty() ? "" : "; nothing written");
    return 1;
  }
  if (!a.json.empty()) {
    // Google Benchmark's writer reports no failed write: on a full disk the
    // JSON came out cut short and replaced the previous file, exit 0
    // (HOSTILE2 F35). Its text is checked whole, then written again with
    // every write, fsync and close checked.
    std::ifstream in(tmp, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    in.close();
    fs::remove(tmp);  // its room, for the checked copy
    guard.p.clear();
    if (!nlohmann::json::accept(text.str()))
      throw ra::InputError(ra::located(a.json, 0, "cannot write: Google Benchmark's JSON came out incomplete (" +
                                                      std::to_string(text.str().size()) +
                                                      " bytes: a full disk?); the previous file is kept"));
    ra::write_text_atomically(a.json, text.str());
    std::printf("wrote %s\n", a.json.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const ra::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rayaudit bench: error: %s\n", e.what());
    return 1;
  }
}
