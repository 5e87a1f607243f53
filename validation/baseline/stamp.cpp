// The exported cases' stamp (see stamp.h).
#include "stamp.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "errors.h"
#include "exact/cases_csv.h"
#include "exact/families.h"
#include "io/input_file.h"
#include "io/text_lines.h"

namespace ra::audit {

namespace {
constexpr const char* kTag = "# rayaudit-cases";

bool whole_number(const std::string& s, unsigned long long& v) {
  if (s.empty() || s.size() > 20 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  errno = 0;
  char* end = nullptr;
  v = std::strtoull(s.c_str(), &end, 10);
  return errno == 0 && *end == 0;
}

bool is_float(double x) { return !std::isfinite(x) || double(float(x)) == x; }
}  // namespace

std::string stamp_line(const CasesStamp& s) {
  std::string fams;
  for (const auto& f : s.families) fams += (fams.empty() ? "" : ",") + f;
  return std::string(kTag) + " version=" + s.version + " seed=" + std::to_string(s.seed) +
         " rays=" + std::to_string(s.rays) + " precision=" + s.precision + " families=" + fams + "\n";
}

std::optional<CasesStamp> read_stamp(const std::string& path) {
  check_input_file(path);
  std::ifstream in(path);
  if (!in) throw InputError(located(path, 0, "cannot open the cases file"));
  std::string line;
  if (!read_text_line(in, line)) return std::nullopt;
  if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  if (line.rfind(kTag, 0) != 0) return std::nullopt;
  CasesStamp s;
  bool seen_seed = false, seen_rays = false;
  std::istringstream words(line.substr(std::string(kTag).size()));
  for (std::string w; words >> w;) {
    const auto eq = w.find('=');
    const std::string key = w.substr(0, eq), value = eq == std::string::npos ? "" : w.substr(eq + 1);
    unsigned long long n = 0;
    if (key == "version" && !value.empty()) {
      s.version = value;
    } else if (key == "seed" && whole_number(value, n)) {
      s.seed = n, seen_seed = true;
    } else if (key == "rays" && whole_number(value, n) && n >= 1 && n <= 10000000000ULL) {
      s.rays = (long long)n, seen_rays = true;
    } else if (key == "precision" && (value == "float" || value == "double")) {
      s.precision = value;
    } else if (key == "families" && !value.empty()) {
      for (const auto& f : split_fields(value, ',')) {
        if (!find_family(f))
          throw InputError(
              located(path, 1, "the stamp names family '" + f + "', which is not a family (" + family_names() + ")"));
        s.families.push_back(f);
      }
    } else {
      throw InputError(located(path, 1,
                               "the stamp's '" + w +
                                   "' is not version=, seed=, rays=, precision=float|double "
                                   "or families="));
    }
  }
  if (s.version.empty() || !seen_seed || !seen_rays || s.precision.empty() || s.families.empty())
    throw InputError(located(path, 1, "the stamp needs version, seed, rays, precision and families"));
  return s;
}

bool answers_look_float(const std::string& answers_csv, const std::string& cases_csv) {
  // A directory or FIFO is named (not read, not waited on) before any open.
  check_input_file(answers_csv);
  check_input_file(cases_csv);
  std::ifstream in(answers_csv);
  if (!in) return false;
  long lineno = 0;
  const std::vector<std::string> header = read_csv_header(in, answers_csv, lineno);
  int hit = -1, t = -1;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == "hit") hit = int(i);
    if (header[i] == "t") t = int(i);
  }
  if (hit < 0 || t < 0) return false;
  long hits = 0;
  std::string line;
  while (read_text_line(in, line)) {
    const auto f = split_fields(line);
    if (f.size() != header.size()) continue;  // the grader names it
    const std::string& h = f[std::size_t(hit)];
    if (!(h == "true" || h == "True" || h == "TRUE" || h == "1")) continue;
    double v = 0;
    if (!parse_double(f[std::size_t(t)], v)) continue;
    if (!is_float(v)) return false;
    ++hits;
  }
  if (hits < 16) return false;
  bool all_float = true;
  for_each_case(cases_csv, [&](const UserCase& c, long) {
    if (!all_float) return;
    for (double x : {c.ray.o.x, c.ray.o.y, c.ray.o.z, c.ray.d.x, c.ray.d.y, c.ray.d.z, c.tri.a.x, c.tri.a.y, c.tri.a.z,
                     c.tri.b.x, c.tri.b.y, c.tri.b.z, c.tri.c.x, c.tri.c.y, c.tri.c.z})
      all_float = all_float && is_float(x);
  });
  return all_float;
}

}  // namespace ra::audit
