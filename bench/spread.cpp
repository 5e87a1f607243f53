// Spread, calibration and the JSON of rayaudit-bench (spread.h).
#include "spread.h"
#include "io/json_input.h"

#include <benchmark/benchmark.h>
#include <sys/utsname.h>
#include <time.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace rb {

using nlohmann::json;

namespace {
double thread_cpu_us() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e6 * double(t.tv_sec) + 1e-3 * double(t.tv_nsec);
}
}  // namespace

Calibration calibration_us() {
  Calibration best{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  for (int k = 0; k < 3; ++k) {
    const double c0 = thread_cpu_us();
    const auto t0 = std::chrono::steady_clock::now();
    std::uint64_t x = 0x9E3779B97F4A7C15ull;
    double s = 0;
    for (int i = 0; i < (1 << 18); ++i) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      s += std::sqrt(double(x & 0xFFFFF) + s * 1e-9);
    }
    benchmark::DoNotOptimize(s);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    best.wall_us = std::min(best.wall_us, us);
    best.cpu_us = std::min(best.cpu_us, thread_cpu_us() - c0);
  }
  return best;
}

json parse_gbench(const std::string& in) { return json::parse(ra::gbench_non_finite_to_null(in)); }

namespace {

double median_of(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// numpy.percentile's default (linear between closest ranks), as the
// report's Python computes it.
double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const std::size_t lo = std::size_t(std::floor(pos)), hi = std::min(v.size() - 1, lo + 1);
  return v[lo] + (pos - double(lo)) * (v[hi] - v[lo]);
}

json five(const std::vector<double>& v) {
  if (v.empty()) return nullptr;
  return {{"median", median_of(v)},
          {"q1", quantile(v, 0.25)},
          {"q3", quantile(v, 0.75)},
          {"min", *std::min_element(v.begin(), v.end())},
          {"max", *std::max_element(v.begin(), v.end())}};
}

// Google Benchmark's own keys of a run row; every other number is a counter.
bool gb_key(const std::string& k) {
  static const std::set<std::string> keys{"name",
                                          "family_index",
                                          "per_family_instance_index",
                                          "run_name",
                                          "run_type",
                                          "repetitions",
                                          "repetition_index",
                                          "threads",
                                          "iterations",
                                          "time_unit",
                                          "error_occurred",
                                          "error_message",
                                          "aggregate_name",
                                          "aggregate_unit",
                                          "label",
                                          "skipped"};
  return keys.count(k) || k.rfind("rayaudit_", 0) == 0;
}

// The figure each group's charts draw, and which way is better.
std::pair<std::string, std::string> metric_of(const std::string& name) {
  const std::string g = name.substr(0, name.find('/'));
  if (g == "kernel") return {"ns_per_test", "lower"};
  if (g == "scene") return {"Mrays_per_s", "higher"};
  if (g == "peer") return {"ratio", "higher"};  // rayaudit's rate over the peer's
  if (g == "obj") return {"MB_per_s", "higher"};
  if (g == "oracle") return {"cases/s", "higher"};
  return {"real_time", "lower"};
}

std::string row_name(const json& r) { return r.value("run_name", r.value("name", std::string())); }

bool failed(const Rep& r) { return r.row.value("error_occurred", false); }

// The kernel rows time the thread's CPU; every other group the wall clock.
bool cpu_timed(const std::string& name) { return name.rfind("kernel/", 0) == 0; }

json machine() {
  json m;
  std::ifstream ci("/proc/cpuinfo");
  std::string line, model, family, cpu_model, stepping;
  bool hv = false;
  int cores = 0;
  while (std::getline(ci, line)) {
    auto val = [&] {
      const auto p = line.find(':');
      return p == std::string::npos ? std::string() : line.substr(p + 2);
    };
    if (line.rfind("processor", 0) == 0)
      ++cores;
    else if (model.empty() && line.rfind("model name", 0) == 0)
      model = val();
    else if (family.empty() && line.rfind("cpu family", 0) == 0)
      family = val();
    else if (cpu_model.empty() && line.rfind("model\t", 0) == 0)
      cpu_model = val();
    else if (stepping.empty() && line.rfind("stepping", 0) == 0)
      stepping = val();
    else if (line.rfind("flags", 0) == 0 && (" " + val() + " ").find(" hypervisor ") != std::string::npos)
      hv = true;
  }
  m["cpu_model"] = model;
  m["cpu_family_model_stepping"] = family + "/" + cpu_model + "/" + stepping;
  m["cores"] = cores;
  m["hypervisor_flag"] = hv;  // the CPU says it runs under a hypervisor
  std::string virt;
  if (FILE* p = popen("systemd-detect-virt 2>/dev/null", "r")) {
    char buf[128] = {};
    if (std::fgets(buf, sizeof buf, p)) virt = buf;
    pclose(p);
    while (!virt.empty() && std::isspace((unsigned char)virt.back())) virt.pop_back();
  }
  std::error_code ec;
  if (virt.empty() && std::filesystem::exists("/sys/hypervisor/type", ec)) {
    std::ifstream t("/sys/hypervisor/type");
    std::getline(t, virt);
  }
  m["virtualization"] = virt.empty() ? (hv ? "virtual machine (hypervisor flag)" : "none detected") : virt;
  utsname u{};
  if (uname(&u) == 0) m["kernel"] = std::string(u.sysname) + " " + u.release;
  return m;
}

// The CPU time the hypervisor gave to others (steal) and all CPU time, from
// /proc/stat, in clock ticks.
std::pair<double, double> steal_and_total() {
  std::ifstream st("/proc/stat");
  std::string cpu;
  double v[10] = {};
  st >> cpu;
  for (double& x : v) st >> x;
  double total = 0;
  for (int i = 0; i < 8; ++i) total += v[i];
  return {v[7], total};
}

// At the program's start: the steal share covers the whole run.
const std::pair<double, double> g_steal_at_start = steal_and_total();

}  // namespace

