// The gate after an audit (see gate.h).
#include "gate.h"

#include <cstdio>
#include <map>
#include <set>

#include "errors.h"
#include "io/json_input.h"
#include "junit.h"

namespace ra::baseline {

nlohmann::json read_audit_json(const std::string& path) { return ra::read_json_file(path); }

namespace {

std::string change_words(const Change& c) {
  char buf[64];
  std::snprintf(buf, sizeof buf, " %.15g -> %.15g", c.before, c.after);
  return c.family + "@" + c.sweep + " " + c.measure + buf;
}

}  // namespace

GateResult gate(const nlohmann::json& audit, const std::optional<nlohmann::json>& baseline, const GateOptions& o) {
  GateResult res;
  const std::vector<FamilyResult> results = family_results(audit);
  std::optional<Diff> diff;
  if (baseline) {
    try {
      diff = compare(*baseline, audit);
    } catch (const Mismatch& e) {
      throw InputError(o.baseline_name + ": cannot be this run's baseline: " + e.what());
    }
    res.rose = diff->worse();
    res.printed = "against " + o.baseline_name + ": " + diff->table(audit);
  } else if (o.failure_lines) {
    res.printed = failure_lines(results);
  }
  std::fputs(res.printed.c_str(), stdout);
  if (o.junit.empty()) return res;

  // One test case per subject x family: with a baseline it fails when a
  // figure of it rose; without, when it has any wrong answer there.
  std::map<std::pair<std::string, std::string>, std::vector<const Change*>> rose;
  if (diff)
    for (const Change& c : diff->rose) rose[{c.subject, c.family}].push_back(&c);
  junit::Suite suite{o.suite, {}};
  for (const FamilyResult& r : results) {
    junit::Case c;
    c.classname = r.subject;
    c.name = r.family;
    const std::string detail = failure_lines({r});
    if (diff) {
      const auto it = rose.find({r.subject, r.family});
      if (it != rose.end()) {
        c.status = junit::Case::Status::fail;
        std::string words;
        for (const Change* ch : it->second) words += (words.empty() ? "" : "; ") + change_words(*ch);
        c.message = "rose against " + o.baseline_name + ": " + words;
        c.text = c.message + "\n" + detail;
      } else if (r.failed) {
        c.text = "no worse than " + o.baseline_name + " (wrong answers there before too): " + r.words;
      }
    } else if (r.failed) {
      c.status = junit::Case::Status::fail;
      c.message = r.words;
      c.text = detail;
    }
    suite.cases.push_back(std::move(c));
  }
  junit::write(o.junit, {suite});
  return res;
}

}  // namespace ra::baseline
