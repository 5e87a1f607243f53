// rayaudit-bench, run as `rayaudit bench`: every group registered,
// the arguments checked before anything runs (one line and exit 2 on bad
// input, nothing written), then Google Benchmark, whose JSON is kept in
// memory and written atomically to --json OUT only when every row succeeded.
//
//   rayaudit-bench [--quick] [--json OUT] [--threads N] [--filter REGEX] [--runs N] [--benchmark_*...]
//
// Repetitions are rounds: every selected row once per round, so a slow phase
// of the host spreads over many rows' single repetitions, where it shows as
// spread, instead of hiding in all repetitions of a few rows (spread.h).
#include <malloc.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <new>
#include <random>
#include <regex>
#include <set>
#include <fstream>
#include <functional>
#include <sstream>

#include "io/atomic_file.h"
#include "io/file_identity.h"
#include "bench.h"
#include "errors.h"
#include "pov/pov_runner.h"
#include "spread.h"

// ---- Heap accounting (peak bytes per triangle of the OBJ parsers, bytes of
// our acceleration structures): every operator new counts its usable size.
namespace {
std::atomic<long> g_live{0}, g_peak{0};
// Adds a fresh block's usable size to the live count and raises the peak.
void* counted(void* p) {
  if (!p) throw std::bad_alloc();
  const long size = long(malloc_usable_size(p));
  const long now = g_live.fetch_add(size, std::memory_order_relaxed) + size;
  long peak = g_peak.load(std::memory_order_relaxed);
  while (now > peak && !g_peak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
  return p;
}
void* counted_alloc(std::size_t n) { return counted(std::malloc(n ? n : 1)); }
void counted_free(void* p) {
  if (!p) return;
  g_live.fetch_sub(long(malloc_usable_size(p)), std::memory_order_relaxed);
  std::free(p);
}
// Over-aligned types (the BVH's 64-byte nodes, the 32-byte leaf blocks) come
// through the align_val_t forms; without these they went uncounted, and a
// BVH's bytes per triangle showed less than the loop's.
void* counted_aligned_alloc(std::size_t n, std::align_val_t al) {
  void* p = nullptr;
  const std::size_t a = std::max(sizeof(void*), std::size_t(al));
  return counted(posix_memalign(&p, a, n ? n : 1) == 0 ? p : nullptr);
}
}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }
void* operator new(std::size_t n, std::align_val_t al) { return counted_aligned_alloc(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return counted_aligned_alloc(n, al); }
void operator delete(void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }

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
  int rounds = 0;                        // --benchmark_repetitions (0: the mode's)
  int runs = 1;                          // --runs: separate processes, one after another
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

// Google Benchmark's own flags, checked here because its parser prints
// several lines, usage text with exit 0, or throws (a negative repetition
// count: "vector::reserve") on a bad value. The bounds keep a
// run finite: at most 1000 repetitions, at most 60 s a row.
bool gb_bool(const std::string& v) {
  static const std::set<std::string> ok{"",  "true", "false", "yes",   "no",   "1",     "0",   "t", "f",
                                        "y", "n",    "True",  "False", "TRUE", "FALSE", "Yes", "No"};
  return ok.count(v) != 0;
}
bool gb_true(const std::string& v) {
  return v.empty() || v == "true" || v == "yes" || v == "1" || v == "t" || v == "y" || v == "True" || v == "TRUE" ||
         v == "Yes";
}

bool whole_number(const std::string& v, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(v.c_str(), &end, 10);
  return !v.empty() && !*end && errno == 0 && n >= lo && n <= hi && std::isdigit((unsigned char)v[0]);
}

bool seconds(const std::string& v, double hi) {
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  const bool decimal = !v.empty() && v.find_first_not_of("0123456789.") == std::string::npos;
  return decimal && !*end && d >= 0 && d <= hi;
}

void check_benchmark_flag(const std::string& arg) {
  const std::size_t eq = arg.find('=');
  const std::string name = arg.substr(0, eq);
  const bool has_value = eq != std::string::npos;
  const std::string v = has_value ? arg.substr(eq + 1) : "";
  auto refuse = [&](const std::string& what) {
    throw ra::InputError(name + ": " + (has_value ? "\"" + v + "\" " : std::string()) + what);
  };
  if (name == "--benchmark_repetitions") {
    if (!whole_number(v, 1, 1000)) refuse("is not a whole number from 1 to 1000");
  } else if (name == "--benchmark_min_time" || name == "--benchmark_min_warmup_time") {
    if (!seconds(v, 60)) refuse("is not a number of seconds from 0 to 60");
  } else if (name == "--benchmark_list_tests" || name == "--benchmark_display_aggregates_only" ||
             name == "--benchmark_report_aggregates_only" || name == "--benchmark_enable_random_interleaving" ||
             name == "--benchmark_counters_tabular") {
    if (!gb_bool(v)) refuse("is not true or false");
  } else if (name == "--benchmark_format") {
    // Our console table is always the display; the JSON goes to --json.
    if (v != "console") refuse("is not supported: the table is always printed (console); --json OUT writes JSON");
  } else if (name == "--benchmark_color") {
    if (v != "auto" && !gb_bool(v)) refuse("is not auto, true or false");
  } else if (name == "--benchmark_time_unit") {
    if (v != "ns" && v != "us" && v != "ms" && v != "s") refuse("is not ns, us, ms or s");
  } else if (name == "--benchmark_perf_counters" || name == "--benchmark_context") {
    if (!has_value || v.empty()) refuse("needs a value");
  } else {
    refuse(
        "is not a Google Benchmark flag rayaudit bench passes on (repetitions, min_time, min_warmup_time, "
        "list_tests, display_aggregates_only, report_aggregates_only, enable_random_interleaving, "
        "counters_tabular, format, color, time_unit, perf_counters, context)");
  }
}

// The last --benchmark_list_tests given, as Google Benchmark reads it.
bool lists_tests(const std::vector<std::string>& passthrough) {
  bool list = false;
  for (const auto& arg : passthrough)
    if (arg.rfind("--benchmark_list_tests", 0) == 0) {
      const std::size_t eq = arg.find('=');
      list = gb_true(eq == std::string::npos ? "" : arg.substr(eq + 1));
    }
  return list;
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
    } else if (option(argc, argv, i, "--runs", v)) {
      if (!whole_number(v, 1, 20))
        throw ra::InputError("--runs: must be a whole number from 1 to 20, got \"" + v + "\"");
      a.runs = int(std::strtol(v.c_str(), nullptr, 10));
    } else if (arg.rfind("--benchmark_out", 0) == 0 || arg.rfind("--benchmark_filter", 0) == 0) {
      throw ra::InputError(arg.substr(0, arg.find('=')) + ": use --json OUT and --filter REGEX instead");
    } else if (arg.rfind("--benchmark_", 0) == 0) {
      check_benchmark_flag(arg);
      // Repetitions are run as rounds here (each row once per round).
      if (arg.rfind("--benchmark_repetitions=", 0) == 0)
        a.rounds = int(std::strtol(arg.c_str() + 24, nullptr, 10));
      else
        a.passthrough.push_back(arg);
    } else {
      throw ra::InputError("rayaudit bench: unknown argument \"" + arg +
                           "\" (--quick, --json OUT, --threads N, --filter REGEX, --runs N, --benchmark_*)");
    }
  }
  // Listing runs nothing, so there would be no JSON: replacing OUT with an
  // empty file is refused rather than done.
  if (!a.json.empty() && lists_tests(a.passthrough))
    throw ra::InputError("--benchmark_list_tests: lists the rows and runs none, so there is no JSON; drop --json");
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
    throw ra::InputError("--filter: \"" + a.filter + "\" selects no benchmark" + (a.quick ? " of --quick" : "") +
                         " (groups: " + kGroups + ")");
  for (const fs::path& p : needs) {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      throw ra::InputError(ra::located(p.string(), 0, "missing from the mesh corpus: ci/fetch-corpus.sh fetches it"));
    ra::note_input(p);  // --json naming a corpus mesh is refused
  }
  // A peer that is not installed is an error, not a skip (Embree,
  // tinyobjloader and CGAL are linked in: without them there is no program).
  if (pov) ra::find_povray();
}