std::vector<std::string> mark_slow(std::vector<Rep>& reps, const std::vector<CalSample>& cal, int wanted) {
  // Per clock (0 wall, 1 CPU): each run's median calibration, the fastest run's.
  std::map<int, std::vector<double>> per_run[2];
  for (const CalSample& c : cal) per_run[0][c.run].push_back(c.us.wall_us), per_run[1][c.run].push_back(c.us.cpu_us);
  std::map<int, double> med[2];
  double fastest[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  for (int k = 0; k < 2; ++k)
    for (auto& [run, v] : per_run[k]) fastest[k] = std::min(fastest[k], med[k][run] = median_of(v));
  std::map<std::string, int> good;
  std::vector<std::string> order;
  for (Rep& r : reps) {
    const std::string n = row_name(r.row);
    if (!good.count(n)) order.push_back(n), good[n] = 0;
    if (failed(r)) continue;
    const int k = cpu_timed(n) ? 1 : 0;
    const double m = med[k].count(r.run) ? med[k][r.run] : 0;
    auto of = [k](const Calibration& c) { return k ? c.cpu_us : c.wall_us; };
    std::string why;
    if (m > 0 && std::max(of(r.cal_before), of(r.cal_after)) > kSlowFactor * m)
      why = std::string("calibration beside it slow (") + (k ? "CPU" : "wall") + " clock)";
    else if (m > kSlowFactor * fastest[k])
      why = std::string("its whole run was slow (") + (k ? "CPU" : "wall") + " clock)";
    r.row["rayaudit_slow_phase"] = !why.empty();
    if (!why.empty())
      r.row["rayaudit_slow_why"] = why;
    else
      ++good[n];
  }
  std::vector<std::string> again;
  for (const auto& n : order)
    if (good[n] < wanted) again.push_back(n);
  return again;
}

void absorb(const json& child, int run, Measured& into) {
  if (into.context.is_null()) into.context = child.at("context");
  for (const json& b : child.at("benchmarks")) {
    if (b.value("run_type", "") != "iteration") continue;
    Rep r;
    r.row = b;
    r.run = run;
    r.round = b.value("rayaudit_round", 0);
    r.retry = b.value("rayaudit_retry", false);
    r.cal_before = {b.value("rayaudit_cal_before_us", 0.0), b.value("rayaudit_cal_before_cpu_us", 0.0)};
    r.cal_after = {b.value("rayaudit_cal_after_us", 0.0), b.value("rayaudit_cal_after_cpu_us", 0.0)};
    into.reps.push_back(std::move(r));
  }
  for (const json& s : child.at("rayaudit").at("calibration").at("samples"))
    into.cal.push_back({run,
                        s.at("t_s").get<double>(),
                        {s.at("us").get<double>(), s.at("cpu_us").get<double>()},
                        s.value("after", "")});
}

json assemble(const Measured& m, const Mode& mode) {
  json out;
  out["context"] = m.context;
  json benchmarks = json::array();
  // Rows in first-seen order, each row's repetitions together.
  std::vector<std::string> order;
  std::map<std::string, std::vector<const Rep*>> by_row;
  for (const Rep& r : m.reps) {
    const std::string n = row_name(r.row);
    if (!by_row.count(n)) order.push_back(n);
    by_row[n].push_back(&r);
  }
  std::map<int, std::vector<double>> cal_runs, cal_cpu_runs;
  for (const CalSample& c : m.cal) cal_runs[c.run].push_back(c.us.wall_us), cal_cpu_runs[c.run].push_back(c.us.cpu_us);
  json rows = json::array();
  int flagged = 0, slow_reps = 0, retried = 0;
  for (const std::string& n : order) {
    const auto& reps = by_row[n];
    std::vector<const Rep*> good, ok;  // good: not failed, not slow; ok: not failed
    for (std::size_t i = 0; i < reps.size(); ++i) {
      json row = reps[i]->row;
      row["rayaudit_run"] = reps[i]->run;
      row["rayaudit_round"] = reps[i]->round;
      row["rayaudit_retry"] = reps[i]->retry;
      row["rayaudit_cal_before_us"] = reps[i]->cal_before.wall_us;
      row["rayaudit_cal_after_us"] = reps[i]->cal_after.wall_us;
      row["rayaudit_cal_before_cpu_us"] = reps[i]->cal_before.cpu_us;
      row["rayaudit_cal_after_cpu_us"] = reps[i]->cal_after.cpu_us;
      row["repetition_index"] = int(i);
      row["repetitions"] = int(reps.size());
      benchmarks.push_back(row);
      if (failed(*reps[i])) continue;
      ok.push_back(reps[i]);
      if (!reps[i]->row.value("rayaudit_slow_phase", false)) good.push_back(reps[i]);
    }
    const auto used = good.empty() ? ok : good;
    if (used.empty()) continue;
    // Every number the rows carry, over the repetitions used.
    std::map<std::string, std::vector<double>> values;
    for (const Rep* r : used)
      for (auto it = r->row.begin(); it != r->row.end(); ++it)
        if (it.value().is_number() && !gb_key(it.key())) values[it.key()].push_back(it.value().get<double>());
    if (used.size() >= 2) {
      // compare.py's aggregate rows, as Google Benchmark names them.
      for (const char* agg : {"mean", "median", "stddev", "cv"}) {
        json a = used.front()->row;
        for (auto k : {"rayaudit_slow_phase", "rayaudit_slow_why", "repetition_index", "error_occurred"}) a.erase(k);
        a["name"] = n + "_" + agg;
        a["run_type"] = "aggregate";
        a["aggregate_name"] = agg;
        a["aggregate_unit"] = std::string(agg) == "cv" ? "percentage" : "time";
        a["repetitions"] = int(used.size());
        for (const auto& [k, v] : values) {
          double mean = 0;
          for (double x : v) mean += x;
          mean /= double(v.size());
          double var = 0;
          for (double x : v) var += (x - mean) * (x - mean);
          const double sd = std::sqrt(var / double(v.size() - 1));
          const std::string s = agg;
          const double val = s == "mean"     ? mean
                             : s == "median" ? median_of(v)
                             : s == "stddev" ? sd
                                             : (mean != 0 ? sd / mean : std::nan(""));
          a[k] = std::isfinite(val) ? json(val) : json(nullptr);
        }
        benchmarks.push_back(a);
      }
    }
    const auto [metric, better] = metric_of(n);
    json e = {{"name", n},
              {"metric", metric},
              {"better", better},
              {"repetitions", int(ok.size())},
              {"used", int(used.size())},
              {"slow_repetitions", int(ok.size() - good.size())}};
    slow_reps += int(ok.size() - good.size());
    const bool had_retry = std::any_of(reps.begin(), reps.end(), [](const Rep* r) { return r->retry; });
    retried += had_retry;
    e["retried"] = had_retry;
    if (values.count(metric)) {
      const json f = five(values[metric]);
      for (auto it = f.begin(); it != f.end(); ++it) e[it.key()] = it.value();
    }
    json per_run = json::array();
    std::map<int, std::vector<double>> run_vals;
    for (const Rep* r : used)
      if (r->row.contains(metric) && r->row[metric].is_number())
        run_vals[r->run].push_back(r->row[metric].get<double>());
    for (const auto& [run, v] : run_vals)
      per_run.push_back({{"run", run}, {"median", median_of(v)}, {"n", int(v.size())}});
    e["run_medians"] = per_run;
    std::string flag;
    if (int(good.size()) < mode.rounds * mode.runs && good.size() < ok.size())
      flag = "slow phase: " + std::to_string(good.size()) + " of " + std::to_string(ok.size()) +
             " repetitions ran at normal speed" + (good.empty() ? " (figures from the slow ones)" : "");
    if (run_vals.size() >= 2 && e.contains("median")) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const auto& [run, v] : run_vals) lo = std::min(lo, median_of(v)), hi = std::max(hi, median_of(v));
      const double med = e["median"].get<double>(), iqr = e["q3"].get<double>() - e["q1"].get<double>();
      if (hi - lo > std::max(0.10 * std::abs(med), iqr))
        flag += std::string(flag.empty() ? "" : "; ") + "runs disagree: their medians span " +
                std::to_string(int(std::lround(100 * (hi - lo) / std::abs(med)))) + "% of the median";
    }
    e["flagged"] = flag;
    flagged += !flag.empty();
    json counters = json::object();
    for (const auto& [k, v] : values)
      if (k != metric) counters[k] = five(v);
    e["figures"] = counters;
    rows.push_back(e);
  }
  out["benchmarks"] = benchmarks;

  json cal = json::array();
  for (const CalSample& c : m.cal) {
    json s = {{"run", c.run}, {"t_s", c.t_s}, {"us", c.us.wall_us}, {"cpu_us", c.us.cpu_us}};
    if (!c.after.empty()) s["after"] = c.after;
    cal.push_back(s);
  }
  json runs = json::array();
  for (const auto& [run, v] : cal_runs)
    runs.push_back(
        {{"run", run}, {"five", five(v)}, {"cpu_five", five(cal_cpu_runs[run])}, {"samples", int(v.size())}});
  const auto steal0 = g_steal_at_start;
  const auto steal1 = steal_and_total();
  out["rayaudit"] = {
      {"format", 1},
      {"mode", mode.quick ? "quick" : "full"},
      {"rounds", mode.rounds},
      {"runs", mode.runs},
      {"min_time_s", mode.min_time},
      {"filter", mode.filter},
      {"interleaving",
       "every selected row once per round, rounds one after another; with --runs, each run a "
       "separate process"},
      {"machine", machine()},
      {"steal_pct",
       steal1.second > steal0.second ? 100.0 * (steal1.first - steal0.first) / (steal1.second - steal0.second) : 0.0},
      {"calibration",
       {{"workload",
         "2^18 steps of a dependent xorshift + sqrt chain, fastest of 3 timings on the wall clock (us) "
         "and on the thread's CPU clock (cpu_us)"},
        {"unit", "us"},
        {"judged_by", "kernel/ rows (timed in thread CPU time) by cpu_us, every other row by us"},
        {"slow_factor", kSlowFactor},
        {"runs", runs},
        {"samples", cal}}},
      {"rows", rows},
      {"flagged_rows", flagged},
      {"slow_repetitions", slow_reps},
      {"retried_rows", retried}};
  return out;
}

