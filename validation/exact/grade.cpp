// Grading answers computed elsewhere against exported cases (see grade.h): the
// answers are held by id, the cases streamed, each ray's group booked by grade_probe().
#include "grade.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <tuple>
#include <unordered_map>

#include "cases_csv.h"
#include "errors.h"
#include "io/input_file.h"
#include "io/text_lines.h"

namespace ra::audit {

namespace {

bool boolean(const std::string& s, bool& out) {
  if (s == "true" || s == "True" || s == "TRUE" || s == "1") return out = true, true;
  if (s == "false" || s == "False" || s == "FALSE" || s == "0") return out = false, true;
  return false;
}

struct Given {
  GivenAnswer answer;
  long line = 0;
  bool used = false;
};

std::unordered_map<std::string, Given> read_answers(const std::string& path) {
  check_input_file(path);  // a directory, FIFO or /dev/zero named, not read
  std::ifstream in(path);
  if (!in) throw InputError(located(path, 0, "cannot open the answers file"));
  std::string line;
  long lineno = 0;
  // The cases reader's: a BOM dropped, UTF-16 named, a column named twice refused.
  const std::vector<std::string> header = read_csv_header(in, path, lineno);
  if (header.empty()) throw InputError(located(path, lineno, "empty file: expected a header line id,hit,t"));
  auto column = [&](const char* name) {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    return -1;
  };
  const int id = column("id"), hit = column("hit"), t = column("t"), u = column("u"), v = column("v");
  for (auto [c, name] : {std::pair{id, "id"}, {hit, "hit"}, {t, "t"}})
    if (c < 0) throw InputError(located(path, lineno, std::string("missing column '") + name + "' (need id,hit,t)"));

  std::unordered_map<std::string, Given> out;
  while (read_text_line(in, line)) {  // \n, \r\n and a lone \r
    ++lineno;
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const auto f = split_fields(line);
    if (f.size() != header.size())
      throw InputError(located(
          path, lineno,
          "expected " + std::to_string(header.size()) + " fields as in the header, found " + std::to_string(f.size())));
    const std::string& key = f[std::size_t(id)];
    if (key.empty()) throw InputError(located(path, lineno, "empty id"));
    Given g;
    g.line = lineno;
    if (!boolean(f[std::size_t(hit)], g.answer.hit))
      throw InputError(located(path, lineno, "hit '" + f[std::size_t(hit)] + "' is not a boolean (true/false or 1/0)"));
    const std::string& ts = f[std::size_t(t)];
    if (g.answer.hit && ts.empty()) throw InputError(located(path, lineno, "a hit without t (id '" + key + "')"));
    if (!ts.empty() && !parse_double(ts, g.answer.t))
      throw InputError(located(path, lineno, "t '" + ts + "' is not a number"));
    for (auto [c, name, out] : {std::tuple{u, "u", &g.answer.u}, {v, "v", &g.answer.v}})
      if (c >= 0 && !f[std::size_t(c)].empty() && !parse_double(f[std::size_t(c)], *out))
        throw InputError(located(path, lineno, std::string(name) + " '" + f[std::size_t(c)] + "' is not a number"));
    const auto [it, fresh] = out.emplace(key, g);
    if (!fresh)
      throw InputError(
          located(path, lineno, "duplicate id '" + key + "' (first at line " + std::to_string(it->second.line) + ")"));
  }
  return out;
}

// An exported id FAMILY:SWEEP:PROBE:K of a known family: the ray's key and K.
bool group_id(const std::string& id, std::string& family, std::string& sweep, std::string& key, long& k) {
  const auto parts = split_fields(id, ':');
  if (parts.size() != 4 || !find_family(parts[0])) return false;
  char* end = nullptr;
  k = std::strtol(parts[3].c_str(), &end, 10);
  if (parts[3].empty() || *end || k < 0) return false;
  family = parts[0], sweep = parts[1], key = parts[0] + ":" + parts[1] + ":" + parts[2];
  return true;
}

}  // namespace

Report grade_answers(const std::string& answers_csv, const std::string& cases_csv, Precision p,
                     const std::string& method) {
  auto answers = read_answers(answers_csv);
  Report rep;
  rep.subjects = {method + "/" + precision_name(p)};
  rep.kinds = {"triangle"};
  std::map<std::pair<std::string, std::string>, std::size_t> cell_of;

  // The ray being read: its rows (one per triangle) until the key changes.
  struct Pending {
    std::string key, family, sweep, first_id;
    Rayd ray;
    std::vector<Tri> tris;
    std::vector<GivenAnswer> given;
  } cur;
  auto flush = [&] {
    if (cur.tris.empty()) return;
    auto [it, fresh] = cell_of.emplace(std::pair{cur.family, cur.sweep}, rep.cells.size());
    if (fresh) {
      const Family* f = find_family(cur.family);
      int w = 0;
      if (f) w = int(std::find(f->sweep.begin(), f->sweep.end(), cur.sweep) - f->sweep.begin());
      rep.cells.push_back({0, cur.family, w, cur.sweep, {}, {}});
    }
    Cell& cell = rep.cells[it->second];
    const std::uint64_t bad = cell.stats.bad();
    grade_probe(cell.stats, p, cur.ray, cur.tris.data(), cur.given.data(), int(cur.tris.size()),
                cur.family == "closed-mesh");
    // The first failing rays in file order, by the id --ids takes back.
    if (cell.stats.bad() != bad && cell.example_ids.size() < Stats::kExamples)
      cell.example_ids.push_back(cur.key.empty() ? cur.first_id : cur.key);
    cur.tris.clear(), cur.given.clear();
  };
  for_each_case(cases_csv, [&](const UserCase& c, long line) {
    const auto a = answers.find(c.id);
    if (a == answers.end())
      throw InputError(located(cases_csv, line, "case '" + c.id + "' has no answer in " + answers_csv));
    if (a->second.used)
      throw InputError(located(cases_csv, line,
                               "duplicate case id '" + c.id + "' (its answer is " + answers_csv + ":" +
                                   std::to_string(a->second.line) + ")"));
    a->second.used = true;
    std::string family = "cases", sweep = "all", key;
    long k = 0;
    const bool grouped = group_id(c.id, family, sweep, key, k);
    if (!grouped || key != cur.key) {
      flush();
      if (grouped && k != 0)
        throw InputError(located(cases_csv, line,
                                 "case '" + c.id +
                                     "' does not follow the other rows of its ray "
                                     "(keep the export's order)"));
      cur.key = grouped ? key : std::string();
      cur.family = family, cur.sweep = sweep, cur.ray = c.ray, cur.first_id = c.id;
    } else if (k != long(cur.tris.size()) || !(c.ray.o == cur.ray.o && c.ray.d == cur.ray.d)) {
      throw InputError(located(cases_csv, line,
                               "case '" + c.id +
                                   "' does not follow the other rows of its ray "
                                   "(keep the export's order and rays)"));
    }
    cur.tris.push_back(c.tri);
    cur.given.push_back(a->second.answer);
  });
  flush();
  // The first answer (by line) whose id no case has.
  const Given* stray = nullptr;
  const std::string* stray_id = nullptr;
  for (const auto& [id, g] : answers)
    if (!g.used && (!stray || g.line < stray->line)) stray = &g, stray_id = &id;
  if (stray)
    throw InputError(located(answers_csv, stray->line, "id '" + *stray_id + "' is not a case of " + cases_csv));
  return rep;
}

}  // namespace ra::audit