// Google Benchmark's JSON, kept in memory and written with
// write_text_atomically at the end: its own file writer does not report a
// full disk (exit 0 and a truncated JSON in place of the old
// file). Google Benchmark hands a file reporter the stream of
// --benchmark_out (set to /dev/null); this one forwards to a JSONReporter
// writing into a string instead.
class MemoryJson : public benchmark::BenchmarkReporter {
 public:
  MemoryJson() {
    inner_.SetOutputStream(&text_);
    inner_.SetErrorStream(&text_);
  }
  bool ReportContext(const Context& c) override { return inner_.ReportContext(c); }
  void ReportRuns(const std::vector<Run>& runs) override { inner_.ReportRuns(runs); }
  void Finalize() override { inner_.Finalize(); }
  std::string text() const { return text_.str(); }

 private:
  std::ostringstream text_;
  benchmark::JSONReporter inner_;
};

// The console table as usual (the context banner once); remembers whether a
// row failed, and after every row times the calibration workload, so each
// repetition has the calibration just before and just after it.
class Reporter : public benchmark::ConsoleReporter {
 public:
  explicit Reporter(OutputOptions options) : ConsoleReporter(options) {}
  bool failed = false;
  std::function<rb::Calibration(const std::string&)> calibrate;  // times the workload, records the sample
  struct Seen {
    std::string name;
    rb::Calibration before, after;
  };
  std::vector<Seen> seen;  // this round's rows, in order
  rb::Calibration last;
  bool ReportContext(const Context& c) override {
    if (context_shown_) return true;
    context_shown_ = true;
    return ConsoleReporter::ReportContext(c);
  }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.error_occurred) {
        failed = true;
        std::fprintf(stderr, "rayaudit bench: %s failed: %s\n", r.benchmark_name().c_str(), r.error_message.c_str());
      }
    ConsoleReporter::ReportRuns(runs);
    if (calibrate && !runs.empty()) {
      const std::string name = runs.front().run_name.str();
      const rb::Calibration after = calibrate(name);
      seen.push_back({name, last, after});
      last = after;
    }
  }

 private:
  bool context_shown_ = false;
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