std::string summary(const json& a) {
  std::ostringstream s;
  const json& r = a.at("rayaudit");
  std::vector<double> rel;
  for (const json& e : r.at("rows"))
    if (e.contains("median") && e["median"].get<double>() != 0)
      rel.push_back((e["q3"].get<double>() - e["q1"].get<double>()) / std::abs(e["median"].get<double>()));
  s << "spread: " << r.at("rows").size() << " rows, " << r.at("rounds") << " repetition(s) each (interleaved), "
    << r.at("runs") << " run(s)";
  if (!rel.empty()) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "; interquartile range over the median: median %.1f%%, worst %.1f%%",
                  100 * median_of(rel), 100 * *std::max_element(rel.begin(), rel.end()));
    s << buf;
  }
  s << "\n";
  for (const json& run : r.at("calibration").at("runs")) {
    const json &f = run.at("five"), &c = run.at("cpu_five");
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "calibration (run %d, %d samples): wall median %.0f us (%.0f-%.0f), CPU median %.0f us (%.0f-%.0f)\n",
                  run.at("run").get<int>(), run.at("samples").get<int>(), f.at("median").get<double>(),
                  f.at("min").get<double>(), f.at("max").get<double>(), c.at("median").get<double>(),
                  c.at("min").get<double>(), c.at("max").get<double>());
    s << buf;
  }
  s << "slow repetitions: " << r.at("slow_repetitions") << " (calibration over " << kSlowFactor
    << "x its run's median, or a slow run); rows rerun: " << r.at("retried_rows")
    << "; rows flagged: " << r.at("flagged_rows") << "\n";
  int shown = 0;
  for (const json& e : r.at("rows"))
    if (!e.at("flagged").get<std::string>().empty() && shown++ < 20)
      s << "  flagged " << e.at("name").get<std::string>() << ": " << e.at("flagged").get<std::string>() << "\n";
  return s.str();
}

std::string exact_names_regex(const std::vector<std::string>& names) {
  std::string re = "^(";
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) re += '|';
    for (char c : names[i]) {
      if (std::strchr(".[]{}()*+?^$|\\", c)) re += '\\';
      re += c;
    }
  }
  return re + ")$";
}

}  // namespace rb
