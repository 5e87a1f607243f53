// How steady a benchmark figure is, measured rather than assumed: every row
// is run once per round (rounds interleave the repetitions of all rows, so
// a slow phase of the host lands on a few repetitions of many rows instead
// of every repetition of a few), a calibration workload is timed before the
// first row and after every row, and each row's figures are summarised by
// their median, quartiles and range over its repetitions (and over several
// processes with --runs). A repetition whose calibration ran slow is marked,
// rerun, and left out of the summary when enough good ones remain; a row
// left without them is flagged. Design and measured figures: bench/README.md.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace rb {

// The fixed workload: 2^18 steps of a dependent xorshift + sqrt chain (no
// memory traffic, nothing the code under test shares), timed three times on
// the wall clock and on the thread's CPU clock; the fastest of each, in
// microseconds. A preemption inflates one timing and is dropped by the
// minimum; a slow phase (a shared core, a throttled or stolen CPU) inflates
// all three. Rows timed in CPU time (kernel/) are judged by the CPU clock's
// calibration (a preemption does not slow them), the others by the wall's.
struct Calibration {
  double wall_us = 0, cpu_us = 0;
};
Calibration calibration_us();

// A repetition is slow when the calibration just before or just after it
// took more than this times the run's median calibration.
inline constexpr double kSlowFactor = 1.15;

// One row's repetition as Google Benchmark's JSON reporter wrote it, with
// where and when it ran.
struct Rep {
  nlohmann::json row;  // run_type "iteration"
  int run = 0, round = 0;
  bool retry = false;
  Calibration cal_before, cal_after;
};

struct CalSample {
  int run = 0;
  double t_s = 0;  // since the run started
  Calibration us;
  std::string after;  // the row it followed ("" at a round's start)
};

// Everything one process measured (a --runs child writes it as JSON).
struct Measured {
  nlohmann::json context;
  std::vector<Rep> reps;
  std::vector<CalSample> cal;
};

// Google Benchmark's JSON text (NaN and Infinity outside strings become null).
nlohmann::json parse_gbench(const std::string& text);

// Marks slow repetitions (kSlowFactor over the median calibration of their
// own run); returns the names of rows with fewer good repetitions than
// `wanted`, to be rerun.
std::vector<std::string> mark_slow(std::vector<Rep>& reps, const std::vector<CalSample>& cal, int wanted);

struct Mode {
  bool quick = false;
  int rounds = 1, runs = 1;
  double min_time = 0;
  std::string filter;
};

// Google Benchmark's JSON (context, every repetition as an iteration row,
// and, with two or more repetitions, the mean/median/stddev/cv aggregate rows
// compare.py reads, over the good repetitions) plus the "rayaudit" object:
// mode, machine, calibration and each row's spread (see bench/README.md).
nlohmann::json assemble(const Measured& m, const Mode& mode);

// A --runs child's JSON back into repetitions and calibration samples, as
// run `run`.
void absorb(const nlohmann::json& child, int run, Measured& into);

// One line a row for the console: flagged rows, slow samples, spreads.
std::string summary(const nlohmann::json& assembled);

// A regular expression selecting exactly these names (Google Benchmark's
// POSIX extended regex).
std::string exact_names_regex(const std::vector<std::string>& names);

}  // namespace rb