std::string self_exe(const char* argv0) {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(argv0) : p.string();
}

// The run in progress under --runs, and the signal that interrupted it: a
// SIGINT or SIGTERM (Ctrl-C, a CI job's timeout) ends that run and then
// this process by the normal path, so the temporary directory of the runs'
// JSONs is removed rather than left behind; the signal is raised again after.
volatile sig_atomic_t g_child = 0, g_interrupt = 0;
extern "C" void on_interrupt(int sig) {
  g_interrupt = sig;
  if (g_child > 0) kill(pid_t(g_child), SIGTERM);
}

// --runs N: this program N times, one process after another, each writing
// its JSON into a temporary directory; then one JSON over all of them.
int run_processes(const Args& a, const rb::Mode& mode, const char* argv0) {
  std::string tmpl = (fs::temp_directory_path() / "rayaudit-bench-runs-XXXXXX").string();  // $TMPDIR or /tmp
  if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot make a temporary directory in " + tmpl);
  struct Cleanup {
    fs::path p;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(p, ec);
    }
  } cleanup{tmpl};
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  const std::string exe = self_exe(argv0);
  rb::Measured m;
  for (int i = 0; i < a.runs; ++i) {
    const fs::path out = fs::path(tmpl) / ("run-" + std::to_string(i) + ".json");
    std::vector<std::string> args{exe, "--json=" + out.string(),
                                  "--benchmark_repetitions=" + std::to_string(mode.rounds)};
    if (a.quick) args.push_back("--quick");
    if (a.threads > 0) args.push_back("--threads=" + std::to_string(a.threads));
    if (a.has_filter) args.push_back("--filter=" + a.filter);
    args.insert(args.end(), a.passthrough.begin(), a.passthrough.end());
    std::printf("==== run %d of %d (a separate process) ====\n", i + 1, a.runs);
    std::fflush(stdout);
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("cannot start " + exe);
    if (pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGTERM);  // an interrupted parent takes its run along
      std::vector<char*> cargv;
      for (auto& s : args) cargv.push_back(s.data());
      cargv.push_back(nullptr);
      execv(exe.c_str(), cargv.data());
      _exit(127);
    }
    g_child = pid;
    if (g_interrupt) kill(pid, SIGTERM);  // the signal came before g_child was set
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    g_child = 0;
    if (g_interrupt) {
      std::fprintf(stderr, "rayaudit bench: interrupted in run %d of %d; nothing written\n", i + 1, a.runs);
      return 128 + g_interrupt;  // run() raises it again once the directory is gone
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::fprintf(stderr, "rayaudit bench: run %d of %d failed%s\n", i + 1, a.runs,
                   a.json.empty() ? "" : "; nothing written");
      return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
    }
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    rb::absorb(rb::parse_gbench(ss.str()), i, m);
  }
  // Again over all runs: a run whose calibration was slow as a whole.
  rb::mark_slow(m.reps, m.cal, mode.rounds * mode.runs);
  const nlohmann::json all = rb::assemble(m, mode);
  std::printf("\n%s", rb::summary(all).c_str());
  if (!a.json.empty()) {
    ra::write_text_atomically(a.json, all.dump(1) + "\n");
    std::printf("wrote %s\n", a.json.c_str());
  }
  return 0;
}

