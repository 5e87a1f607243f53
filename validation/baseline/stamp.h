// The stamp an exported cases file carries (`rayaudit audit --export-cases`),
// so grading knows which run the cases are: its first line,
//   # rayaudit-cases version=0.9.0 seed=1 rays=20000 precision=float families=edge,vertex
// before the CSV header. Readers of the cases (and of answers files) skip
// lines starting with '#' before the header; numpy's loadtxt/genfromtxt do
// by default, pandas with comment='#'.
//
// Guarantee: a graded run takes its seed, rays per family and precision from
// the stamp, and is refused (one line) when the stamp was written by another
// rayaudit version, names a family that is not one, or a graded row belongs
// to a family the stamp does not list; so a baseline cannot silently span
// two versions or two sets of cases.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace ra::audit {

struct CasesStamp {
  std::string version;
  std::uint64_t seed = 0;
  long long rays = 0;
  std::string precision;  // "float" or "double"
  std::vector<std::string> families;
};

// The line, with its newline.
std::string stamp_line(const CasesStamp& s);

// The stamp of a cases file, or nullopt when its first line is not one.
// Throws ra::InputError "FILE:1: ..." for a stamp line that is malformed.
std::optional<CasesStamp> read_stamp(const std::string& cases_csv);

// True when the answers look computed in float: at least 16 hits, every hit's
// t a float, and every coordinate of the cases a float. Grading such answers
// as double books float rounding as errors of 1e10 ulps.
bool answers_look_float(const std::string& answers_csv, const std::string& cases_csv);

}  // namespace ra::audit
