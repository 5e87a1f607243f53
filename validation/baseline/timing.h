// Timing a user's intersector as `rayaudit bench` times the registry's
// kernel/ rows, so it lands on the report's speed chart beside them
// (`rayaudit report --timings FILE`).
//
// Source: bench/kernel_bench.cpp, row kernel/METHOD/PRECISION/nocull/hit=50/
// back=0, the row the speed chart reads: the same 4096 ray/triangle pairs
// (the same generator and seed, half of them hits, every ray from the
// front), timed in the thread's CPU time, ns per test. The subject is
// called through its std::function (the bench calls the registry's
// prepared entry point), which adds about a nanosecond.
//
// From other languages, time your kernel on any representative batch and
// write the same CSV: a header `subject,ns_per_test`, then one row per
// METHOD/PRECISION as the audit names it (`mine/float`).
#pragma once
#include <string>
#include <vector>

#include "exact/audit.h"

namespace ra::audit {

struct Timing {
  std::string subject;  // "METHOD/PRECISION"
  double ns_per_test = 0;
};

// The median of `repetitions` runs, each at least `min_seconds` of CPU time.
Timing time_subject(const TriangleSubject& s, int repetitions = 5, double min_seconds = 0.1);

// The CSV `rayaudit report --timings` reads (written atomically).
void write_timings_csv(const std::string& path, const std::vector<Timing>& rows);

}  // namespace ra::audit