int run(int argc, char** argv) {
  const Args a = parse_args(argc, argv);
  rb::config().quick = a.quick;
  rb::config().threads_all = a.threads > 0 ? a.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  register_all();
  check_selection(a);
  // Checked before the run: the directory, the name, and that it is not
  // a corpus file this run reads (note_input above).
  if (!a.json.empty()) ra::declare_output(a.json);
  const bool listing = lists_tests(a.passthrough);
  rb::Mode mode;
  mode.quick = a.quick;
  mode.rounds = a.rounds > 0 ? a.rounds : rb::repetitions();
  mode.runs = a.runs;
  mode.min_time = rb::min_time();
  mode.filter = a.filter;
  if (a.runs > 1 && !listing) {
    const int rc = run_processes(a, mode, argv[0]);
    if (g_interrupt) {  // the runs' directory is removed: die of the signal, as the shell expects
      signal(g_interrupt, SIG_DFL);
      raise(g_interrupt);
    }
    return rc;
  }

  // One repetition per round; the rounds are the repetitions.
  std::vector<std::string> gb_args = {argv[0], "--benchmark_repetitions=1",
                                      "--benchmark_min_time=" + std::to_string(rb::min_time()),
                                      "--benchmark_out=/dev/null", "--benchmark_out_format=json"};
  gb_args.insert(gb_args.end(), a.passthrough.begin(), a.passthrough.end());
  std::vector<char*> gb_argv;
  for (auto& s : gb_args) gb_argv.push_back(s.data());
  int gb_argc = int(gb_argv.size());
  gb_argv.push_back(nullptr);
  benchmark::Initialize(&gb_argc, gb_argv.data());
  if (benchmark::ReportUnrecognizedArguments(gb_argc, gb_argv.data())) return 2;
  // Colour only on a terminal, unless --benchmark_color says: a reporter
  // passed in, as this one is, colours by default, which put escapes in
  // every log file the table was redirected to.
  const char* term = std::getenv("TERM");
  bool colour = isatty(STDOUT_FILENO) && term && std::strcmp(term, "dumb") != 0;
  for (const std::string& p : a.passthrough)
    if (p.rfind("--benchmark_color", 0) == 0) {
      const std::string v = p.find('=') == std::string::npos ? "" : p.substr(p.find('=') + 1);
      if (v != "auto") colour = gb_true(v);
    }
  Reporter reporter(colour ? benchmark::ConsoleReporter::OO_ColorTabular : benchmark::ConsoleReporter::OO_Tabular);
  // Google Benchmark prints its context banner on the error stream; on
  // stdout, stderr holds only errors (one line for a full disk at the end).
  reporter.SetErrorStream(&std::cout);
  const std::string spec = a.has_filter && !a.filter.empty() ? a.filter : ".";
  if (listing) {
    benchmark::RunSpecifiedBenchmarks(&reporter, spec);
    benchmark::Shutdown();
    return 0;
  }

  rb::Measured m;
  const auto t_start = rb::now();
  reporter.calibrate = [&](const std::string& after) {
    const rb::Calibration us = rb::calibration_us();
    m.cal.push_back({0, rb::seconds_since(t_start), us, after});
    return us;
  };
  // One pass over the rows selected by `filter`; its repetitions join m.
  auto round = [&](int index, const std::string& filter, bool retry) {
    reporter.seen.clear();
    reporter.last = reporter.calibrate("");
    MemoryJson json;
    benchmark::RunSpecifiedBenchmarks(&reporter, &json, filter);
    const nlohmann::json j = rb::parse_gbench(json.text());
    if (m.context.is_null()) m.context = j.at("context");
    std::size_t k = 0;
    for (const auto& b : j.at("benchmarks")) {
      if (b.value("run_type", "") != "iteration") continue;
      rb::Rep r;
      r.row = b;
      r.round = index;
      r.retry = retry;
      const std::string name = b.value("run_name", b.value("name", std::string()));
      // The reporter saw the same rows in the same order.
      while (k < reporter.seen.size() && reporter.seen[k].name != name) ++k;
      if (k < reporter.seen.size()) {
        r.cal_before = reporter.seen[k].before;
        r.cal_after = reporter.seen[k].after;
        ++k;
      }
      m.reps.push_back(std::move(r));
    }
  };
  for (int i = 0; i < mode.rounds; ++i) {
    if (mode.rounds > 1) std::printf("---- repetition %d of %d (every row once) ----\n", i + 1, mode.rounds);
    std::fflush(stdout);
    round(i, spec, false);
    if (reporter.failed) break;
  }
  // Repetitions beside a slow calibration are run again (twice at most),
  // unless most of more than 8 rows would be: then the whole run is slow, and says so.
  std::set<std::string> all_rows;
  for (const auto& r : m.reps) all_rows.insert(r.row.value("run_name", std::string()));
  for (int pass = 0; !reporter.failed && pass < 2; ++pass) {
    const std::vector<std::string> again = rb::mark_slow(m.reps, m.cal, mode.rounds);
    if (again.empty() || (2 * again.size() > all_rows.size() && again.size() > 8)) break;
    std::printf("---- again: %zu row(s) had a repetition beside a slow calibration ----\n", again.size());
    std::fflush(stdout);
    round(mode.rounds + pass, rb::exact_names_regex(again), true);
  }
  rb::mark_slow(m.reps, m.cal, mode.rounds);
  benchmark::Shutdown();
  if (!rb::notes().empty()) {
    std::printf("\n");
    for (const auto& n : rb::notes()) std::printf("%s\n", n.c_str());
  }
  if (reporter.failed) {
    std::fprintf(stderr, "rayaudit bench: some rows failed%s\n", a.json.empty() ? "" : "; nothing written");
    return 1;
  }
  const nlohmann::json all = rb::assemble(m, mode);
  std::printf("\n%s", rb::summary(all).c_str());
  if (!a.json.empty()) {
    ra::write_text_atomically(a.json, all.dump(1) + "\n");
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
