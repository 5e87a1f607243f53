// Failures that teach (see baseline.h): per subject x family, what went
// wrong in the table's words, up to 3 failing case ids with the command
// that replays them, and a hint when the pattern has a known cause (a
// one-sided subject misses exactly the hits seen from behind).
#include <algorithm>
#include <cstdio>
#include <map>

#include "baseline.h"
#include "exact/families.h"
#include "registry.h"

namespace ra::baseline {

namespace {

using nlohmann::json;

std::uint64_t count(const json& stats, const char* key) {
  return stats.is_object() && stats.contains(key) && stats[key].is_number_unsigned() ? stats[key].get<std::uint64_t>()
                                                                                     : 0;
}

// A word for the shell: quoted when it holds anything but safe characters.
std::string shell_word(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./:@,=+%") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// "12 false misses, 1 bad t" for one cell's stats; empty when nothing is wrong.
std::string cell_words(const json& s) {
  std::string out;
  auto add = [&](std::uint64_t n, const std::string& what) {
    if (n) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(count(s, "false_hits"), "false hits");
  add(count(s, "false_misses"), "false misses");
  add(count(s, "wrong_t"), "bad t");
  add(count(s, "nan_inf"), "NaN answers");
  if (count(s, "leaks")) add(count(s, "leaks"), "leaks of " + std::to_string(count(s, "groups")) + " groups");
  add(count(s, "double_hits"), "double hits");
  return out;
}

// Hits the subject should have made, split by the side the ray meets.
struct Sides {
  std::uint64_t back = 0, back_missed = 0, hits = 0, missed = 0;
  void add(const json& s) {
    back += count(s, "back_hits");
    back_missed += count(s, "back_false_misses");
    hits += count(s, "true_hits") + count(s, "false_misses");
    missed += count(s, "false_misses");
  }
  // Every hit from behind missed, and few from the front: back-face culling.
  std::string hint() const {
    const std::uint64_t front = hits - back, front_missed = missed - back_missed;
    if (back >= 8 && back_missed == back && front > 0 && front_missed * 10 < front)
      return "looks one-sided: it missed all " + std::to_string(back) +
             " hits on triangles seen from behind (d . ((b-a) x (c-a)) > 0) but only " + std::to_string(front_missed) +
             " of " + std::to_string(front) +
             " from the front; the audit expects two-sided subjects (no back-face "
             "culling; see validation/exact/README.md, the subject contract)";
    if (front >= 8 && front_missed == front && back > 0 && back_missed * 10 < back)
      return "looks one-sided: it missed all " + std::to_string(front) +
             " hits on triangles seen from the front (d . ((b-a) x (c-a)) < 0) but only " +
             std::to_string(back_missed) + " of " + std::to_string(back) +
             " from behind; the audit expects two-sided subjects";
    return {};
  }
};

std::string precision_of(const std::string& subject) {
  const auto slash = subject.rfind('/');
  return slash == std::string::npos ? "double" : subject.substr(slash + 1);
}
std::string method_of(const std::string& subject) {
  const auto slash = subject.rfind('/');
  return slash == std::string::npos ? subject : subject.substr(0, slash);
}

}  // namespace

std::string replay_command(const json& audit, const std::string& subject, const std::string& family,
                           const std::vector<std::string>& ids) {
  if (ids.empty()) return {};
  std::string list;
  for (const auto& id : ids) list += (list.empty() ? "" : ",") + id;
  const std::string p = precision_of(subject);
  // Graded answers: the ids are rows of the cases file graded.
  if (audit.contains("graded") && audit["graded"].is_object() && audit["graded"].contains("cases") &&
      audit["graded"]["cases"].is_string())
    return "rayaudit audit --cases " + shell_word(audit["graded"]["cases"].get<std::string>()) + " --ids " +
           shell_word(list) + " --precision " + p;
  const std::string seed = audit.contains("seed") ? audit["seed"].dump() : "1";
  const std::string rays = audit.contains("rays_per_family") ? audit["rays_per_family"].dump() : "20000";
  const ra::Method* m = ra::find_method(method_of(subject));
  const ra::audit::Family* f = ra::audit::find_family(family);
  if (!f) return {};
  const std::string methods = m ? " --methods " + shell_word(m->name) : "";
  if (f->kind != ra::Kind::triangle || f->secondary) {
    // No fixed cases to export: the family again, for this method alone.
    if (!m) return {};
    return "rayaudit audit" + methods + " --families " + family + " --seed " + seed + " --rays " + rays +
           " --precision " + p;
  }
  return "rayaudit audit --export-cases replay.csv --families " + family + " --seed " + seed + " --rays " + rays +
         " --precision " + p + " --ids " + shell_word(list) + " && rayaudit audit --cases replay.csv --precision " + p +
         (m && m->kind == ra::Kind::triangle ? methods : "");
}

std::vector<FamilyResult> family_results(const json& audit, const Scope& scope) {
  std::vector<FamilyResult> out;
  if (!audit.is_object() || !audit.contains("cells") || !audit["cells"].is_array()) return out;
  std::map<std::pair<std::string, std::string>, std::size_t> at;
  std::map<std::string, Sides> subject_sides;
  std::map<std::size_t, Sides> family_sides;
  for (const json& c : audit["cells"]) {
    if (!c.is_object() || !c.contains("subject") || !c["subject"].is_string() || !c.contains("family") ||
        !c["family"].is_string() || !c.contains("sweep") || !c["sweep"].is_string())
      continue;
    const std::string subject = c["subject"], family = c["family"], sweep = c["sweep"];
    if (!scope.has(scope.subjects, subject) || !scope.has(scope.families, family) || !scope.has(scope.sweeps, sweep))
      continue;
    const auto [it, fresh] = at.emplace(std::pair{subject, family}, out.size());
    if (fresh) out.push_back({subject, family, 0, false, "", {}, "", ""});
    FamilyResult& r = out[it->second];
    const json& s = c.contains("stats") ? c["stats"] : json();
    r.tests += count(s, "tests");
    subject_sides[subject].add(s);
    family_sides[it->second].add(s);
    const std::string words = cell_words(s);
    if (words.empty()) continue;
    r.failed = true;
    r.words += (r.words.empty() ? "" : "; ") + family + "@" + sweep + ": " + words;
    if (c.contains("examples") && c["examples"].is_array())
      for (const json& id : c["examples"])
        if (id.is_string() && r.ids.size() < 3) r.ids.push_back(id.get<std::string>());
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    FamilyResult& r = out[i];
    if (!r.failed) continue;
    r.replay = replay_command(audit, r.subject, r.family, r.ids);
    // The subject-wide pattern, shown where this family's misses are part of it.
    if (family_sides[i].back_missed > 0) r.hint = subject_sides[r.subject].hint();
  }
  return out;
}

std::string failure_lines(const std::vector<FamilyResult>& results) {
  std::string out;
  for (const FamilyResult& r : results) {
    if (!r.failed) continue;
    out += r.subject + " " + r.family + ": " + r.words + "\n";
    if (!r.hint.empty()) out += "  " + r.hint + "\n";
    if (!r.ids.empty()) {
      std::string ids;
      for (const auto& id : r.ids) ids += (ids.empty() ? "" : ", ") + id;
      out += "  cases " + ids + "\n";
    }
    if (!r.replay.empty()) out += "  replay: " + r.replay + "\n";
  }
  return out;
}

}  // namespace ra::baseline
