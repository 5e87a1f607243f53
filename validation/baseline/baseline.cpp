// Comparing two audit JSON files cell by cell (see baseline.h).
#include "baseline.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

namespace ra::baseline {

bool Scope::has(const std::vector<std::string>& list, const std::string& v) const {
  return list.empty() || std::find(list.begin(), list.end(), v) != list.end();
}

namespace {

using nlohmann::json;

// The figures compared, in the order the table lists them.
struct Measure {
  const char* name;
  const char* key;
  bool maximum;  // compared with the doubling rule, not as a count
};
constexpr Measure kMeasures[] = {{"wrong", "wrong", false},
                                 {"leaks", "leaks", false},
                                 {"double hits", "double_hits", false},
                                 {"NaN answers", "nan_inf", false},
                                 {"t error (ulps, max)", "t_ulps_max", true}};

// A maximum "rose" only past twice the old value plus 2 ulps.
bool max_rose(double before, double after) { return after > 2 * before + 2; }

const char* which(bool baseline) { return baseline ? "the baseline" : "this run"; }

// The document's shape as far as the comparison needs it.
void check_audit(const json& j, bool baseline) {
  if (!j.is_object()) throw Mismatch(std::string(which(baseline)) + " is not an audit's JSON (not an object)");
  if (j.contains("cases") && !j.contains("subjects"))
    throw Mismatch(std::string(which(baseline)) + " is an `audit --cases` table, not an audit of families");
  if (j.contains("shard"))
    throw Mismatch(std::string(which(baseline)) +
                   " is one shard's partial counts: merge the shards first "
                   "(rayaudit audit merge)");
  for (const char* key : {"seed", "rays_per_family", "subjects", "cells"})
    if (!j.contains(key)) throw Mismatch(std::string(which(baseline)) + " has no '" + key + "': not an audit's JSON");
  if (!j["cells"].is_array() || !j["subjects"].is_array())
    throw Mismatch(std::string(which(baseline)) + ": 'cells' and 'subjects' must be arrays");
}

std::string text(const json& j, const char* key, const std::string& none = "(none)") {
  return j.contains(key) ? (j[key].is_string() ? j[key].get<std::string>() : j[key].dump()) : none;
}

double figure(const json& cell, const char* key, bool baseline) {
  const json& s = cell.contains("stats") ? cell["stats"] : json();
  if (!s.is_object() || !s.contains(key) || !s[key].is_number())
    throw Mismatch(std::string(which(baseline)) + ": a cell of " + text(cell, "subject") + " has no number '" + key +
                   "'");
  return s[key].get<double>();
}

using Key = std::tuple<std::string, std::string, std::string>;  // subject, family, sweep

std::map<Key, const json*> cells_in(const json& j, const Scope& scope, bool baseline) {
  std::map<Key, const json*> out;
  for (const json& c : j["cells"]) {
    if (!c.is_object() || !c.contains("subject") || !c.contains("family") || !c.contains("sweep") ||
        !c["subject"].is_string() || !c["family"].is_string() || !c["sweep"].is_string())
      throw Mismatch(std::string(which(baseline)) + ": a cell without subject, family or sweep");
    Key k{c["subject"], c["family"], c["sweep"]};
    if (!scope.has(scope.subjects, std::get<0>(k)) || !scope.has(scope.families, std::get<1>(k)) ||
        !scope.has(scope.sweeps, std::get<2>(k)))
      continue;
    if (!out.emplace(k, &c).second)
      throw Mismatch(std::string(which(baseline)) + " holds " + std::get<0>(k) + " " + std::get<1>(k) + "@" +
                     std::get<2>(k) + " twice");
  }
  return out;
}

std::string join(const std::set<std::string>& s) {
  std::string out;
  for (const auto& x : s) out += (out.empty() ? "" : ", ") + x;
  return out.empty() ? "none" : out;
}

std::string number(double v) {
  char buf[40];
  if (v == double(std::uint64_t(v)) && v < 1e15)
    std::snprintf(buf, sizeof buf, "%llu", (unsigned long long)v);
  else
    std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

void check_plan(const json& base, std::uint64_t seed, long long rays) {
  check_audit(base, true);
  if (text(base, "version") != RAYAUDIT_VERSION)
    throw Mismatch("the baseline was written by rayaudit " + text(base, "version") + ", this is " + RAYAUDIT_VERSION +
                   ": make a new baseline with this version");
  if (!base["seed"].is_number_unsigned() || base["seed"].get<std::uint64_t>() != seed)
    throw Mismatch("the baseline's seed is " + text(base, "seed") + ", this run's " + std::to_string(seed) +
                   " (give --seed " + text(base, "seed") + ")");
  if (!base["rays_per_family"].is_number_integer() || base["rays_per_family"].get<long long>() != rays)
    throw Mismatch("the baseline has " + text(base, "rays_per_family") + " rays per family, this run " +
                   std::to_string(rays) + " (give --rays " + text(base, "rays_per_family") + ")");
}

Diff compare(const json& base, const json& cur, const Scope& scope) {
  check_audit(base, true);
  check_audit(cur, false);
  Diff d;
  d.version = text(cur, "version");
  if (text(base, "version") != d.version)
    throw Mismatch("the baseline was written by rayaudit " + text(base, "version") + ", this run by " + d.version +
                   ": make a new baseline with this version");
  if (base["seed"] != cur["seed"])
    throw Mismatch("seeds differ: the baseline's is " + text(base, "seed") + ", this run's " + text(cur, "seed"));
  if (base["rays_per_family"] != cur["rays_per_family"])
    throw Mismatch("rays per family differ: the baseline has " + text(base, "rays_per_family") + ", this run " +
                   text(cur, "rays_per_family"));
  d.seed = cur["seed"].is_number_unsigned() ? cur["seed"].get<std::uint64_t>() : 0;
  d.rays = cur["rays_per_family"].is_number_integer() ? cur["rays_per_family"].get<long long>() : 0;

  const auto b = cells_in(base, scope, true), c = cells_in(cur, scope, false);
  std::set<std::string> base_subjects, cur_subjects;
  for (const auto& [k, cell] : b) base_subjects.insert(std::get<0>(k));
  for (const auto& [k, cell] : c) cur_subjects.insert(std::get<0>(k));
  for (const auto& s : cur_subjects)
    if (!base_subjects.count(s)) d.new_subjects.push_back(s);
  for (const auto& s : base_subjects)
    if (!cur_subjects.count(s))
      throw Mismatch("subject '" + s + "' of the baseline is not in this run (this run has: " + join(cur_subjects) +
                     ")");
  if (base_subjects.empty())
    throw Mismatch("nothing to compare: the baseline has no cell" +
                   std::string(scope.families.empty() && scope.sweeps.empty() && scope.subjects.empty()
                                   ? ""
                                   : " in the families, sweep values and subjects asked for"));
  // Same families and sweep values for every subject compared.
  for (const auto& s : base_subjects) {
    std::set<std::string> bf, cf, bs, cs;
    for (const auto& [k, cell] : b)
      if (std::get<0>(k) == s) bf.insert(std::get<1>(k)), bs.insert(std::get<1>(k) + "@" + std::get<2>(k));
    for (const auto& [k, cell] : c)
      if (std::get<0>(k) == s) cf.insert(std::get<1>(k)), cs.insert(std::get<1>(k) + "@" + std::get<2>(k));
    if (bf != cf)
      throw Mismatch("families differ for " + s + ": the baseline has " + join(bf) + "; this run " + join(cf));
    if (bs != cs) {
      std::set<std::string> only;
      for (const auto& x : bs)
        if (!cs.count(x)) only.insert(x);
      for (const auto& x : cs)
        if (!bs.count(x)) only.insert(x);
      throw Mismatch("sweep values differ for " + s + ": " + join(only) + " in one file only");
    }
  }
  for (const auto& [k, bc] : b) {
    const auto it = c.find(k);
    if (it == c.end()) continue;
    const json& cc = *it->second;
    const auto& [subject, family, sweep] = k;
    const double bt = figure(*bc, "tests", true), ct = figure(cc, "tests", false);
    if (bt != ct)
      throw Mismatch(subject + " " + family + "@" + sweep + ": " + number(bt) + " tests in the baseline, " +
                     number(ct) + " in this run: not the same rays (every shard merged? the same cases?)");
    ++d.cells;
    for (const Measure& m : kMeasures) {
      const double before = figure(*bc, m.key, true), after = figure(cc, m.key, false);
      const bool up = m.maximum ? max_rose(before, after) : after > before;
      const bool down = m.maximum ? max_rose(after, before) : after < before;
      if (up) d.rose.push_back({subject, family, sweep, m.name, before, after});
      if (down) d.fell.push_back({subject, family, sweep, m.name, before, after});
    }
  }
  return d;
}

std::string Diff::table(const json& current) const {
  auto row = [](const char* tag, const Change& ch) {
    char buf[512];
    const std::string where = ch.family + "@" + ch.sweep;
    const double delta = ch.after - ch.before;
    std::snprintf(buf, sizeof buf, "%-9s %-24s %-28s %-20s %12s %12s  (%s%s)\n", tag, ch.subject.c_str(), where.c_str(),
                  ch.measure.c_str(), number(ch.before).c_str(), number(ch.after).c_str(), delta > 0 ? "+" : "-",
                  number(delta > 0 ? delta : -delta).c_str());
    return std::string(buf);
  };
  std::string out;
  char head[512];
  std::snprintf(head, sizeof head,
                "%zu figure(s) rose, %zu fell, in %zu cells compared (seed %llu, %lld rays per family, "
                "rayaudit %s)\n",
                rose.size(), fell.size(), cells, (unsigned long long)seed, rays, version.c_str());
  out += head;
  if (!rose.empty() || !fell.empty()) {
    std::snprintf(head, sizeof head, "%-9s %-24s %-28s %-20s %12s %12s\n", "", "SUBJECT", "FAMILY@SWEEP", "MEASURE",
                  "BASELINE", "NOW");
    out += head;
  }
  for (const Change& ch : rose) out += row("ROSE", ch);
  for (const Change& ch : fell) out += row("IMPROVED", ch);
  for (const auto& s : new_subjects) out += "new subject (not in the baseline, not compared): " + s + "\n";
  // For each subject x family that rose: what it got wrong now, and how to see it.
  std::set<std::pair<std::string, std::string>> worse;
  for (const Change& ch : rose) worse.insert({ch.subject, ch.family});
  if (!worse.empty() && current.is_object() && current.contains("cells")) {
    Scope scope;
    // The cells that rose: their failing case ids (the lowest of each cell,
    // old failures among them; the counts say how many are new).
    for (const auto& [subject, family] : worse) scope.subjects.push_back(subject), scope.families.push_back(family);
    for (const Change& ch : rose)
      if (std::find(scope.sweeps.begin(), scope.sweeps.end(), ch.sweep) == scope.sweeps.end())
        scope.sweeps.push_back(ch.sweep);
    std::vector<FamilyResult> shown;
    for (FamilyResult& r : family_results(current, scope))
      if (worse.count({r.subject, r.family}) && r.failed) shown.push_back(std::move(r));
    out += failure_lines(shown);
  }
  return out;
}

}  // namespace ra::baseline
